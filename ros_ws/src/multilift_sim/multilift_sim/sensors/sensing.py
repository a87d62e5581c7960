"""What the controllers receive of every UAV when the scenario has `sensors:`: its sensor
models' outputs, not the state (docs/sensors.md). One compiled function, which
`physics.tick.measure` calls for the engine's tick and `FormationSimulator.snapshot` alike, so
the ROS nodes and the headless engine receive the same numbers to the bit. Each model is
reached through `measure_sensor`, the dispatcher generated from the registry
(`SENSORS`, `multilift_sim.part_dispatch`)."""
from multilift_sim import part_dispatch
from multilift_sim import sensors as registry
from multilift_sim.kernels import jit
from multilift_sim.physics.layout import MEASURED_COLUMNS

SENSORS = part_dispatch.declare(
    'sensors', 'measure_sensor(model, constants, draws, memory, tick, truth, received)',
    step='measure', caller=f'{__name__}.sensed_states', parts=lambda: registry.SENSOR_MODELS,
    cache_callers=False)
measure_sensor = SENSORS.compiled()  # rebound when the registry changes (SENSORS.refresh)


@jit
def sensed_states(models, constants, draws, memory, tick, truth, states):
    """Replace the MEASURED_* slots of every UAV's row of states (n, >= MEASURED_COLUMNS) at
    control tick `tick` by what its controllers receive: each sensor k of the formation in
    turn (models (K,) int: its model's index in SENSOR_MODELS; constants (K, C), draws (K, n,
    samples, D), memory (K, n, M): its rows, padded to the widest), each from the truth (n,
    SENSED_COLUMNS: each UAV's true measured state, then its cable's, physics.layout
    SENSED_*), writing over what the ones before it wrote."""
    n = states.shape[0]
    for k in range(models.shape[0]):
        for i in range(n):
            measure_sensor(models[k], constants[k], draws[k, i], memory[k, i], tick, truth[i],
                           states[i, :MEASURED_COLUMNS])
