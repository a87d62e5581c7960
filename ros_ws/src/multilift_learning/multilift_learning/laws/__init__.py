"""The learning environments' own compiled laws (numba, as `multilift_control.laws`: compiled
or run uncompiled as MULTILIFT_KERNEL says): `body_rates`, the attitude-rate loop of the
collective-thrust-and-body-rates action mode."""
