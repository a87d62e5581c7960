"""The estimators' errors against the truth, accumulated at every tick flown (issue 33 item 6;
docs/estimation.md), compiled: each UAV's estimate as /uav{i}/estimate carries it (position
and attitude, their pose covariance: estimators.published) and the payload's
(/payload/estimate: position, velocity), into the run's sums (statistics.layout RUN_*
ESTIMATION, PAYLOAD, *_ERROR_SQ, *_NEES), whose summary (statistics.figures) is their rms and
mean NEES. Units: SI, world frame z up."""
import numpy as np

from multilift_sim.estimators.published import (COVARIANCE_SIDE, ESTIMATE_COLUMNS, ESTIMATE_LINEAR,
                                                ESTIMATE_ORIENTATION, ESTIMATE_POSE_COVARIANCE,
                                                ESTIMATE_POSITION)
from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import attitude_difference, quaternion_rotation
from multilift_sim.physics.layout import BODY_QUATERNION, POSITION
from multilift_sim.physics.state_slots import (payload_slot, rates_slot, uav_attitude_slot,
                                               uav_slot)
from multilift_sim.statistics.layout import (
    RUN_ATTITUDE_ERROR_SQ, RUN_ATTITUDE_NEES, RUN_ESTIMATION_SAMPLES, RUN_PAYLOAD_NEES,
    RUN_PAYLOAD_POSITION_SQ, RUN_PAYLOAD_VELOCITY_SQ, RUN_POSITION_ERROR_SQ, RUN_POSITION_NEES,
    RUN_SCALARS, RUN_UAV_COLUMNS)


@jit
def pose_nees(estimate, block, error):
    """e^T P^-1 e of error (3,) with P the 3 x 3 block from row and column `block` (0: the
    position, 3: the attitude about the world's axes) of the pose covariance in `estimate`
    (its published slots)."""
    covariance = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            covariance[r, c] = estimate[ESTIMATE_POSE_COVARIANCE
                                        + COVARIANCE_SIDE * (block + r) + block + c]
    return error @ np.linalg.solve(covariance, error)


@jit
def run_add_estimation(run, state, estimates, payload):
    """One tick's estimates against the formation state x `state`: estimates (n, >=
    ESTIMATE_COLUMNS) every UAV's (the attitude error Log(q_hat^-1 q), body, turned into the
    world's axes as the published covariance has it), payload (0 or >= ESTIMATE_COLUMNS) the
    payload's (none: 0 columns). A tick whose estimates carry no covariance (an estimator that
    publishes none: a zero on a variance's diagonal, or fewer than ESTIMATE_COLUMNS) is not
    counted."""
    n = estimates.shape[0]
    if estimates.shape[1] < ESTIMATE_COLUMNS:
        return
    for i in range(n):
        for j in range(COVARIANCE_SIDE):
            if not estimates[i, ESTIMATE_POSE_COVARIANCE + (COVARIANCE_SIDE + 1) * j] > 0.0:
                return
    run[RUN_ESTIMATION_SAMPLES] += 1.0
    error = np.empty(3)
    for i in range(n):
        estimate = estimates[i]
        for j in range(3):
            error[j] = estimate[ESTIMATE_POSITION + j] - state[uav_slot(i) + POSITION + j]
        slot = RUN_SCALARS + RUN_UAV_COLUMNS * i
        run[slot + RUN_POSITION_ERROR_SQ] += error @ error
        run[slot + RUN_POSITION_NEES] += pose_nees(estimate, 0, error)
        q = np.empty(4)  # (w, x, y, z) from the message's (x, y, z, w)
        q[0] = estimate[ESTIMATE_ORIENTATION + 3]
        q[1:] = estimate[ESTIMATE_ORIENTATION:ESTIMATE_ORIENTATION + 3]
        base = uav_attitude_slot(n, i) + BODY_QUATERNION
        body = np.empty(3)
        body[0], body[1], body[2] = attitude_difference(q, 0, state[base], state[base + 1],
                                                        state[base + 2], state[base + 3])
        world = quaternion_rotation(q, 0) @ body
        run[slot + RUN_ATTITUDE_ERROR_SQ] += world @ world
        run[slot + RUN_ATTITUDE_NEES] += pose_nees(estimate, 3, world)
    if payload.shape[0]:
        p = payload_slot(n)
        v = rates_slot(n) + p
        speed = np.empty(3)
        for j in range(3):
            error[j] = payload[ESTIMATE_POSITION + j] - state[p + j]
            speed[j] = payload[ESTIMATE_LINEAR + j] - state[v + j]
        run[RUN_PAYLOAD_POSITION_SQ] += error @ error
        run[RUN_PAYLOAD_VELOCITY_SQ] += speed @ speed
        run[RUN_PAYLOAD_NEES] += pose_nees(payload, 0, error)
