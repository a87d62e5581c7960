"""What the controllers receive when the scenario has an estimator: its estimate of every UAV
from its sensors (docs/estimation.md). One compiled function, which `physics.tick.measure`
calls after the sensors for the engine's tick and `FormationSimulator.snapshot` alike; each
estimator reached through `estimate_uav`, the dispatcher generated from the registry
(`multilift_sim.part_dispatch`)."""
from multilift_sim import estimators as registry
from multilift_sim import part_dispatch
from multilift_sim.kernels import jit

ESTIMATORS_DISPATCH = part_dispatch.declare(
    'estimators', 'estimate_uav(model, constants, sensors, memory, tick, received)',
    step='estimate', caller=f'{__name__}.estimated_states',
    parts=lambda: registry.ESTIMATORS)
estimate_uav = ESTIMATORS_DISPATCH.compiled()  # rebound when the registry changes


@jit
def estimated_states(models, constants, sensor_memory, memory, tick, states):
    """The MEASURED_* slots of every UAV's row of states (n, >= MEASURED_COLUMNS) at control
    tick `tick` from its estimator (models (E,) int: E = 0 or 1, its index in ESTIMATORS;
    constants (E, C); memory (E, n, M)), which reads UAV i's sensors sensor_memory[:, i]
    (K, n, Ms)."""
    for e in range(models.shape[0]):
        for i in range(states.shape[0]):
            estimate_uav(models[e], constants[e], sensor_memory[:, i], memory[e, i], tick,
                         states[i])
