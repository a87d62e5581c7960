"""Run statistics: one definition of each figure a run reports (no ROS).

The simulator (node or headless), the controller runtime, `run`, `run --headless`, `sweep` and
the reproduction report all read these definitions, so a figure means the same wherever it
is printed. World frame `world` (z up), SI units.

- tracking error: |r_ref(t) - r_1(t)| of the leader [m] (max and rms over the ticks);
- formation error: the virtual-constraint residual g_vc of a follower (seed Eq. 3.7-3.8) [m]
  (max |component| and mean Euclidean norm over the ticks);
- saturation: time a UAV spent with any rotor at a speed limit [s];
- tension: the cable tensions T_i = 2 l_i lambda_i [N] (min and max over cables and ticks);
- payload swing: the horizontal distance of the payload from its static-equilibrium place
  under the UAVs at the same tick [m] (`payload_swing`).

Each figure is accumulated once, by a numba function over a float array whose slots are named
in one place, so a compiled control tick runs the same code as these classes:

- `layout`: the slots of the accumulator arrays (and the check's status codes);
- `swing`: the payload's equilibrium place and swing, compiled;
- `accumulators`: the per-tick accumulation and seed Algorithm 1's check, compiled;
- `figures`: the classes (views over the arrays) and the swing on plain inputs;
- `summary`: a run's summary as one `sweep` row.

Importing the package does not import numba (a `sweep` or the command line need only
`summary_row`); the first figure added or swing asked for does.
"""
from multilift_sim.statistics.figures import (FormationErrorStatistics, PeakRms,
                                              RunStatistics, TrackingStatistics,
                                              equilibrium_payload_position, payload_swing,
                                              payload_swing_at)
from multilift_sim.statistics.summary import summary_row

__all__ = ['FormationErrorStatistics', 'PeakRms', 'RunStatistics', 'TrackingStatistics',
           'equilibrium_payload_position', 'payload_swing', 'payload_swing_at', 'summary_row']
