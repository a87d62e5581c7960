"""Learning environments of multilift (issue "Learning environments"), registered with
Gymnasium on import:

    import gymnasium, multilift_learning
    env = gymnasium.make('multilift/Hover-v0')                     # twin_lift, hover
    env = gymnasium.make('multilift/Mission-v0', scenario='multi_lift')
    env = gymnasium.make('multilift/Navigate-v0')                  # forest: past the trees
    envs = gymnasium.make_vec('multilift/Hover-v0', num_envs=256)  # one batched engine

A PettingZoo ParallelEnv, an agent per UAV: multilift_learning.parallel_env. Spaces, rewards
and ends: multilift_learning.batch; tasks: multilift_learning.tasks.
"""
from __future__ import annotations

import gymnasium

# each environment's id -> its constructor's defaults (the task; Navigate-v0's world, and a
# bound beyond its goal's 6.4 m from the start)
ENVIRONMENTS = {
    'multilift/Hover-v0': {'task': 'hover'},
    'multilift/Mission-v0': {'task': 'mission'},
    'multilift/Navigate-v0': {'task': 'navigate', 'scenario': 'forest', 'bound': 10.0},
}

for _id, _defaults in ENVIRONMENTS.items():
    if _id not in gymnasium.registry:
        gymnasium.register(id=_id, entry_point='multilift_learning.env:FormationEnv',
                           vector_entry_point='multilift_learning.vector_env:FormationVectorEnv',
                           kwargs=dict(_defaults))
