"""The small dense linear algebra of the nonlinear virtual constraint rows, in plain loops (the
same arithmetic compiled and uncompiled, bit for bit, where LAPACK's would depend on the
library the caller links)."""
import math

import numpy as np

from multilift_control.laws import jit

_SWEEPS = 60        # one-sided Jacobi sweeps at most (a few suffice for these sizes)
_ORTHOGONAL = 1e-15  # columns count as orthogonal below this cosine


@jit
def right_singular(matrix):
    """(singular values s (q,), V (q, q), B V = U diag(s) (p, q)) of a (p, q) matrix B, U's
    columns orthonormal (zero where s is): one-sided Jacobi (Hestenes) rotations of B's columns,
    accumulated in V. Singular values to high relative accuracy, so a null direction comes
    out at about 1e-16 of the largest; V's columns are the right singular vectors, in no
    particular order. A q > p matrix gives q - p (at least) zero values."""
    p, q = matrix.shape
    columns = matrix.copy()
    basis = np.eye(q)
    # a column this small (1e-30 of the matrix's norm) is a null direction found: rotating it
    # further would only divide by its underflowing products
    negligible = 0.0
    for k in range(p):
        for a in range(q):
            negligible += matrix[k, a] * matrix[k, a]
    negligible *= 1e-60
    for _ in range(_SWEEPS):
        rotated = False
        for a in range(q - 1):
            for b in range(a + 1, q):
                alpha = beta = gamma = 0.0
                for k in range(p):
                    alpha += columns[k, a] * columns[k, a]
                    beta += columns[k, b] * columns[k, b]
                    gamma += columns[k, a] * columns[k, b]
                if (gamma == 0.0 or alpha <= negligible or beta <= negligible
                        or abs(gamma) <= _ORTHOGONAL * math.sqrt(alpha * beta)):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                if abs(zeta) < 1e150:
                    tangent = math.copysign(1.0, zeta) / (abs(zeta)
                                                          + math.sqrt(1.0 + zeta * zeta))
                else:  # the same to the last bit, without zeta^2's overflow
                    tangent = 0.5 / zeta
                cosine = 1.0 / math.sqrt(1.0 + tangent * tangent)
                sine = cosine * tangent
                for k in range(p):
                    x, y = columns[k, a], columns[k, b]
                    columns[k, a] = cosine * x - sine * y
                    columns[k, b] = sine * x + cosine * y
                for k in range(q):
                    x, y = basis[k, a], basis[k, b]
                    basis[k, a] = cosine * x - sine * y
                    basis[k, b] = sine * x + cosine * y
        if not rotated:
            break
    values = np.empty(q)
    for a in range(q):
        total = 0.0
        for k in range(p):
            total += columns[k, a] * columns[k, a]
        values[a] = math.sqrt(total)
    return values, basis, columns


@jit
def minimum_norm_solve(matrix, rhs):
    """x of the square system A x = rhs (m,) by A's singular value decomposition, singular
    values below eps m s_max dropped: A^-1 rhs where A is regular, the least-squares,
    minimum-norm solution where it is singular (numpy's lstsq with rcond=None). Between
    the two (a condition number past 1/(eps m)) this is where `np.linalg.solve` would return
    noise."""
    m = matrix.shape[0]
    values, basis, columns = right_singular(matrix)
    largest = 0.0
    for k in range(m):
        largest = max(largest, values[k])
    cutoff = 2.220446049250313e-16 * m * largest
    solution = np.zeros(m)
    for k in range(m):
        if values[k] <= cutoff or values[k] == 0.0:
            continue
        along = 0.0  # u_k . rhs s_k
        for j in range(m):
            along += columns[j, k] * rhs[j]
        along /= values[k] * values[k]
        for j in range(m):
            solution[j] += basis[j, k] * along
    return solution
