"""The engine: a formation's whole control tick in one compiled call, for B formations at once.

One tick (seed Algorithm 1, the order the ROS graph gives, `runtime.answer_tick`): every UAV's
measured state from the formation state, the leader's answer (mission reference, cascade,
mixer and saturation), the thrust book, every follower's answer (virtual constraints,
Eq. 3.1-3.13), the rotor speeds held over one control period (RK4, the physics of
`multilift_sim.physics`), the constraint checks and the run statistics' accumulators. The
arithmetic is the laws' and the physics' own functions (each written once); this package only
orders them and names the arrays they share.

- `arrays`: the arrays of B formations (`FormationArrays`: constants; `FormationMemory`: what
  a tick changes; `TickRecord`: what one tick leaves for a bag), built once from scenarios;
- `tick`: the compiled tick, `run_ticks` (many ticks of many formations per call);
- `engine`: `Engine`, the small public API (`reset`, `step`, state and statistics as arrays).
"""
from multilift_control.engine.engine import Engine

__all__ = ['Engine']
