"""What the seed says, quoted from ../shared/seed (§2.8 and Ch. 4): its single-lift values and
its figure captions; and the scenarios (scenarios/*.yaml) that fly its cases. The seed's frame
is z down, (x, y, z)_world = (x, -y, -z)_seed (multilift_sim.frames).
"""
from __future__ import annotations

# -- what the seed says (quoted from ../shared/seed, §2.8 and Ch. 4) -------------------------
SEED_RELEASE = (1.02, -0.65, 2.19)      # r_p(0) [m], seed frame (z down), §4.1
SEED_PERIOD = 2.94                      # pendulum period [s], §2.8.1 and §4.1
SEED_EIGENVALUE = 2.13                  # lambda_1 = lambda_2 = +/- 2.13j [1/s], §2.8.1

# -- the scenarios of the seed's cases -------------------------------------------------------
SWING = 'single_lift_swing'
TWIN, MULTI = 'twin_lift', 'multi_lift'

# -- the seed's figure captions (quoted from ../shared/seed, §2.8 and Ch. 4) ------------------
SEED_CAPTIONS: dict[str, str] = {
    '2.12': 'Eigenvalues from the twin-lift configuration.',
    '4.1': 'Trajectories from the single-lift system.',
    '4.2': 'Constraint equation from the single-lift system for different stabilization '
           'parameters.',
    '4.3': 'Position error from the UAV and payload for α_f = 100.',
    '4.4': 'Constraints over time from the twin-lift system.',
    '4.5': 'Top-view from the twin-lift simulation.',
    '4.6': 'Attitude from the UAVs considering the twin-lift configuration.',
    '4.7': 'Virtual constraints from the twin-lift formation control.',
    '4.8': 'Thrust force required from the UAVs in the twin-lift configuration.',
    '4.9': 'UAVs trajectories from the twin-lift configuration.',
    '4.10': 'Constraints from the multi-lift system.',
    '4.11': 'Virtual constraints from the multi-lift formation control.',
    '4.12': 'Thrust forces from the UAVs in the multi-lift configuration.',
    '4.13': 'Trajectories (Top-view) for the multi-lift configuration.',
    '4.14': 'Trajectories from the multi-lift system.',
    '4.15': 'Comparison between the payload position when considering the twin-lift and '
            'multi-lift configurations.',
    '4.16': 'Comparison between the virtual constraints when considering the twin-lift and '
            'multi-lift configurations.',
    '4.17': 'Comparison from the rotor speed from the leader in the twin-lift and multi-lift '
            'formations.',
}
