"""The payload's estimate when the scenario has a payload estimator (docs/estimation.md): one
compiled function, which `physics.tick.measure` calls after the UAVs' estimator for the
engine's tick and `FormationSimulator.snapshot` alike; each estimator reached through
`estimate_payload`, the dispatcher generated from the registry (`multilift_sim.part_dispatch`)."""
from multilift_sim import part_dispatch
from multilift_sim import payload_estimators as registry
from multilift_sim.kernels import jit

PAYLOAD_ESTIMATORS_DISPATCH = part_dispatch.declare(
    'payload_estimators', 'estimate_payload(model, constants, sensors, estimates, memory, tick)',
    step='estimate', caller=f'{__name__}.estimated_payload',
    parts=lambda: registry.PAYLOAD_ESTIMATORS)
estimate_payload = PAYLOAD_ESTIMATORS_DISPATCH.compiled()  # rebound when the registry changes


@jit
def estimated_payload(models, constants, sensor_memory, estimator_memory, memory, tick):
    """The payload's estimate at control tick `tick` into memory (P, M) from its estimator
    (models (P,) int: P = 0 or 1, its index in PAYLOAD_ESTIMATORS; constants (P, C)), which
    reads every UAV's sensors sensor_memory (K, n, Ms) and estimates estimator_memory[0]
    (n, Me)."""
    for e in range(models.shape[0]):
        estimate_payload(models[e], constants[e], sensor_memory, estimator_memory[0],
                         memory[e], tick)
