"""Cables that pull but never push (`cable_model: slack`, slack.SlackCableModel) on one
formation's arrays: the taut set, the snap (positions projected onto the cable's length, an
inelastic impulse in the mass metric; a rigid payload's and the UAVs' rotations included,
docs/rigid_payload.md) and the RK4 step cut at each taut event (located by `taut_event`).
Not in the seed (slack.py's docstring has the model and its references). World frame, SI;
arguments as in formation_dae, the slots `physics.layout`'s.

The rigid model is this one with every cable taut and none allowed to slacken: the same
`formation_dae.solve`, whose slack cables have multiplier 0.
"""
import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.formation_dae import (cable_multipliers, inverse_delta, residuals,
                                                 rk4_step, solve)
from multilift_sim.physics.free_motion import (add_cable_torque, attached_off_centre,
                                              cable_moment_arm, cable_turn, uav_attach_motion)
from multilift_sim.physics.layout import (
    BODY_RATES, CABLE_COLUMNS, CABLE_INV_DELTA, CABLE_MOMENT, CABLE_OFFSET, CABLE_PAYLOAD_MOMENT,
    CABLE_RHS,
    FORMATION_INV_PAYLOAD_MASS, FORMATION_PAYLOAD_INERTIA, FORMATION_PAYLOAD_MASS,
    PAYLOAD_BODY_RATES, POSITION, SLACK_CABLE_ROWS,
    SLACK_END, SLACK_EVENT, SLACK_FLAGS, SLACK_G_DOT_END, SLACK_G_END, SLACK_MULTIPLIERS,
    SLACK_SNAPPING, SLACK_SOLUTION, SLACK_STATES, SLACK_TARGET, UAV_LENGTH_SQ,
    UAV_MASS, WORK_ACC, WORK_ROWS, WRENCH_COLUMNS)
from multilift_sim.physics.state_slots import (attitude_slot, payload_slot, rates_slot,
                                               uav_attitude_slot, uav_slot)
from multilift_sim.physics.attitude import turn_quaternion
from multilift_sim.physics.rigid_payload import (payload_rotation, rigid_cable_row,
                                                 rigid_multipliers, world_rates)
from multilift_sim.physics.taut_event import EVENT_TOLERANCE, taut_event


# ---------------------------------------------------------------- solves in the mass metric
# G M^-1 G^T is the matrix of the multiplier equation without its Baumgarte terms (the DAE's
# solve builds it the same way): each cable's row from d_i and, where they exist, the moment
# arms k_i (a UAV held off its centre) and c_i (a rigid payload); docs/rigid_payload.md.
@jit
def mass_metric_solve(x, uavs, formation, taut, rhs, out, cables):
    """z = (G M^-1 G^T)_TT^-1 rhs_T over the taut cables T (0 on the others) into out (n,),
    at the positions of x; leaves each cable's row in `cables`: d_i [m] from its attach
    points, k_i (CABLE_MOMENT, 0 at a UAV's centre) and with a rigid payload c_i
    (CABLE_PAYLOAD_MOMENT)."""
    n = uavs.shape[0]
    p = payload_slot(n)
    attitude = attitude_slot(n)
    if x.shape[0] > attitude:  # a rigid payload: the 6 x 6 Woodbury solve (physics.rigid_payload)
        rotation = payload_rotation(x, attitude)
        w = world_rates(x, attitude, rotation)
        attach = np.zeros((3, 3))
        still = np.zeros((n, WRENCH_COLUMNS))  # (the attach points' accelerations: unused)
        for i in range(n):
            rigid_cable_row(x, uavs, i, still, rotation, w, attitude, attach, cables)
            cables[i, CABLE_RHS] = rhs[i]
        rigid_multipliers(cables, formation, taut, out)
        return
    for i in range(n):
        r = uav_slot(i) + POSITION
        dx, dy, dz = x[p] - x[r], x[p + 1] - x[r + 1], x[p + 2] - x[r + 2]
        k0 = k1 = k2 = 0.0
        if attached_off_centre(uavs, i):  # from the attach point r_i + R_i a_i
            attach = np.empty((3, 3))
            uav_rotation_i = uav_attach_motion(x, i, np.zeros((n, WRENCH_COLUMNS)), uavs,
                                               attach)
            dx, dy, dz = dx - attach[0, 0], dy - attach[0, 1], dz - attach[0, 2]
            k0, k1, k2 = cable_moment_arm(uavs, i, uav_rotation_i, dx, dy, dz)
        cables[i, CABLE_OFFSET], cables[i, CABLE_OFFSET + 1], cables[i, CABLE_OFFSET + 2] = \
            dx, dy, dz
        cables[i, CABLE_MOMENT], cables[i, CABLE_MOMENT + 1], cables[i, CABLE_MOMENT + 2] = \
            k0, k1, k2
        cables[i, CABLE_INV_DELTA] = inverse_delta(uavs, i, dx * dx + dy * dy + dz * dz,
                                                   k0, k1, k2)
        cables[i, CABLE_RHS] = rhs[i]
    cable_multipliers(cables, formation[FORMATION_PAYLOAD_MASS], taut, out)


@jit
def move_along_cables(x, uavs, formation, z, start, cables):
    """x moved by -M^-1 G^T z (the rows of `cables`, `mass_metric_solve`'s): UAV i by
    +2 z_i d_i / m_i and, held off its centre, turned by J_i^-1 (2 z_i k_i) (body FLU); the
    payload by -2 sum_i z_i d_i / m_p and, a rigid one, turned by -2 J_p^-1 sum_i z_i c_i
    (payload frame). start = 0 moves the positions [m] and attitudes (each quaternion q ->
    q (x) (1, turn / 2), back to unit length: to first order, as the projection's Newton steps
    are), start = 3n + 3 the velocities [m/s] and body rates [rad/s]."""
    n = uavs.shape[0]
    p = start + payload_slot(n)
    inv_payload_mass = formation[FORMATION_INV_PAYLOAD_MASS]
    for i in range(n):
        r = start + uav_slot(i) + POSITION
        for k in range(3):
            pull = 2.0 * z[i] * cables[i, CABLE_OFFSET + k]  # G^T z of this body
            x[r + k] += pull / uavs[i, UAV_MASS]
            x[p + k] -= pull * inv_payload_mass
        if attached_off_centre(uavs, i):  # the impulse's moment about UAV i's centre
            base = uav_attitude_slot(n, i)
            if start == 0:
                t0, t1, t2 = cable_turn(uavs, i, 2.0 * z[i], cables[i, CABLE_MOMENT],
                                        cables[i, CABLE_MOMENT + 1], cables[i, CABLE_MOMENT + 2])
                turn_quaternion(x, base, t0, t1, t2)
            else:
                add_cable_torque(uavs, i, x, base + BODY_RATES, 2.0 * z[i],
                                 cables[i, CABLE_MOMENT], cables[i, CABLE_MOMENT + 1],
                                 cables[i, CABLE_MOMENT + 2])
    if x.shape[0] > attitude_slot(n):  # a rigid payload's rotation
        base = attitude_slot(n)
        turn0 = turn1 = turn2 = 0.0
        for i in range(n):
            turn0 += z[i] * cables[i, CABLE_PAYLOAD_MOMENT]
            turn1 += z[i] * cables[i, CABLE_PAYLOAD_MOMENT + 1]
            turn2 += z[i] * cables[i, CABLE_PAYLOAD_MOMENT + 2]
        turn0 *= -2.0 / formation[FORMATION_PAYLOAD_INERTIA]
        turn1 *= -2.0 / formation[FORMATION_PAYLOAD_INERTIA + 1]
        turn2 *= -2.0 / formation[FORMATION_PAYLOAD_INERTIA + 2]
        if start == 0:
            turn_quaternion(x, base, turn0, turn1, turn2)
        else:
            x[base + PAYLOAD_BODY_RATES] += turn0
            x[base + PAYLOAD_BODY_RATES + 1] += turn1
            x[base + PAYLOAD_BODY_RATES + 2] += turn2


@jit
def snap_velocities(x, uavs, formation, taut, g, g_dot, impulses, cables):
    """x's velocities projected so that every `taut` cable has g_dot = 0: u+ = u - M^-1 G^T
    (G M^-1 G^T)^-1 G u, an inelastic impulse along the cables (the bodies' rotations in M
    and G: docs/rigid_payload.md; linear and angular momentum kept, kinetic energy not
    increased). Writes x; g, g_dot, impulses (n,) scratch."""
    residuals(x, uavs, g, g_dot)
    mass_metric_solve(x, uavs, formation, taut, g_dot, impulses, cables)
    nq = rates_slot(uavs.shape[0])
    move_along_cables(x, uavs, formation, impulses, nq, cables)


@jit
def project_lengths(x, uavs, formation, taut, snapping, g, g_dot, target, shifts, cables):
    """x's positions moved, in the mass metric (the centre of mass stays), until the
    `snapping` cables have g = 0 while the other taut ones keep their g: Newton steps
    dq = -M^-1 G^T (G M^-1 G^T)^-1 (g - g_target) over the taut set. At a located event the
    residual is ~1e-12 l^2, so the first step already leaves rounding. Writes x."""
    n = uavs.shape[0]
    residuals(x, uavs, g, g_dot)
    for i in range(n):
        target[i] = 0.0 if snapping[i] else g[i]
    for _ in range(2):
        residuals(x, uavs, g, g_dot)
        for i in range(n):
            g[i] -= target[i]
        mass_metric_solve(x, uavs, formation, taut, g, shifts, cables)
        move_along_cables(x, uavs, formation, shifts, 0, cables)


@jit
def snap(x, uavs, formation, taut, snapping, values, cables):
    """The `snapping` (slack) cables become taut at x (taut updated): positions projected
    onto their length, then the inelastic, momentum-conserving velocity jump. Writes x;
    values (SLACK_CABLE_ROWS, n) scratch."""
    for i in range(uavs.shape[0]):
        taut[i] = taut[i] or snapping[i]
    g, g_dot = values[SLACK_G_END], values[SLACK_G_DOT_END]
    project_lengths(x, uavs, formation, taut, snapping, g, g_dot, values[SLACK_TARGET],
                    values[SLACK_SOLUTION], cables)
    snap_velocities(x, uavs, formation, taut, g, g_dot, values[SLACK_SOLUTION], cables)


@jit
def update_taut_set(x, wrenches, uavs, gusts, formation, taut, multipliers, acc, cables):
    """Drop taut cables whose multiplier would push (lambda_i < 0), most negative first,
    until none does; their multipliers [N/m] at x into multipliers (n,)."""
    while True:
        solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers, cables)
        worst, lowest = -1, 0.0
        for i in range(uavs.shape[0]):
            if taut[i] and multipliers[i] < lowest:
                worst, lowest = i, multipliers[i]
        if worst < 0:
            return
        taut[worst] = False


@jit
def snap_separating(state, wrenches, uavs, gusts, formation, taut, released, g, g_dot, values,
                    flags, work, cables):
    """After a snap: a slack cable (not `released`) that its impulse leaves at its length
    (|g_i| within EVENT_TOLERANCE l_i^2) and separating (g_dot_i > 0) snaps at once with the
    taut ones, the taut set updated again (at most n rounds). Without it two cables that both
    reach their lengths would take turns, each one's impulse pulling the other taut within
    the next microseconds, and the last would snap only at the step's end, past its length.
    state, taut, g [m^2], g_dot [m^2/s] updated."""
    n = uavs.shape[0]
    snapping = flags[SLACK_SNAPPING]
    for _ in range(n):
        any_snapping = False
        for i in range(n):
            snapping[i] = (not taut[i] and not released[i] and g_dot[i] > 0.0
                           and g[i] >= -EVENT_TOLERANCE * uavs[i, UAV_LENGTH_SQ])
            any_snapping = any_snapping or snapping[i]
        if not any_snapping:
            return
        snap(state, uavs, formation, taut, snapping, values, cables)
        update_taut_set(state, wrenches, uavs, gusts, formation, taut,
                        values[SLACK_MULTIPLIERS], work[WORK_ACC], cables)
        residuals(state, uavs, g, g_dot)


@jit
def slack_step(state, wrenches, uavs, gusts, formation, taut, released, dt, g, g_dot, states,
               values, flags, work, cables):
    """One RK4 step of dt [s] from state (whose residuals are g, g_dot), cut at each taut
    event of a cable not `released`: the state at its end into state, its g [m^2], g_dot
    [m^2/s] into g, g_dot."""
    n = uavs.shape[0]
    end = states[SLACK_END]
    g_end, g_dot_end = values[SLACK_G_END], values[SLACK_G_DOT_END]
    snapping = flags[SLACK_SNAPPING]
    left, events = dt, 0
    while True:
        rk4_step(state, wrenches, uavs, gusts, formation, taut, left, end,
                 values[SLACK_MULTIPLIERS], work, cables)
        residuals(end, uavs, g_end, g_dot_end)
        if taut.all():
            state[:] = end
            g[:] = g_end
            g_dot[:] = g_dot_end
            return
        # an event makes a cable taut: a few per step at most (a bound against cycling)
        tau = taut_event(state, wrenches, uavs, gusts, formation, taut, released, left, g,
                         g_dot, states, values, flags, work, cables) if events <= 2 * n else -1.0
        if tau < 0.0:
            break
        events += 1
        state[:] = states[SLACK_EVENT]
        snap(state, uavs, formation, taut, snapping, values, cables)
        # a new taut cable may not hold (it would push)
        update_taut_set(state, wrenches, uavs, gusts, formation, taut,
                        values[SLACK_MULTIPLIERS], work[WORK_ACC], cables)
        residuals(state, uavs, g, g_dot)
        snap_separating(state, wrenches, uavs, gusts, formation, taut, released, g, g_dot,
                        values, flags, work, cables)
        left -= tau
        if left <= 0.0:
            return
    # no crossing located: a cable already at its length when it went slack (g_i >= 0 at
    # the step's start, so no sign change) that separates at the end snaps there
    state[:] = end
    any_snapping = False
    for i in range(n):
        snapping[i] = (not taut[i] and not released[i] and g_end[i] >= 0.0
                       and g_dot_end[i] > 0.0)
        any_snapping = any_snapping or snapping[i]
    g[:] = g_end
    g_dot[:] = g_dot_end
    if any_snapping:
        snap(state, uavs, formation, taut, snapping, values, cables)
        residuals(state, uavs, g, g_dot)


@jit
def integrate_period(x, wrenches, uavs, gusts, formation, taut, released, dt, steps):
    """`steps` RK4 steps of dt [s] from x with the wrenches held, cables going slack (at each
    step's start, when their multiplier would push) and snapping taut (at the located event;
    never a `released` one, (n,) bool):
    (the state at the end, the multipliers [N/m] at x after the taut set's update there,
    g [m^2] and g_dot [m^2/s] at the end). taut (n,) bool is updated; x is not written."""
    n = uavs.shape[0]
    size = x.shape[0]  # 2 (3n + 3), the UAVs' attitudes and a rigid payload's
    work = np.empty((WORK_ROWS, size))
    states = np.empty((SLACK_STATES, size))
    values = np.empty((SLACK_CABLE_ROWS, n))
    flags = np.zeros((SLACK_FLAGS, n), dtype=np.bool_)
    cables = np.empty((n, CABLE_COLUMNS))
    first = np.empty(n)
    g = np.empty(n)
    g_dot = np.empty(n)
    state = x.copy()
    update_taut_set(state, wrenches, uavs, gusts, formation, taut, first, work[WORK_ACC], cables)
    residuals(state, uavs, g, g_dot)
    for step in range(steps):
        if step:
            update_taut_set(state, wrenches, uavs, gusts, formation, taut,
                            values[SLACK_MULTIPLIERS], work[WORK_ACC], cables)
        slack_step(state, wrenches, uavs, gusts, formation, taut, released, dt, g, g_dot,
                   states, values, flags, work, cables)
    return state, first, g, g_dot
