"""Analysis of the formation without flying it: references and linearisations (seed Sec. 2.6,
2.8).

    reduced_model  the reduced-coordinate single-lift model (Eq. 2.33-2.40), the reference
                   solution, in the seed's frame
    coordinates    the formation's coordinates q_f at rest: names, inertia M_f, the constraint
                   Jacobian G and residuals g, a state moved by (dq, dq_dot)
    equilibrium    the static equilibrium of Eq. 2.73 (rotor speeds, attitudes, multipliers)
    modal          the open-loop linearisation about it and its eigen-decomposition
    modes          each mode named: its kind (pendulum, rigid, ...), real shapes, where its
                   kinetic energy sits

Modal analysis of the formation about a static equilibrium (seed Sec. 2.8, Eq. 2.71-2.73),
the method of `equilibrium`, `coordinates`, `modal` and `modes`:

World frame (z up), SI units, coordinates ``q_f`` of docs/conventions.md (6n + 3 of them); a
rigid-body payload adds its attitude as a rotation vector (below: 6n + 6 coordinates).

1. Equilibrium (Eq. 2.73 with q_dot = 0): ``f_g + G^T Lambda = B_f u_f``, ``g = 0``. Written in
   the world frame the rows are

       payload:   m_p g e_z + sum_i 2 lambda_i d_i = 0              (d_i = r_p - r_i)
       UAV i:     m_i g e_z - 2 lambda_i d_i = u_T,i R(eta_i) e_z   (B_r of Eq. 2.20)
       attitude:  0 = W^T tau_i, so tau_i = 0

   The payload rows give the multipliers (least squares, exact when the payload can hang at
   rest there), the UAV rows each UAV's thrust and its roll and pitch at the scenario's yaw, the
   allocation the rotor speeds. The UAVs are level only where their cable hangs vertically
   (n = 1): a level UAV's thrust is vertical and cannot balance a slanted cable's horizontal
   pull, so for n >= 2 Eq. 2.73 has no level solution and each UAV tilts away from the payload
   (1.57 deg in the twin_lift scenario). For n >= 4 the payload rows do not fix Lambda
   (statically indeterminate); the least-norm split is taken.
2. Linearisation, open loop: rotor speeds held at the equilibrium values, the exact
   index-reduced DAE of Eq. 2.58 (FormationModel with alpha_f = beta_f = 0) differentiated by
   central differences. Its multipliers are eliminated, not linearised: with n dependent
   coordinates q_d (the UAV altitudes by default, as the seed does for the twin-lift; usable
   while no cable is horizontal) and the constraint Jacobian G = [G_i G_d] at equilibrium,

       dq = T dq_i,   T = [I; -G_d^-1 G_i]   (rows of q_i, then of q_d; G T = 0, Eq. 2.71)

   and projecting ``M dq_ddot = dF - G^T dLambda`` with T^T (Eq. 2.72, T plays N_f) gives

       T^T M T dq_i_ddot = T^T M J_q T dq_i + T^T M J_v T dq_i_dot,

   J_q, J_v the Jacobians of the DAE's accelerations (the G^T dLambda part drops out since
   T^T G^T = 0). ``basis='nullspace'`` uses an orthonormal null-space basis N_f of G instead of
   T; the eigenvalues are the same (test_modal.py). ``hold_uavs`` clamps the UAVs' 6n
   coordinates (their rows of T zero: the cables' upper ends held still, as a bifilar
   suspension's formula assumes); T^T G^T = 0 still removes the multipliers, and what the
   cables' turning does at the equilibrium tension, -T^T (dG^T/dq) Lambda_e, stays in J_q.
3. Eigenvalues of the first-order system ``A = [[0, I], [M_r^-1 K_r, M_r^-1 D_r]]``. A free
   formation under held rotor speeds has rigid-body modes (translation of the whole formation,
   and each UAV's attitude, which nothing restores in open loop) at zero: they are reported
   apart. Purely imaginary pairs of pendulum size are the pendulum modes. Each mode is named
   by where its kinetic energy sits (`motion_shares`): the payload's swing x / y, heave, its
   roll / pitch / yaw (a rigid body), the UAVs' translation or attitude.

A rigid-body payload (docs/rigid_payload.md, "The equations"): cable i holds it at b_i
(payload frame), d_i = r_p + R_p b_i - r_i. Its attitude enters as a rotation vector theta in
the payload frame, R_p = R_e Exp(theta) (3 coordinates after q_f, not the quaternion's 4),
with rates omega_p (= theta_dot to first order at rest, so theta_ddot linearises to the DAE's
alpha_p). The equilibrium's payload rows gain the moment, ``sum_i 2 lambda_i c_i = 0`` with
c_i = b_i x R_p^T d_i (n >= 7, or cables through one point: least-norm), G the columns
``dg_i/dtheta = 2 c_i`` (U_i = 2 (d_i, c_i) of the docs), M the principal inertia J_p. The
hanging rest is the simulator's start (simulation.formation_start: level, the identity).

Cables held off the UAVs' centres (uavs[i].attach_point, a_i body FLU; docs/rigid_payload.md):
cable i starts at s_i = r_i + R_i a_i, so d_i = r_p (+ R_p b_i) - r_i - R_i a_i. The given UAV
positions place each s_i where it would be with the UAV level at its yaw, s_i = r_i +
Rz(psi_i) a_i (simulation.formation_start's convention: the simulator starts the UAVs level
there); the cables' geometry is then fixed, so the payload rows give Lambda as above. Each UAV
tilts to point its thrust along m_i g e_z - F_c,i (F_c,i = 2 lambda_i d_i, the cable's pull on
it), its centre then moves to r_i = s_i - R_i a_i at that attitude (s_i stays put), and its
rotors also cancel the pull's moment about the centre: the attitude rows read
0 = W^T (tau_i + a_i x R_i^T F_c,i), so tau_i = -a_i x R_i^T F_c,i (body FLU; the DAE's
2 lambda_i k_i, physics/free_motion.py cable_moment_arm, with the sign reversed). G gains the
columns of the UAVs' Euler angles, dg_i/deta_i = -2 d_i . d(R_i a_i)/deta_i (= -2 W_i^T k_i,
k_i = a_i x R_i^T d_i), so that T^T G^T = 0 still removes the multipliers of the DAE (which
turns the UAV by J_i^-1 2 lambda_i k_i). Attach points all zero are the seed's case exactly.

Payload drag and gusts do not enter: the quadratic drag has zero slope at zero air speed, and
the analysis is of the formation in still air.
"""
