"""Elastic cables (`cable_model: elastic`, issue 32): each cable a rope along its chord that
pulls T_i = k_i (L_i - l_i) + c_i L_i_dot when stretched (L_i = |r_p - r_i| beyond its rest
length l_i) and nothing otherwise (a rope pushes never: T_i >= 0). No constraint and no
multipliers: the formation is n + 1 free bodies, each UAV on its own attitude
(`free_motion.uav_free_motion`), the payload under its drag (Eq. 2.53). World frame (z up),
SI units; slots: `physics.layout` (UAV_CABLE_STIFFNESS, UAV_CABLE_DAMPING).

A stiff rope is a fast oscillator: RK4 is stable below omega h = 2.8 and loses about
(omega h)^6 / 72 of an oscillation's energy per step, so the scenario's validation asks for
sub-steps (`simulation.substeps`, FORMATION_SUBSTEPS) until omega h <= ELASTIC_OMEGA_H
(`scenario.limits`), omega bounded by the mass-spring system's largest eigenfrequency
(Gershgorin: omega^2 <= 2 max(k_i / m_i, sum_i k_i / m_p)).
"""
import math

from multilift_sim.kernels import jit
from multilift_sim.physics.free_motion import payload_motion, uav_free_motion
from multilift_sim.physics.layout import (FORMATION_GRAVITY, FORMATION_INV_PAYLOAD_MASS,
                                          FORMATION_TIME, FORMATION_WINCH, POSITION,
                                          UAV_CABLE_DAMPING, UAV_CABLE_STIFFNESS, UAV_LENGTH_SQ,
                                          UAV_MASS)
from multilift_sim.physics.state_slots import payload_slot, rates_slot, uav_slot
from multilift_sim.physics.winch import reel_at


@jit
def rope_tension(stiffness, damping, rest, dx, dy, dz, dvx, dvy, dvz, rest_rate):
    """(T [N], L [m]) of a rope of stiffness k [N/m], damping c [N s/m] and rest length l [m]
    (paid out at l_dot = rest_rate [m/s] by a winch, else 0) whose ends are d = (dx, dy, dz)
    [m] apart, moving apart at dv [m/s]: k (L - l) + c (L_dot - l_dot) when L > l, floored at
    0 (no push), else 0."""
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    if length <= rest:
        return 0.0, length
    rate = (dx * dvx + dy * dvy + dz * dvz) / length - rest_rate
    tension = stiffness * (length - rest) + damping * rate
    return (tension if tension > 0.0 else 0.0), length


@jit
def elastic_solve(x, wrenches, uavs, gusts, formation, taut, acc, multipliers):
    """The state's rates into acc (the translations' accelerations [m/s^2], then each UAV's
    attitude block's rates, `uav_free_motion`) at state x, the cables elastic; each cable's
    tension T_i [N] into multipliers (n,) as T_i / (2 l_i) [N/m], so that the tick's
    T_i = 2 l_i lambda_i reads it as it reads a rigid cable's. A cable let go of (`taut`
    False: a cable_release event) pulls no more."""
    n = uavs.shape[0]
    p = payload_slot(n)
    nq = rates_slot(n)
    px, py, pz, pvx, pvy, pvz, drag_ax, drag_ay, drag_az = payload_motion(x, n, gusts,
                                                                          formation)
    gravity = formation[FORMATION_GRAVITY]
    pull_x = pull_y = pull_z = 0.0   # the cables' pull on the payload [N]
    for i in range(n):
        r = uav_slot(i) + POSITION
        thrust_ax, thrust_ay, thrust_az = uav_free_motion(x, i, wrenches, uavs, formation, acc)
        dx, dy, dz = px - x[r], py - x[r + 1], pz - x[r + 2]
        rest = math.sqrt(uavs[i, UAV_LENGTH_SQ])
        stiffness, damping = uavs[i, UAV_CABLE_STIFFNESS], uavs[i, UAV_CABLE_DAMPING]
        reel_rate = 0.0
        if formation[FORMATION_WINCH] != 0.0:  # a reeled rope (physics.winch): its rest length
            # l(t), its stiffness and damping EA / l and c l_0 / l, its stretch rate L_dot - l_dot
            reeled, reel_rate, _ = reel_at(uavs, i, formation[FORMATION_TIME])
            stiffness, damping = stiffness * rest / reeled, damping * rest / reeled
            rest = reeled
        tension, length = 0.0, 1.0
        if taut[i]:
            tension, length = rope_tension(stiffness, damping, rest, dx, dy, dz,
                                           pvx - x[nq + r], pvy - x[nq + r + 1],
                                           pvz - x[nq + r + 2], reel_rate)
        multipliers[i] = 0.5 * tension / rest
        per_length = tension / length if tension > 0.0 else 0.0   # T / L [N/m]
        pull = per_length / uavs[i, UAV_MASS]
        acc[r] = thrust_ax + pull * dx
        acc[r + 1] = thrust_ay + pull * dy
        acc[r + 2] = thrust_az + pull * dz - gravity
        pull_x -= per_length * dx
        pull_y -= per_length * dy
        pull_z -= per_length * dz
    inverse_mass = formation[FORMATION_INV_PAYLOAD_MASS]
    acc[p] = drag_ax + pull_x * inverse_mass
    acc[p + 1] = drag_ay + pull_y * inverse_mass
    acc[p + 2] = drag_az + pull_z * inverse_mass - gravity
