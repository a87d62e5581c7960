"""What the controllers receive when the scenario has an estimator, and the payload's estimate
when it has a payload estimator (docs/estimation.md): one compiled function, `estimated`,
which `physics.tick.measure` calls after the sensors for the engine's tick and
`FormationSimulator.snapshot` alike. Each UAV's estimator is reached through `estimate_uav`,
each payload estimator through `estimate_payload`: the dispatchers generated from the two
registries (`multilift_sim.estimators`, `multilift_sim.payload_estimators`;
`multilift_sim.part_dispatch`)."""
from multilift_sim import estimators, part_dispatch, payload_estimators
from multilift_sim.kernels import jit

ESTIMATORS_DISPATCH = part_dispatch.declare(
    'estimators', 'estimate_uav(model, constants, sensors, memory, tick, received)',
    step='estimate', caller=f'{__name__}.estimated', parts=lambda: estimators.ESTIMATORS,
    cache_callers=False)
PAYLOAD_ESTIMATORS_DISPATCH = part_dispatch.declare(
    'payload_estimators', 'estimate_payload(model, constants, sensors, estimates, memory, tick)',
    step='estimate', caller=f'{__name__}.estimated',
    parts=lambda: payload_estimators.PAYLOAD_ESTIMATORS, cache_callers=False)
# each rebound when its registry changes
estimate_uav = ESTIMATORS_DISPATCH.compiled()
estimate_payload = PAYLOAD_ESTIMATORS_DISPATCH.compiled()


@jit
def estimated(models, constants, payload_models, payload_constants, sensor_memory, memory,
              payload_memory, tick, states):
    """At control tick `tick`, from every UAV's sensors sensor_memory (K, n, Ms): first the
    MEASURED_* slots of each UAV's row of states (n, >= MEASURED_COLUMNS) from its estimator
    (models (E,) int: E = 0 or 1, its index in ESTIMATORS; constants (E, C); memory (E, n,
    M)), which reads UAV i's sensors sensor_memory[:, i] (K, Ms); then the payload's
    estimate into payload_memory (P, Mp) from its estimator (payload_models (P,) int: P = 0
    or 1, its index in PAYLOAD_ESTIMATORS; payload_constants (P, Cp)), which reads every
    UAV's sensors and the UAVs' estimates memory[0] (n, M)."""
    for e in range(models.shape[0]):
        for i in range(states.shape[0]):
            estimate_uav(models[e], constants[e], sensor_memory[:, i], memory[e, i], tick,
                         states[i])
    for e in range(payload_models.shape[0]):
        estimate_payload(payload_models[e], payload_constants[e], sensor_memory, memory[0],
                         payload_memory[e], tick)
