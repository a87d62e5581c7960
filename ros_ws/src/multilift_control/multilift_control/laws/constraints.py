"""The virtual constraint rows g_vc(r_f) of seed Eq. 3.5 (Table 3.1), world frame: each row
(rows (m, ROW_SIZE) ints, targets (m,) [m]) a linear row (r_i - r_j)_axis - target [m]
(Eq. 3.2-3.4, the V's Eq. 3.6) or a squared distance |r_i - r_j|^2 - target^2 [m^2] (Eq. 3.1;
Table 3.1 prints "- d", read as d^2, a slip). Positions r and velocities v are (n, 3) [m],
[m/s]; the flattened formation vector r_f is r.reshape(3n)."""
import numpy as np

from multilift_control.laws import jit
from multilift_control.laws.layout import ROW_AXIS, ROW_DISTANCE, ROW_FIRST, ROW_SECOND
from multilift_control.laws.linalg import right_singular


@jit
def row_residual(rows, targets, positions, k):
    """g_vc row k [m or m^2]."""
    i, j, axis = rows[k, ROW_FIRST], rows[k, ROW_SECOND], rows[k, ROW_AXIS]
    if axis != ROW_DISTANCE:
        return positions[i, axis] - positions[j, axis] - targets[k]
    total = 0.0
    for d in range(3):
        gap = positions[i, d] - positions[j, d]
        total += gap * gap
    return total - targets[k] * targets[k]


@jit
def row_rate(rows, positions, velocities, k):
    """g_vc_dot row k = (J_vc r_f_dot)_k [m/s or m^2/s]: (v_i - v_j)_axis, or
    2 (r_i - r_j) . (v_i - v_j)."""
    i, j, axis = rows[k, ROW_FIRST], rows[k, ROW_SECOND], rows[k, ROW_AXIS]
    if axis != ROW_DISTANCE:
        return velocities[i, axis] - velocities[j, axis]
    total = 0.0
    for d in range(3):
        total += 2.0 * (positions[i, d] - positions[j, d]) * (velocities[i, d] - velocities[j, d])
    return total


@jit
def residual(rows, targets, positions):
    """g_vc(r) (m,) [m or m^2] (Eq. 3.5)."""
    out = np.empty(rows.shape[0])
    for k in range(rows.shape[0]):
        out[k] = row_residual(rows, targets, positions, k)
    return out


@jit
def jacobian(rows, positions):
    """J_vc = d g_vc / d r_f (m, 3n): +-1 at the row's axis for a linear row (constant,
    Eq. 3.7), +-2 (r_i - r_j) for a distance row."""
    n = positions.shape[0]
    out = np.zeros((rows.shape[0], 3 * n))
    for k in range(rows.shape[0]):
        i, j, axis = rows[k, ROW_FIRST], rows[k, ROW_SECOND], rows[k, ROW_AXIS]
        if axis != ROW_DISTANCE:
            out[k, 3 * i + axis] = 1.0
            out[k, 3 * j + axis] = -1.0
            continue
        for d in range(3):
            gap = 2.0 * (positions[i, d] - positions[j, d])
            out[k, 3 * i + d] = gap
            out[k, 3 * j + d] = -gap
    return out


@jit
def jacobian_rate_product(rows, velocities):
    """J_vc_dot r_f_dot (m,): zero for a linear row, 2 |v_i - v_j|^2 for a distance row
    [m^2/s^2]."""
    out = np.zeros(rows.shape[0])
    for k in range(rows.shape[0]):
        i, j = rows[k, ROW_FIRST], rows[k, ROW_SECOND]
        if rows[k, ROW_AXIS] != ROW_DISTANCE:
            continue
        total = 0.0
        for d in range(3):
            gap = velocities[i, d] - velocities[j, d]
            total += gap * gap
        out[k] = 2.0 * total
    return out


@jit
def rows_of(rows, index):
    """The indices (ascending) of the rows that involve UAV `index` (0 = the leader)."""
    count = 0
    for k in range(rows.shape[0]):
        if rows[k, ROW_FIRST] == index or rows[k, ROW_SECOND] == index:
            count += 1
    out = np.empty(count, dtype=np.int64)
    count = 0
    for k in range(rows.shape[0]):
        if rows[k, ROW_FIRST] == index or rows[k, ROW_SECOND] == index:
            out[count] = k
            count += 1
    return out


@jit
def rows_by_uav(rows, n):
    """Every UAV's rows at once, in O(m + n): (start (n + 1,), index ints): the rows that
    involve UAV j (0 = the leader), ascending as `rows_of(rows, j)`, are
    index[start[j]:start[j + 1]]."""
    start = np.zeros(n + 1, dtype=np.int64)
    for k in range(rows.shape[0]):
        i, j = rows[k, ROW_FIRST], rows[k, ROW_SECOND]
        start[i + 1] += 1
        if j != i:
            start[j + 1] += 1
    for j in range(n):
        start[j + 1] += start[j]
    index = np.empty(start[n], dtype=np.int64)
    filled = start[:n].copy()
    for k in range(rows.shape[0]):
        i, j = rows[k, ROW_FIRST], rows[k, ROW_SECOND]
        index[filled[i]] = k
        filled[i] += 1
        if j != i:
            index[filled[j]] = k
            filled[j] += 1
    return start, index


@jit
def free_follower_motions(rows, positions, tol):
    """Orthonormal basis (2(n-1), k) of the followers' horizontal motions that leave every row
    unchanged to first order with the leader held: the null space of J_vc's follower x, y
    columns (stacked x_2, y_2, .., x_n, y_n), singular values up to tol times the largest
    counting as zero. Empty (k = 0) for linear rows; for a circle the rotation about the
    leader, for 'distance' each follower's tangent."""
    n = positions.shape[0]
    full = jacobian(rows, positions)
    follower = np.empty((rows.shape[0], 2 * (n - 1)))
    for k in range(rows.shape[0]):
        for c in range(2 * (n - 1)):
            follower[k, c] = full[k, 3 * (1 + c // 2) + c % 2]
    values, basis, _ = right_singular(follower)
    largest = 1e-300
    for value in values:
        largest = max(largest, value)
    free = 0
    for value in values:
        if not value > tol * largest:
            free += 1
    out = np.empty((2 * (n - 1), free))
    free = 0
    for c in range(values.shape[0]):
        if not values[c] > tol * largest:
            out[:, free] = basis[:, c]
            free += 1
    return out
