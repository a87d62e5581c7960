"""The seed's vehicle (Table 4.2, 2.5 kg quadrotor), as every shipped scenario writes it out:
`vehicle.preset: table_4_2`."""
NAME = 'table_4_2'
VALUES = {
    'mass': 2.5,                        # [kg]
    'inertia': (0.957, 0.486, 0.355),   # principal, body [kg m^2] (the seed's printed value)
    'inertia_source': 'seed',
    'frame_type': 'quad_x',             # the seed does not say + or x
    'arm_length': 0.2,                  # [m]
    'thrust_coefficient': 1.83e-6,      # k_T [N s^2/rad^2]
    'moment_coefficient': 1.85e-7,      # k_D [N m s^2/rad^2]
    'rotor_speed_min': 0.0,             # [rad/s]
    'rotor_speed_max': 2100.0,          # [rad/s]
}
