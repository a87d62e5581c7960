"""A symmetric 3 x 3 system solved in closed form: what the payload's 3-dof Schur complement
needs in the seed's formation (`formation_dae.cable_multipliers`, Eq. 2.68) and in heavy
cables (`chain_cables`)."""
from multilift_sim.kernels import jit


@jit
def symmetric_solve3(s00, s01, s02, s11, s12, s22, b0, b1, b2):
    """y = S^-1 b (3 floats) for the symmetric S = [[s00, s01, s02], [s01, s11, s12], [s02,
    s12, s22]] by its adjugate (S nonsingular)."""
    c00 = s11 * s22 - s12 * s12
    c01 = s02 * s12 - s01 * s22
    c02 = s01 * s12 - s02 * s11
    c11 = s00 * s22 - s02 * s02
    c12 = s01 * s02 - s00 * s12
    c22 = s00 * s11 - s01 * s01
    inv_det = 1.0 / (s00 * c00 + s01 * c01 + s02 * c02)
    return ((c00 * b0 + c01 * b1 + c02 * b2) * inv_det,
            (c01 * b0 + c11 * b1 + c12 * b2) * inv_det,
            (c02 * b0 + c12 * b1 + c22 * b2) * inv_det)
