"""The run statistics' per-tick accumulation and seed Algorithm 1's check (lines 10-13),
compiled: numba functions that update the float accumulator arrays of
`multilift_sim.statistics.layout` in place. One formation's arrays per call, so a compiled
tick (or a batch of them) calls them as they are; `multilift_sim.statistics.figures` holds the
arrays behind the classes the simulator and the controllers use.

Each comparison keeps the semantics of Python's max/min that the figures were defined with: a
value replaces the figure only when it compares greater (smaller), so NaN never does.
"""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.kernels import jit
from multilift_sim.physics.attitude import quaternion_norm_error
from multilift_sim.physics.chain_cables import cable_paths
from multilift_sim.physics.layout import (POSITION, REEL_LENGTH, UAV_CABLE_STIFFNESS,
                                          UAV_COORDINATES)
from multilift_sim.physics.state_slots import (attitude_slot, payload_slot,
                                               rigid_payload_state, uav_attitude_slot,
                                               uav_slot)
from multilift_sim.statistics.layout import (
    CHECK_G, CHECK_G_DOT, CHECK_NON_FINITE, CHECK_OK, CHECK_QUATERNION, FORMATION_MAX_ABS,
    FORMATION_NORM_SUM, FORMATION_SAMPLES, PEAK_MAX, PEAK_SAMPLES, PEAK_SUM_SQ,
    QUATERNION_NORM_TOLERANCE, RUN_COMPRESSED_TIME, RUN_LEAST_THRUST_MARGIN, RUN_MAX_ABS_G,
    RUN_MAX_ABS_G_DOT, RUN_MAX_GUST_SPEED, RUN_MAX_ROTOR_SPEED, RUN_MAX_SAG, RUN_MAX_STRETCH,
    RUN_LONGEST_CABLE, RUN_MAX_TENSION, RUN_MIN_TENSION, RUN_PEAK_TENSION, RUN_SATURATED_TIME,
    RUN_SCALARS, RUN_SHORTEST_CABLE,
    RUN_SIMULATED_TIME, RUN_SLACK_TIME, RUN_SWING, RUN_UAV_COLUMNS, SWING_FROM, TRACKING_ERROR)
from multilift_sim.statistics.swing import swing_at


@jit
def peak_rms_add(acc: np.ndarray, block: int, value: float) -> None:
    """One sample of a non-negative signal into the peak/rms block at `block` (PEAK_*)."""
    if value > acc[block + PEAK_MAX]:
        acc[block + PEAK_MAX] = value
    acc[block + PEAK_SUM_SQ] += value * value
    acc[block + PEAK_SAMPLES] += 1.0


@jit
def run_add_commands(run: np.ndarray, rotor_speeds: np.ndarray, saturated: np.ndarray,
                     period: float) -> None:
    """One control period [s] of commands: each UAV's rotor speeds, a row of (n, k) [rad/s]
    (its peak |speed| raises the UAV's max; k = 1: the peak itself; padded with 0), and its
    saturation flags, a row of (n, m) bool (any set: the period counts as saturated; padded
    with False)."""
    for i in range(rotor_speeds.shape[0]):
        block = RUN_SCALARS + RUN_UAV_COLUMNS * i
        peak = abs(rotor_speeds[i, 0])
        for r in range(1, rotor_speeds.shape[1]):
            if abs(rotor_speeds[i, r]) > peak:
                peak = abs(rotor_speeds[i, r])
        if peak > run[block + RUN_MAX_ROTOR_SPEED]:
            run[block + RUN_MAX_ROTOR_SPEED] = peak
        for r in range(saturated.shape[1]):
            if saturated[i, r]:
                run[block + RUN_SATURATED_TIME] += period
                break


@jit
def run_add_thrust_margin(run: np.ndarray, rotor_speeds: np.ndarray, effectiveness: np.ndarray,
                          allocation: np.ndarray, rotor_speed_max: np.ndarray) -> None:
    """One control period of commands: each UAV's thrust margin 1 - u_T / u_T,max lowers its
    least (RUN_LEAST_THRUST_MARGIN): u_T = sum_r k_T,r e_r omega_r^2 of the commanded speeds
    (n, rotors) [rad/s] and u_T,max the same at rotor_speed_max (n,) [rad/s], with the
    allocation's thrust row (n, 4, rotors) (seed Eq. 2.14) and the rotors' effectiveness
    (n, rotors) in [0, 1] (a failed rotor lifts nothing, nor counts in the largest thrust).
    A UAV without a command (NaN) or that can lift nothing is left as it is."""
    for i in range(rotor_speeds.shape[0]):
        top = rotor_speed_max[i] * rotor_speed_max[i]
        thrust = largest = 0.0
        for r in range(rotor_speeds.shape[1]):
            lift = allocation[i, 0, r] * effectiveness[i, r]
            thrust += lift * rotor_speeds[i, r] * rotor_speeds[i, r]
            largest += lift * top
        if largest > 0.0 and not math.isnan(thrust):
            margin = 1.0 - thrust / largest
            slot = RUN_SCALARS + RUN_UAV_COLUMNS * i + RUN_LEAST_THRUST_MARGIN
            if margin < run[slot]:
                run[slot] = margin


@jit
def run_add_compression(run: np.ndarray, tension: np.ndarray, period: float) -> None:
    """One control period [s] starting with the cable tensions T_i (n,) [N]: when a cable
    pushes (T_i < 0, which rigid cables allow), the period counts as compressed."""
    for i in range(tension.shape[0]):
        if tension[i] < 0.0:
            run[RUN_COMPRESSED_TIME] += period
            return


@jit
def run_add_tensions(run: np.ndarray, tension: np.ndarray) -> None:
    """The cable tensions T_i (n,) [N] of one tick into the min and max tension."""
    low, high = tension[0], tension[0]
    for i in range(1, tension.shape[0]):
        if tension[i] < low:
            low = tension[i]
        if tension[i] > high:
            high = tension[i]
    if low < run[RUN_MIN_TENSION]:
        run[RUN_MIN_TENSION] = low
    if high > run[RUN_MAX_TENSION]:
        run[RUN_MAX_TENSION] = high


@jit
def run_add_ropes(run: np.ndarray, state: np.ndarray, lengths: np.ndarray,
                  tension: np.ndarray) -> None:
    """Elastic ropes (cable_model: elastic) at one tick: each rope's stretch L_i - l_i [m]
    (L_i = |r_p - r_i| in the formation state x, l_i its rest length, `lengths` (n,) [m];
    negative when slack) and its tension T_i (n,) [N] raise its maxima (RUN_MAX_STRETCH,
    RUN_PEAK_TENSION)."""
    n = tension.shape[0]
    p = payload_slot(n)
    for i in range(n):
        r = uav_slot(i) + POSITION
        dx, dy, dz = state[p] - state[r], state[p + 1] - state[r + 1], state[p + 2] - state[r + 2]
        stretch = math.sqrt(dx * dx + dy * dy + dz * dz) - lengths[i]
        block = RUN_SCALARS + RUN_UAV_COLUMNS * i
        if stretch > run[block + RUN_MAX_STRETCH]:
            run[block + RUN_MAX_STRETCH] = stretch
        if tension[i] > run[block + RUN_PEAK_TENSION]:
            run[block + RUN_PEAK_TENSION] = tension[i]


@jit
def run_add_chains(run: np.ndarray, state: np.ndarray, uavs: np.ndarray, inner: int,
                   lengths: np.ndarray, tension: np.ndarray) -> None:
    """Heavy cables (cable_model: chain) at one tick: each cable's sag, the largest distance
    [m] of its `inner` nodes from its chord (from where it holds its UAV to where it holds the
    payload, `chain_cables.cable_paths`), raises its maximum (RUN_MAX_SAG); with elastic links
    (UAV_CABLE_STIFFNESS > 0) its stretch, the links' summed lengths less its rest length
    `lengths` (n,) [m], and its top link's tension `tension` (n,) [N] raise theirs
    (RUN_MAX_STRETCH, RUN_PEAK_TENSION)."""
    paths = cable_paths(state, uavs, inner)
    for i in range(paths.shape[0]):
        path = paths[i]
        cx, cy, cz = path[-1, 0] - path[0, 0], path[-1, 1] - path[0, 1], path[-1, 2] - path[0, 2]
        chord_sq = cx * cx + cy * cy + cz * cz
        sag = 0.0
        for k in range(1, inner + 1):
            ex, ey, ez = path[k, 0] - path[0, 0], path[k, 1] - path[0, 1], path[k, 2] - path[0, 2]
            along = (ex * cx + ey * cy + ez * cz) / chord_sq if chord_sq > 0.0 else 0.0
            off = math.sqrt((ex - along * cx) ** 2 + (ey - along * cy) ** 2
                            + (ez - along * cz) ** 2)
            if off > sag:
                sag = off
        block = RUN_SCALARS + RUN_UAV_COLUMNS * i
        if sag > run[block + RUN_MAX_SAG]:
            run[block + RUN_MAX_SAG] = sag
        if uavs[i, UAV_CABLE_STIFFNESS] > 0.0:
            span = 0.0
            for k in range(inner + 1):
                dx, dy, dz = (path[k + 1, 0] - path[k, 0], path[k + 1, 1] - path[k, 1],
                              path[k + 1, 2] - path[k, 2])
                span += math.sqrt(dx * dx + dy * dy + dz * dz)
            if span - lengths[i] > run[block + RUN_MAX_STRETCH]:
                run[block + RUN_MAX_STRETCH] = span - lengths[i]
            if tension[i] > run[block + RUN_PEAK_TENSION]:
                run[block + RUN_PEAK_TENSION] = tension[i]


@jit
def run_add_reel(run: np.ndarray, reel: np.ndarray, lengths: np.ndarray) -> None:
    """Winches at one tick: each cable's reeled length (reel (n, REEL_COLUMNS), physics.winch)
    widens its range (RUN_SHORTEST_CABLE, RUN_LONGEST_CABLE); `lengths` (n,) [m] the start's,
    which the range holds from the first tick."""
    for i in range(reel.shape[0]):
        block = RUN_SCALARS + RUN_UAV_COLUMNS * i
        for length in (lengths[i], reel[i, REEL_LENGTH]):
            if length < run[block + RUN_SHORTEST_CABLE]:
                run[block + RUN_SHORTEST_CABLE] = length
            if length > run[block + RUN_LONGEST_CABLE]:
                run[block + RUN_LONGEST_CABLE] = length


@jit
def run_add_slack(run: np.ndarray, taut: np.ndarray, period: float) -> None:
    """A control period [s] ending with these cables taut (n,) bool (cable_model: slack)."""
    for i in range(taut.shape[0]):
        if not taut[i]:
            run[RUN_SCALARS + RUN_UAV_COLUMNS * i + RUN_SLACK_TIME] += period


@jit
def run_add_gust_speed(run: np.ndarray, speed: float) -> None:
    """The gust speed [m/s] the payload meets at one tick into the peak."""
    if speed > run[RUN_MAX_GUST_SPEED]:
        run[RUN_MAX_GUST_SPEED] = speed


@jit
def run_check(run: np.ndarray, state: np.ndarray, g: np.ndarray, g_dot: np.ndarray,
              taut: np.ndarray, constraint_tolerance: float, rate_tolerance: float, t: float,
              tick: int, swing_every: int, reach: np.ndarray) -> tuple[int, int]:
    """Algorithm 1, lines 10-13, at the state x (docs/conventions.md) of time t [s]: the
    constraint residuals g (n,) [m^2] and g_dot (n,) [m^2/s] of the taut cables (taut (n,)
    bool: the tolerances hold for those only) into the run's peaks, the payload swing when
    tick % swing_every == 0 and t >= SWING_FROM (`swing_at` under the UAVs whose cables are
    taut, with their reach (n,) [m]: a released or slack cable holds nothing), the simulated
    time.

    Returns (status, cable): CHECK_NON_FINITE (the state is not finite; nothing accumulated),
    CHECK_QUATERNION (body `cable`'s quaternion, UAV `cable` or the rigid payload's at n, is
    more than QUATERNION_NORM_TOLERANCE off unit length: no attitude; nothing accumulated;
    `quaternion_fault`), CHECK_G or CHECK_G_DOT (the first
    cable of the largest |g| or |g_dot| is over its tolerance; |g| is checked first), else
    CHECK_OK; cable: that cable (from 0), else -1.
    """
    for value in state:
        if not math.isfinite(value):
            return CHECK_NON_FINITE, -1
    body = quaternion_fault(state, g.shape[0])
    if body >= 0:
        return CHECK_QUATERNION, body
    peak, worst, peak_rate, worst_rate = -1.0, -1, -1.0, -1
    for i in range(g.shape[0]):
        abs_g, abs_g_dot = (abs(g[i]), abs(g_dot[i])) if taut[i] else (0.0, 0.0)
        if worst < 0 or abs_g > peak:
            peak, worst = abs_g, i
        if worst_rate < 0 or abs_g_dot > peak_rate:
            peak_rate, worst_rate = abs_g_dot, i
    if peak > run[RUN_MAX_ABS_G]:
        run[RUN_MAX_ABS_G] = peak
    if peak_rate > run[RUN_MAX_ABS_G_DOT]:
        run[RUN_MAX_ABS_G_DOT] = peak_rate
    if tick % swing_every == 0 and t >= SWING_FROM:
        n = g.shape[0]
        held = 0  # the swing under the UAVs whose cables hold the payload (not a released one)
        for i in range(n):
            if taut[i]:
                held += 1
        payload = state[payload_slot(n):payload_slot(n) + 3]
        if held == n:  # every cable holds it (no copy)
            uavs = state[:payload_slot(n)].reshape((n, UAV_COORDINATES))
            peak_rms_add(run, RUN_SWING, swing_at(uavs[:, POSITION:POSITION + 3], payload,
                                                  reach))
        elif held > 0:
            held_uavs = np.empty((held, 3))
            reaches = np.empty(held)
            k = 0
            for i in range(n):
                if taut[i]:
                    for axis in range(3):
                        held_uavs[k, axis] = state[uav_slot(i) + POSITION + axis]
                    reaches[k] = reach[i]
                    k += 1
            peak_rms_add(run, RUN_SWING, swing_at(held_uavs, payload, reaches))
    run[RUN_SIMULATED_TIME] = t
    if peak > constraint_tolerance:
        return CHECK_G, worst
    if peak_rate > rate_tolerance:
        return CHECK_G_DOT, worst_rate
    return CHECK_OK, -1


@jit
def quaternion_fault(state: np.ndarray, n: int) -> int:
    """The first body whose attitude quaternion is more than QUATERNION_NORM_TOLERANCE off
    unit length in a state of n UAVs (UAV i as i, a rigid payload as n), else -1."""
    for i in range(n):
        if quaternion_norm_error(state, uav_attitude_slot(n, i)) > QUATERNION_NORM_TOLERANCE:
            return i
    if rigid_payload_state(state.shape[0], n) and quaternion_norm_error(
            state, attitude_slot(n)) > QUATERNION_NORM_TOLERANCE:
        return n
    return -1


@jit
def tracking_add(acc: np.ndarray, reference_position: np.ndarray, position: np.ndarray) -> None:
    """The leader's tracking error |r_ref - r_1| [m] of one tick (world, (3,) each)."""
    dx = reference_position[0] - position[0]
    dy = reference_position[1] - position[1]
    dz = reference_position[2] - position[2]
    peak_rms_add(acc, TRACKING_ERROR, math.sqrt(dx * dx + dy * dy + dz * dz))


@jit
def formation_error_add(acc: np.ndarray, residual: np.ndarray) -> None:
    """A follower's virtual-constraint residual g_vc (m,) [m] of one tick: its largest
    |component| into the peak, its Euclidean norm into the sum."""
    if residual.shape[0]:
        largest, sum_sq = abs(residual[0]), 0.0
        for k in range(residual.shape[0]):
            value = residual[k]
            if abs(value) > largest:
                largest = abs(value)
            sum_sq += value * value
        if largest > acc[FORMATION_MAX_ABS]:
            acc[FORMATION_MAX_ABS] = largest
        acc[FORMATION_NORM_SUM] += math.sqrt(sum_sq)
    acc[FORMATION_SAMPLES] += 1.0
