"""`cable_geometry`: the payload's position and velocity from the UAVs' estimates and their
cable sensors (issue 33 item 3; docs/estimation.md), a Kalman filter of six states (p, v
[m, m/s], world) run once per control tick.

Prediction, tension-driven (Newton on a point payload): a = g_w + (1 / m_p) sum_i T_i u_i,
u_i = -d_i the unit vector from the payload up cable i (d_i from UAV i's attach point to the
payload, seen by its gimbal: R_i_hat d_body(alpha_i, beta_i), physics.cable_sensing), T_i its
load cell's latest tension; p += v dt + a dt^2 / 2, v += a dt. The process noise: white
acceleration of density `acceleration_noise` [m/s^2/sqrt(Hz)] (the payload's drag and gusts,
which the model leaves out) plus the measured force's noise, sum_i (sigma_T^2 + T_i^2
sigma_enc^2) / m_p^2 per axis, held over the period. Before the load cells' first reading
(tick 0: no tick flown) the acceleration is taken as 0.

Update, per UAV whose cable sample arrived (and whose tension is positive: a slack cable says
nothing of the payload): the seed's cable constraint (Eq. 2.42) solved for the payload,
z_i = r_i_hat + l_i d_i, against p (with the sample's latency Delta: z_i = r_i_hat - Delta
v_i_hat + l_i d_i against p - Delta v, H = [I, -Delta I]), its covariance the UAV's pose
covariance through J = [I, -l_i [d_i]x] (position, attitude error about the world's axes, as
/uav{i}/estimate carries it) plus the encoders' noise l_i^2 R J_g sigma^2 J_g^T R^T.
The filter assumes each update independent: the UAV's attitude error is correlated from one
tick to the next, which this leaves out (docs/estimation.md measures what it does).

Starts at tick 0 from the first samples (position prior 100 m^2 per axis, then the updates),
at rest (`initial_velocity_noise` [m/s]). Needs a point payload on cables of fixed length
(rigid), the UAVs' estimator and a `cable_sensor:`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from multilift_sim.estimators.published import (
    COVARIANCE_SIDE, ESTIMATE_ANGULAR, ESTIMATE_COLUMNS, ESTIMATE_LINEAR, ESTIMATE_ORIENTATION,
    ESTIMATE_POSE_COVARIANCE, ESTIMATE_POSITION, ESTIMATE_TWIST_COVARIANCE)
from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import quaternion_rotation
from multilift_sim.physics.cable_sensing import gimbal_direction, gimbal_jacobian
from multilift_sim.sensors import cable_sensor
from multilift_sim.sensors.outputs import ARRIVED, OUTPUT, TAKEN

NAME = 'cable_geometry'
UNITS = {'acceleration_noise': 'm/s^2/sqrt(Hz)', 'initial_velocity_noise': 'm/s'}
INITIAL_POSITION_VARIANCE = 100.0  # [m^2] per axis, before the first samples
UNKNOWN_VARIANCE = 1e9      # a point payload's attitude and rates: not estimated

# -- its constants row -------------------------------------------------------------------------
CABLE_ROW = 0               # the cable sensor's row in the run's sensor arrays
PERIOD = 1                  # the control period dt [s]
GRAVITY = 2                 # g [m/s^2]
PAYLOAD_MASS = 3            # m_p [kg]
ACCELERATION_VARIANCE = 4   # the white acceleration's density squared [m^2/s^3]
ENCODER_VARIANCE = 5        # each gimbal angle's noise variance [rad^2]
LOAD_CELL_VARIANCE = 6      # the load cell's noise variance [N^2]
INITIAL_VELOCITY_VARIANCE = 7  # [m^2/s^2]
CABLE_LENGTH = 8            # l_i [m], one per UAV (n)
# -- the formation's memory: first its estimate as /payload/estimate carries it
#    (estimators.published, ESTIMATE_COLUMNS), then
LAST_TICK = ESTIMATE_COLUMNS  # the tick estimated last (-1: none)
STATE_SIZE = 6              # the filter's state: p (3), then v (3)
STATE = LAST_TICK + 1       # (p, v) [m, m/s], world (STATE_SIZE)
COVARIANCE = STATE + STATE_SIZE  # P (STATE_SIZE, STATE_SIZE), row by row
MEMORY_COLUMNS = COVARIANCE + STATE_SIZE * STATE_SIZE


@dataclass(frozen=True)
class CableGeometrySettings:
    acceleration_noise: float        # [m/s^2/sqrt(Hz)]: what the model leaves out
    initial_velocity_noise: float    # [m/s] per axis: the payload starts at rest


def parse(d) -> CableGeometrySettings:
    return CableGeometrySettings(
        acceleration_noise=d.non_negative('acceleration_noise', 0.5),
        initial_velocity_noise=d.non_negative('initial_velocity_noise', 0.01))


def needs(scenario) -> str:
    """'' when the scenario has what it reads (a `cable_sensor:`, the UAVs' `estimator:`, a
    point payload on rigid cables of fixed length), else what is missing."""
    if not any(c.model == cable_sensor.NAME for c in scenario.sensor_suite):
        return 'needs the sensors cable_sensor (section cable_sensor: ...)'
    if scenario.estimator is None:
        return 'needs the UAVs\' estimator (estimator: ekf)'
    if scenario.payload.inertia is not None:
        return 'needs a point payload (payload.model: point)'
    if scenario.cable_model != 'rigid' or scenario.winches:
        return 'needs cables of fixed length (cable_model: rigid, no winch)'
    return ''


def constants(settings: CableGeometrySettings, scenario, rows: dict) -> np.ndarray:
    sim = scenario.simulation
    cable = next(c for c in scenario.sensor_suite if c.model == cable_sensor.NAME).settings
    row = np.zeros(CABLE_LENGTH + scenario.n_uavs)
    row[CABLE_ROW] = rows[cable_sensor.NAME]
    row[PERIOD], row[GRAVITY] = 1.0 / sim.control_rate, sim.gravity
    row[PAYLOAD_MASS] = scenario.payload.mass
    row[ACCELERATION_VARIANCE] = settings.acceleration_noise ** 2
    row[ENCODER_VARIANCE] = cable.encoder_noise ** 2
    row[LOAD_CELL_VARIANCE] = cable.load_cell_noise ** 2
    row[INITIAL_VELOCITY_VARIANCE] = settings.initial_velocity_noise ** 2
    row[CABLE_LENGTH:] = [u.cable_length for u in scenario.uavs]
    return row


def memory(settings: CableGeometrySettings, scenario) -> np.ndarray:
    row = np.zeros(MEMORY_COLUMNS)
    row[LAST_TICK] = -1.0
    return row


@jit
def predict(constants, cables, state, covariance):
    """state (6,) and covariance (6, 6) over one control period, driven by the cables' latest
    tensions and gimbal directions `cables` (n, 4: u_i (3) world, T_i [N]; NaN T: none yet)."""
    dt = constants[PERIOD]
    mass = constants[PAYLOAD_MASS]
    accel = np.zeros(3)
    accel[2] = -constants[GRAVITY]
    force_variance = 0.0
    for i in range(cables.shape[0]):
        tension = cables[i, 3]
        if math.isnan(tension):
            accel[:] = 0.0
            force_variance = 0.0
            break
        for j in range(3):
            accel[j] += tension * cables[i, j] / mass
        force_variance += (constants[LOAD_CELL_VARIANCE]
                           + tension * tension * constants[ENCODER_VARIANCE]) / (mass * mass)
    for j in range(3):
        state[j] += state[3 + j] * dt + 0.5 * accel[j] * dt * dt
        state[3 + j] += accel[j] * dt
    transition = np.eye(STATE_SIZE)
    for j in range(3):
        transition[j, 3 + j] = dt
    moved = transition @ covariance @ transition.T
    q = constants[ACCELERATION_VARIANCE]
    for j in range(3):
        p, v = j, 3 + j
        moved[p, p] += q * dt ** 3 / 3.0 + force_variance * dt ** 4 / 4.0
        moved[p, v] += q * dt ** 2 / 2.0 + force_variance * dt ** 3 / 2.0
        moved[v, p] += q * dt ** 2 / 2.0 + force_variance * dt ** 3 / 2.0
        moved[v, v] += q * dt + force_variance * dt * dt
    covariance[:, :] = moved


@jit
def update(state, covariance, measured, noise, lag):
    """One payload position measurement `measured` (3,) [m] of p - lag v (lag [s]) with noise
    covariance `noise` (3, 3) fused into state (6,) and covariance (6, 6) (Joseph form)."""
    h = np.zeros((3, STATE_SIZE))
    for j in range(3):
        h[j, j], h[j, 3 + j] = 1.0, -lag
    innovation = measured - h @ state
    s = h @ covariance @ h.T + noise
    gain = covariance @ h.T @ np.linalg.inv(s)
    state += gain @ innovation
    keep = np.eye(STATE_SIZE) - gain @ h
    joseph = keep @ covariance @ keep.T + gain @ noise @ gain.T
    covariance[:, :] = 0.5 * (joseph + joseph.T)


@jit
def cable_measurement(constants, cable, uav, length, measured, noise, up):
    """From UAV `uav`'s estimate (its published slots) and its cable sensor's latest output
    `cable` (its memory): the payload position its cable puts it at into measured (3,), that
    position's covariance into noise (3, 3), the unit vector up the cable u = -d into up (3,);
    returns the sample's age [s]."""
    orientation = np.empty(4)  # (w, x, y, z), from the message's (x, y, z, w)
    orientation[0] = uav[ESTIMATE_ORIENTATION + 3]
    orientation[1:] = uav[ESTIMATE_ORIENTATION:ESTIMATE_ORIENTATION + 3]
    rotation = quaternion_rotation(orientation, 0)
    alpha = cable[OUTPUT + cable_sensor.OUTPUT_ANGLES]
    beta = cable[OUTPUT + cable_sensor.OUTPUT_ANGLES + 1]
    body = np.empty(3)
    body[0], body[1], body[2] = gimbal_direction(alpha, beta)
    direction = rotation @ body
    lag = (cable[ARRIVED] - cable[TAKEN]) * constants[PERIOD]
    velocity = rotation @ uav[ESTIMATE_LINEAR:ESTIMATE_LINEAR + 3]
    for j in range(3):
        measured[j] = (uav[ESTIMATE_POSITION + j] - lag * velocity[j]
                       + length * direction[j])
        up[j] = -direction[j]
    pose = np.empty((COVARIANCE_SIDE, COVARIANCE_SIDE))
    for r in range(COVARIANCE_SIDE):
        for c in range(COVARIANCE_SIDE):
            pose[r, c] = uav[ESTIMATE_POSE_COVARIANCE + COVARIANCE_SIDE * r + c]
    # d(measured) / d(position, attitude error about the world's axes)
    jacobian = np.zeros((3, COVARIANCE_SIDE))
    for j in range(3):
        jacobian[j, j] = 1.0
    d = direction * length  # dz = dr + dtheta x (l d) = dr - [l d]x dtheta
    jacobian[0, 4], jacobian[0, 5] = d[2], -d[1]
    jacobian[1, 3], jacobian[1, 5] = -d[2], d[0]
    jacobian[2, 3], jacobian[2, 4] = d[1], -d[0]
    angles = np.empty((3, 2))
    gimbal_jacobian(alpha, beta, angles)
    encoders = length * (rotation @ angles)
    noise[:, :] = (jacobian @ pose @ jacobian.T
                   + constants[ENCODER_VARIANCE] * (encoders @ encoders.T))
    return lag


@jit
def publish(state, covariance, memory):
    """The estimate as /payload/estimate carries it into memory's first ESTIMATE_COLUMNS: the
    position and its covariance, the velocity (world: a point payload's frame is the world's
    axes) and its covariance; no attitude (identity, UNKNOWN_VARIANCE on its rows)."""
    memory[:ESTIMATE_COLUMNS] = 0.0
    memory[ESTIMATE_ORIENTATION + 3] = 1.0
    for r in range(3):
        memory[ESTIMATE_POSITION + r] = state[r]
        memory[ESTIMATE_LINEAR + r] = state[3 + r]
        memory[ESTIMATE_ANGULAR + r] = 0.0
        for c in range(3):
            memory[ESTIMATE_POSE_COVARIANCE + COVARIANCE_SIDE * r + c] = covariance[r, c]
            memory[ESTIMATE_TWIST_COVARIANCE + COVARIANCE_SIDE * r + c] = covariance[3 + r,
                                                                                    3 + c]
        unknown = COVARIANCE_SIDE * (3 + r) + 3 + r
        memory[ESTIMATE_POSE_COVARIANCE + unknown] = UNKNOWN_VARIANCE
        memory[ESTIMATE_TWIST_COVARIANCE + unknown] = UNKNOWN_VARIANCE


@jit
def estimate(constants, sensors, estimates, memory, tick):
    """At control tick `tick`: the filter predicted over the period from the last tick (from
    tick 0: started), then each cable sample that arrived now fused; its estimate published
    into memory. A second call at one tick changes nothing."""
    if memory[LAST_TICK] == tick:
        return
    memory[LAST_TICK] = tick
    cables = sensors[int(constants[CABLE_ROW])]
    n = cables.shape[0]
    state = memory[STATE:STATE + STATE_SIZE]
    covariance = memory[COVARIANCE:MEMORY_COLUMNS].copy().reshape((STATE_SIZE, STATE_SIZE))
    measured = np.empty((n, 3))
    noise = np.empty((n, 3, 3))
    lags = np.empty(n)
    forces = np.empty((n, 4))
    for i in range(n):
        lags[i] = cable_measurement(constants, cables[i], estimates[i],
                                    constants[CABLE_LENGTH + i], measured[i], noise[i],
                                    forces[i, :3])
        forces[i, 3] = cables[i, OUTPUT + cable_sensor.OUTPUT_TENSION]
    if tick == 0:
        state[:] = 0.0
        covariance[:, :] = 0.0
        for j in range(3):
            state[j] = measured[0, j]
            covariance[j, j] = INITIAL_POSITION_VARIANCE
            covariance[3 + j, 3 + j] = constants[INITIAL_VELOCITY_VARIANCE]
    else:
        predict(constants, forces, state, covariance)
    for i in range(n):
        tension = forces[i, 3]
        if cables[i, ARRIVED] == tick and (tick == 0 or tension > 0.0):
            update(state, covariance, measured[i], noise[i], lags[i])
    memory[COVARIANCE:MEMORY_COLUMNS] = covariance.reshape(STATE_SIZE * STATE_SIZE)
    publish(state, covariance, memory)
