"""The formation's physics, written once as numba functions over float arrays (seed Ch. 2).

- `layout`: the slots of the packed arrays (state, constants, gusts, scratch): named once;
- `formation_dae`: payload drag and gusts, the DAE solve (Eq. 2.59-2.60, a 3 x 3 Woodbury
  solve over the taut cables), RK4 over a control period, the constraint residuals;
- `slack_cables`: cables that go slack and snap taut (taut set, snap impulse, the RK4 step
  cut at each taut event);
- `taut_event`: that event located within the RK4 step (the guard on the RK4 map, Hermite
  bracketing, Illinois regula falsi).

Each function takes one formation's arrays, so a batched engine can loop over formations
inside numba. `dynamics.FormationModel` and `slack.SlackCableModel` build the arrays once and
call them compiled, or under MULTILIFT_KERNEL=python their uncompiled run
(`kernels.runnable`, `kernels.uncompiled`). Importing a module here imports numba (the
package itself does not).
"""
