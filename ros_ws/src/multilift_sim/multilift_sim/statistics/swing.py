"""The payload swing, compiled: the payload's static-equilibrium place under UAVs held where
they are (the lowest point within reach of every cable) and its horizontal distance from the
payload. numba functions over float arrays, no Python objects: a point is an (x, y, z) tuple,
NaN where there is none (the cables cannot meet). `multilift_sim.statistics.figures` wraps
them for plain inputs. World frame z up [m].
"""
from __future__ import annotations

import math

import numpy as np

from multilift_sim.kernels import jit

# How far outside a ball a candidate may lie and still count as inside it [m].
FEASIBILITY = 1e-9
# How many of the most restrictive cables start the active-set search (`equilibrium_point`).
WORKING_SET = 6
_VELTKAMP = 134217729.0             # 2^27 + 1: splits a double into two halves
_DBL_MIN = 2.2250738585072014e-308  # the smallest normal double


@jit
def _two_product(x: float, y: float) -> tuple[float, float]:
    """(x y rounded, its exact rounding error) (Dekker: Veltkamp's split, no fma)."""
    p = x * y
    t = x * _VELTKAMP
    xh = t - (t - x)
    xl = x - xh
    t = y * _VELTKAMP
    yh = t - (t - y)
    yl = y - yh
    return p, ((xh * yh - p) + xh * yl + xl * yh) + xl * yl


@jit
def hypot2(x: float, y: float) -> float:
    """sqrt(x^2 + y^2) bit for bit as CPython's math.hypot of two floats (its vector_norm:
    power-of-two scaling, exact squares, compensated sum, a corrected square root), so the
    compiled swing gives the numbers the Python statistics gave; libm's hypot, which numba
    calls, differs in the last bit about once in a thousand."""
    x = abs(x)
    y = abs(y)
    largest = 0.0
    if x > largest:
        largest = x
    if y > largest:
        largest = y
    if math.isinf(largest):
        return largest
    if math.isnan(x) or math.isnan(y):
        return math.nan
    if largest == 0.0:
        return largest
    unscale = 1.0
    exponent = math.frexp(largest)[1]
    if exponent < -1023:                        # subnormal: ldexp(1, -exponent) would overflow
        x /= _DBL_MIN
        y /= _DBL_MIN
        unscale = _DBL_MIN
        exponent = math.frexp(largest / _DBL_MIN)[1]
    scale = math.ldexp(1.0, -exponent)
    total, frac1, frac2 = 1.0, 0.0, 0.0
    for value in (x * scale, y * scale):
        hi, lo = _two_product(value, value)
        summed = total + hi
        frac2 += (total - summed) + hi
        total = summed
        frac1 += lo
    h = math.sqrt(total - 1.0 + (frac1 + frac2))
    hi, lo = _two_product(-h, h)
    summed = total + hi
    frac2 += (total - summed) + hi
    total = summed
    frac1 += lo
    h += (total - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return unscale * (h / scale)


@jit
def sphere_pair_lowest(x1: float, y1: float, z1: float, r1: float, x2: float, y2: float,
                       z2: float, r2: float) -> tuple[float, float, float]:
    """Lowest point of the circle where the spheres (c1, r1) and (c2, r2) meet (NaN: none)."""
    ax, ay, az = x2 - x1, y2 - y1, z2 - z1
    d = math.sqrt(ax * ax + ay * ay + az * az)
    if d < 1e-12 or d > r1 + r2 or d < abs(r1 - r2):
        return math.nan, math.nan, math.nan
    ax, ay, az = ax / d, ay / d, az / d
    a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    across = r1 * r1 - a * a
    if 0.0 > across:
        across = 0.0
    radius = math.sqrt(across)
    # -e_z without its part along the axis
    dx, dy, dz = ax * az, ay * az, -1.0 + az * az
    norm = math.sqrt(dx * dx + dy * dy + dz * dz)
    if norm < 1e-12:                                            # vertical axis: any point
        dx, dy, dz = 0.0, az, -ay                               # axis x e_x
        norm = math.sqrt(dy * dy + dz * dz)
    k = radius / norm
    return x1 + a * ax + k * dx, y1 + a * ay + k * dy, z1 + a * az + k * dz


@jit
def sphere_triple_lowest(x1: float, y1: float, z1: float, r1: float, x2: float, y2: float,
                         z2: float, r2: float, x3: float, y3: float, z3: float,
                         r3: float) -> tuple[float, float, float]:
    """The lower of the (at most two) points where three spheres meet (NaN: none)."""
    ex, ey_, ez_ = x2 - x1, y2 - y1, z2 - z1
    d = math.sqrt(ex * ex + ey_ * ey_ + ez_ * ez_)
    if d < 1e-12:
        return math.nan, math.nan, math.nan
    ex, ey_, ez_ = ex / d, ey_ / d, ez_ / d                     # e_x, the unit axis 1 -> 2
    wx, wy, wz = x3 - x1, y3 - y1, z3 - z1
    i = ex * wx + ey_ * wy + ez_ * wz
    fx, fy, fz = wx - i * ex, wy - i * ey_, wz - i * ez_        # e_y before its norm
    j = math.sqrt(fx * fx + fy * fy + fz * fz)
    if j < 1e-12:
        return math.nan, math.nan, math.nan
    fx, fy, fz = fx / j, fy / j, fz / j
    gx, gy, gz = ey_ * fz - ez_ * fy, ez_ * fx - ex * fz, ex * fy - ey_ * fx  # e_z = e_x x e_y
    x = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d)
    y = (r1 * r1 - r3 * r3 + i * i + j * j) / (2.0 * j) - i * x / j
    z_sq = r1 * r1 - x * x - y * y
    if z_sq < 0.0:
        return math.nan, math.nan, math.nan
    bx, by, bz = x1 + x * ex + y * fx, y1 + x * ey_ + y * fy, z1 + x * ez_ + y * fz
    z = math.sqrt(z_sq)
    if bz + z * gz <= bz - z * gz:
        return bx + z * gx, by + z * gy, bz + z * gz
    return bx - z * gx, by - z * gy, bz - z * gz


@jit
def lowest_of_two(uavs: np.ndarray, lengths: np.ndarray) -> tuple[float, float, float]:
    """`equilibrium_point` for one or two UAVs: uavs (n, 3) [m], lengths (n,) [m]."""
    x1, y1, z1, l1 = uavs[0, 0], uavs[0, 1], uavs[0, 2], lengths[0]
    if uavs.shape[0] == 1:
        return x1, y1, z1 - l1
    x2, y2, z2, l2 = uavs[1, 0], uavs[1, 1], uavs[1, 2], lengths[1]
    dx, dy, dz = x2 - x1, y2 - y1, z2 - z1
    # a ball's bottom inside the other ball: that cable alone holds the payload
    below, reach = dz + l1, l2 * (1.0 + FEASIBILITY)
    if dx * dx + dy * dy + below * below <= reach * reach:
        return x1, y1, z1 - l1
    below, reach = dz - l2, l1 * (1.0 + FEASIBILITY)
    if dx * dx + dy * dy + below * below <= reach * reach:
        return x2, y2, z2 - l2
    # the lowest point of the circle where the spheres meet (NaN where they do not; with one
    # UAV exactly above the other the circle is level: any of its points)
    return sphere_pair_lowest(x1, y1, z1, l1, x2, y2, z2, l2)


@jit
def _inside_all(uavs: np.ndarray, lengths: np.ndarray, members: np.ndarray, count: int,
                px: float, py: float, pz: float) -> bool:
    """Whether (px, py, pz) lies within reach of every member cable (FEASIBILITY; NaN: no)."""
    for m in range(count):
        i = members[m]
        dx, dy, dz = uavs[i, 0] - px, uavs[i, 1] - py, uavs[i, 2] - pz
        if not math.sqrt(dx * dx + dy * dy + dz * dz) - lengths[i] \
                <= FEASIBILITY * (1.0 + lengths[i]):
            return False
    return True


@jit
def lowest_in(uavs: np.ndarray, lengths: np.ndarray, members: np.ndarray,
              count: int) -> tuple[float, float, float]:
    """The lowest point inside every ball (r_i, l_i), i in members[:count] (ascending), NaN
    if they do not meet. The optimum of `min z` over an intersection of balls lies on at most
    three spheres, so it is the lowest feasible one of: a ball's bottom, a pair's lowest circle
    point, a triple's lower meeting point."""
    bx, by, bz = math.nan, math.nan, math.nan
    for m in range(count):
        i = members[m]
        pz = uavs[i, 2] - lengths[i]
        if not pz >= bz and _inside_all(uavs, lengths, members, count, uavs[i, 0],
                                        uavs[i, 1], pz):
            bx, by, bz = uavs[i, 0], uavs[i, 1], pz
    if not math.isnan(bz):
        return bx, by, bz
    for a in range(count):
        i = members[a]
        for b in range(a + 1, count):
            j = members[b]
            px, py, pz = sphere_pair_lowest(uavs[i, 0], uavs[i, 1], uavs[i, 2], lengths[i],
                                            uavs[j, 0], uavs[j, 1], uavs[j, 2], lengths[j])
            if not pz >= bz and _inside_all(uavs, lengths, members, count, px, py, pz):
                bx, by, bz = px, py, pz
    for a in range(count):
        i = members[a]
        for b in range(a + 1, count):
            j = members[b]
            for c in range(b + 1, count):
                k = members[c]
                px, py, pz = sphere_triple_lowest(
                    uavs[i, 0], uavs[i, 1], uavs[i, 2], lengths[i], uavs[j, 0], uavs[j, 1],
                    uavs[j, 2], lengths[j], uavs[k, 0], uavs[k, 1], uavs[k, 2], lengths[k])
                if not pz >= bz and _inside_all(uavs, lengths, members, count, px, py, pz):
                    bx, by, bz = px, py, pz
    return bx, by, bz


@jit
def equilibrium_point(uavs: np.ndarray, lengths: np.ndarray) -> tuple[float, float, float]:
    """Where the payload would hang at rest under UAVs held at `uavs` (n, 3) [m] on cables of
    `lengths` (n,) [m]: the lowest point within reach of every cable (the minimum of the
    potential m_p g z over |r_p - r_i| <= l_i); NaN when the cables cannot all reach one point.

    One UAV: l_1 straight below it. Two: the lowest point of the circle the cables span (or
    below one UAV while the other cable is slack). Three or more: an active-set search that
    starts with the WORKING_SET cables whose lowest reach z_i - l_i is highest (ties: the
    lower index; NaN last) and adds the cable the candidate violates most. With rigid cables
    and three or more UAVs the payload is held at this place by the constraints themselves, so
    its swing stays at rounding level.
    """
    n = uavs.shape[0]
    if n <= 2:
        return lowest_of_two(uavs, lengths)
    chosen = np.zeros(n, dtype=np.bool_)
    for _ in range(min(WORKING_SET, n)):
        best = -1
        for i in range(n):
            if chosen[i]:
                continue
            reach = uavs[i, 2] - lengths[i]
            if best < 0 or reach > uavs[best, 2] - lengths[best] \
                    or (math.isnan(uavs[best, 2] - lengths[best]) and not math.isnan(reach)):
                best = i
        chosen[best] = True
    members = np.empty(n, dtype=np.int64)
    while True:
        count = 0
        for i in range(n):
            if chosen[i]:
                members[count] = i
                count += 1
        px, py, pz = lowest_in(uavs, lengths, members, count)
        if math.isnan(pz):
            return math.nan, math.nan, math.nan
        # the cable outside its reach the most (argmax: the first NaN, else the first largest)
        worst, gap = -1, -math.inf
        for i in range(n):
            if chosen[i]:
                continue
            dx, dy, dz = uavs[i, 0] - px, uavs[i, 1] - py, uavs[i, 2] - pz
            here = math.sqrt(dx * dx + dy * dy + dz * dz) - lengths[i]
            if math.isnan(here):
                worst, gap = i, here
                break
            if worst < 0 or here > gap:
                worst, gap = i, here
        if worst < 0 or gap <= FEASIBILITY * (1.0 + lengths[worst]):
            return px, py, pz
        chosen[worst] = True


@jit
def swing_at(uavs: np.ndarray, payload: np.ndarray, lengths: np.ndarray) -> float:
    """The payload swing [m]: the horizontal distance of `payload` (3,) from its equilibrium
    place under `uavs` (n, 3) on cables `lengths` (n,) (`equilibrium_point`), world [m];
    NaN where the cables cannot meet."""
    x, y, z = equilibrium_point(uavs, lengths)
    if math.isnan(z):
        return math.nan
    return hypot2(payload[0] - x, payload[1] - y)
