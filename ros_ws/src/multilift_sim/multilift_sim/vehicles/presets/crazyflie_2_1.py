"""Bitcraze's Crazyflie 2.1 nano quadrotor: `vehicle.preset: crazyflie_2_1`.

Sources:
- mass 27 g and size 92 x 92 x 29 mm motor to motor: Bitcraze, "Crazyflie 2.1 datasheet"
  (www.bitcraze.io, product documentation); the arm (centre to rotor) is half of the 92 mm
  motor-to-motor diagonal, 46 mm, an X frame (Bitcraze's default orientation: quad_x).
- inertia, thrust and torque coefficients, motor limit: J. Förster, "System Identification of
  the Crazyflie 2.0 Nano Quadrocopter", bachelor thesis, IDSC, ETH Zurich, 2015: the principal
  moments are the diagonal of its identified inertia (16.571710, 16.655602, 29.261652) 1e-6
  kg m^2 (its off-diagonal terms, under 2e-6, neglected); thrust per rotor C_T Omega^2 with
  C_T = 3.1582e-10 N/rpm^2 and drag torque C_D Omega^2 with C_D = 7.9379e-12 N m/rpm^2,
  here per (rad/s)^2: times (60 / 2 pi)^2 = 91.18906; the rotor speed at full command from
  its PWM-to-speed map Omega = 0.2685 PWM + 4070.3 rpm at PWM = 65535: 21,666 rpm
  = 2268.9 rad/s (the motors stop at 0; the map's 4,070 rpm at PWM 0 is not a floor).
At full speed a rotor gives 0.148 N: 0.593 N in all, 2.24 times the 27 g vehicle's weight.
"""
import math

NAME = 'crazyflie_2_1'
_RPM = (60.0 / (2.0 * math.pi)) ** 2  # rpm^2 per (rad/s)^2
VALUES = {
    'mass': 0.027,                                       # [kg] datasheet
    'inertia': (16.571710e-6, 16.655602e-6, 29.261652e-6),  # principal, body [kg m^2]
    'frame_type': 'quad_x',
    'arm_length': 0.046,                                 # [m] datasheet: 92 mm / 2
    'thrust_coefficient': 3.1582e-10 * _RPM,             # k_T [N s^2/rad^2]: 2.880e-8
    'moment_coefficient': 7.9379e-12 * _RPM,             # k_D [N m s^2/rad^2]: 7.238e-10
    'rotor_speed_min': 0.0,                              # [rad/s]
    'rotor_speed_max': (0.2685 * 65535 + 4070.3) * 2.0 * math.pi / 60.0,  # [rad/s]: 2268.9
}
