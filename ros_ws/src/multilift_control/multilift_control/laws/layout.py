"""The named slots of every array the control laws read and write, in one place.

A law's constants (gains, masses, limits) are one float array per controller, built once from
the scenario; its memory (integrals, the time of the last tick, a follower's last lift and
held heading) one small float array it updates in place, NaN standing for "none yet". The
formation's measured states are one (n, UAV_STATE_SIZE) array, a UAV a row. Units: SI, angles
[rad], world frame z up, body FLU (docs/conventions.md).
"""
from multilift_sim.physics.layout import (MEASURED_BODY_RATES, MEASURED_COLUMNS, MEASURED_EULER,
                                          MEASURED_POSITION, MEASURED_VELOCITY)

# --- a UAV's measured state: one row of the formation's states (n, UAV_STATE_SIZE), the slots
# the simulator measures into (multilift_sim.physics.layout MEASURED_*, physics.measurement) ---
UAV_POSITION = MEASURED_POSITION        # (3) world [m]
UAV_VELOCITY = MEASURED_VELOCITY        # (3) world [m/s]
UAV_EULER = MEASURED_EULER              # (3) roll, pitch, yaw [rad]
UAV_BODY_RATES = MEASURED_BODY_RATES    # (3) body angular velocity, FLU [rad/s]
UAV_STATE_SIZE = MEASURED_COLUMNS

# --- the mission reference a leader tracks (reference.mission_reference's result) -------------
REFERENCE_POSITION = 0      # (3) [m]
REFERENCE_VELOCITY = 3      # (3) [m/s]
REFERENCE_ACCELERATION = 6  # (3) [m/s^2]
REFERENCE_YAW = 9           # the heading to hold [rad] (0: the seed's)
REFERENCE_SIZE = 10
# the mission's constants
MISSION_START = 0   # (3) position at t = 0 [m]
MISSION_FINAL = 3   # (3) position after the last segment [m]
MISSION_OMEGA = 6   # 1 / tau of the reference prefilter [1/s]; 0: the raw path
MISSION_SHAPED = 7  # 1: the steps are an input shaper's (control.payload_feedback); 0: not
MISSION_FORM = 8    # which compiled reference: FORM_VELOCITY_SEGMENTS or FORM_POLYNOMIAL
MISSION_SIZE = 9
# MISSION_FORM's values: the index of a mission source's FORM in multilift_sim.missions.FORMS
FORM_VELOCITY_SEGMENTS = 0  # `segments` rows (SEGMENT_*) and `steps` (STEP_*)
FORM_POLYNOMIAL = 1         # `segments` holds pieces (PIECE_*), `steps` is empty
# a polynomial mission's pieces, a row each (pieces, PIECE_SIZE), in the segments' place
PIECE_START_TIME = 0    # [s]
PIECE_END_TIME = 1      # [s]
PIECE_AXES = 4          # x, y, z [m], yaw [rad]
PIECE_ORDER = 8         # coefficients an axis: degree 7 at most (multilift_sim.missions)
PIECE_COEFFICIENTS = 2  # (PIECE_AXES * PIECE_ORDER) axis by axis, the lowest power first, in
#                         powers of t - PIECE_START_TIME [s]
PIECE_SIZE = PIECE_COEFFICIENTS + PIECE_AXES * PIECE_ORDER
# the mission's segments, a row each (segments, SEGMENT_SIZE)
SEGMENT_START_TIME = 0  # [s]
SEGMENT_END_TIME = 1    # [s]
SEGMENT_VELOCITY = 2    # (3) [m/s]
SEGMENT_ORIGIN = 5      # (3) position at the segment's start [m]
SEGMENT_SIZE = 8
# its velocity steps (the first from rest at t = 0, the last the stop), a row each
STEP_TIME = 0   # [s]
STEP_DV = 1     # (3) velocity step [m/s]
STEP_SIZE = 4

# --- the cascade (CascadeController): constants ------------------------------------------------
CASCADE_KP = 0                 # (3) position gains [1/s^2]
CASCADE_KD = 3                 # (3) [1/s]
CASCADE_KI = 6                 # (3) [1/s^3]
CASCADE_INTEGRAL_LIMIT = 9     # |integral| bound per axis [m/s^2]
CASCADE_HOVER_MASS = 10        # the UAV and its payload share [kg]
CASCADE_GRAVITY = 11           # [m/s^2]
CASCADE_MAX_TILT = 12          # [rad]
CASCADE_INERTIA = 13           # (3) principal moments [kg m^2]
CASCADE_ATT_KP = 16            # (3) attitude gains [1/s^2]
CASCADE_ATT_KD = 19            # (3) [1/s]
CASCADE_SQUARE_MIN = 22        # omega_min^2 [rad^2/s^2]
CASCADE_SQUARE_MAX = 23        # omega_max^2 [rad^2/s^2]
CASCADE_THRUST_COEFFICIENT = 24  # k_T [N s^2/rad^2]
# a leader's swing feedback (`swing.swing_feedback`, control.payload_feedback); both gains 0:
# the seed's law (off)
CASCADE_SWING_STIFFNESS = 25   # k_s [1/s^2]
CASCADE_SWING_DAMPING = 26     # k_d [1/s]
CASCADE_SWING_REST = 27        # (2) s_0: the payload's x, y from the UAVs' mean at rest [m]
CASCADE_SWING_LIMIT = 29       # a_max: the largest |a_s| [m/s^2]
CASCADE_SIZE = 30
# its memory
CASCADE_INTEGRAL = 0   # (3) position loop integral [m/s^2]
CASCADE_LAST_T = 3     # time of the last tick [s] (NaN: none yet)
CASCADE_MEMORY_SIZE = 4

# --- the rotor mixer: a row per rotor (n_rotors, MIXER_SIZE) -----------------------------------
MIXER_WRENCH = 0       # (4) its row of the allocation's pseudo-inverse: omega^2 [rad^2/s^2] per
#                        newton of u_T and per N m of each body torque
MIXER_COLLECTIVE = 4   # omega^2 per newton of collective thrust [rad^2/(s^2 N)]
MIXER_SIZE = 5

# --- the virtual constraint rows g_vc: a row each (m, ROW_SIZE) of ints ------------------------
ROW_FIRST = 0    # UAV index i of the row (0 = the leader)
ROW_SECOND = 1   # UAV index j
ROW_AXIS = 2     # linear row: the axis of (r_i - r_j)_axis - target [m]; ROW_DISTANCE: squared
ROW_SIZE = 3     # distance |r_i - r_j|^2 - target^2 [m^2]
ROW_DISTANCE = -1

# --- a follower (FormationFollower): constants -------------------------------------------------
FOLLOWER_TWO_ALPHA = 0          # 2 alpha_vc [1/s]
FOLLOWER_BETA_SQ = 1            # beta_vc^2 [1/s^2]
FOLLOWER_ALTITUDE_OFFSET = 2    # z_d,i - z_1 [m]
FOLLOWER_HOVER_MASS = 3         # [kg]
FOLLOWER_GRAVITY = 4            # [m/s^2]
FOLLOWER_KP_Z = 5               # altitude loop gains [1/s^2]
FOLLOWER_KD_Z = 6               # [1/s]
FOLLOWER_KI_Z = 7               # [1/s^3]
FOLLOWER_INTEGRAL_LIMIT = 8     # [m/s^2]
FOLLOWER_COMMANDED = 9          # 1: u_i is the lift asked at the last tick; 0: as measured
FOLLOWER_FREE_MODE_GAIN = 10    # k_f [1/s] (NaN: off)
FOLLOWER_LINEAR = 11            # 1: linear (and V) rows, the O(n) law of constant matrices
FOLLOWER_LEADER_CLIMB = 12      # 1: the altitude loop damps z_1_dot - z_i_dot; 0: -z_i_dot
FOLLOWER_SIZE = 13
# its memory
FOLLOWER_INTEGRAL = 0   # altitude loop integral [m/s^2]
FOLLOWER_LAST_T = 1     # time of the last tick [s] (NaN: none yet)
FOLLOWER_LIFT = 2       # (3) the lift asked at the last tick R(eta_d) e_z u_T, world [N] (NaN)
FOLLOWER_YAW = 5        # the heading held [rad] (NaN: the one measured at the first tick)
FOLLOWER_MEMORY_SIZE = 6

# --- a reorganising follower (`formation.reorganize: thrust_margin`, laws.reorganize): its
# constants after the FOLLOWER_* slots ---
REORGANIZE_PAYLOAD_MASS = FOLLOWER_SIZE       # m_p [kg]
REORGANIZE_MIN_SPACING = FOLLOWER_SIZE + 1    # least horizontal distance between UAVs [m]
REORGANIZE_MAX_SPREAD = FOLLOWER_SIZE + 2     # largest horizontal distance between UAVs [m]
REORGANIZE_MAX_RATE = FOLLOWER_SIZE + 3       # largest speed of a follower's offset [m/s]
REORGANIZE_FLOOR = FOLLOWER_SIZE + 4          # thrust margin floor [-]
REORGANIZE_GAIN = FOLLOWER_SIZE + 5           # offset rate per unit of cost gradient [m^2/s]
REORGANIZE_FILTER_TIME = FOLLOWER_SIZE + 6    # the apparent gravity's low-pass time [s]
REORGANIZE_DEPTH = FOLLOWER_SIZE + 7          # cable_forces: the payload's depth below its
#                                               level UAVs at the start [m]
REORGANIZE_MODE = FOLLOWER_SIZE + 8           # REORGANIZE_GRADIENT or REORGANIZE_ALLOCATE
REORGANIZE_AT_REST = FOLLOWER_SIZE + 9        # 1: a point payload's statics in the law
#                                               (laws.reorganize.static_pulls), 0: none
REORGANIZE_RIGID = FOLLOWER_SIZE + 10         # 1: a rigid-body payload's statics
#                                               (laws.rigid_statics), 0: a point payload's
REORGANIZE_UAVS = FOLLOWER_SIZE + 11          # then a row of REORGANIZE_UAV_SIZE per UAV:
REORGANIZE_UAV_MASS = 0                       # its vehicle's mass m_i [kg]
REORGANIZE_UAV_LARGEST = 1                    # u_T,max,i, every rotor at its limit [N]
REORGANIZE_UAV_LENGTH = 2                     # its cable's length l_i [m]
REORGANIZE_UAV_ATTACH = 3                     # (3) a rigid body: where its cable holds it,
#                                               b_i, payload frame [m] (a point payload: 0)
REORGANIZE_UAV_SIZE = 6
REORGANIZE_GRADIENT = 0.0  # thrust_margin: laws.reorganize.reorganize
REORGANIZE_ALLOCATE = 1.0  # cable_forces: laws.cable_forces.allocate
# a follower whose offsets turn with the leader's heading (`formation.reorganize: heading`):
# its constants after the FOLLOWER_* slots
HEADING_LEADER_START_YAW = FOLLOWER_SIZE      # the leader's yaw at the start [rad]
HEADING_SIZE = FOLLOWER_SIZE + 1
# its memory after the FOLLOWER_* slots
REORGANIZE_ACCELERATION = FOLLOWER_MEMORY_SIZE  # (3) the formation's filtered a [m/s^2]
REORGANIZE_SHIFT = FOLLOWER_MEMORY_SIZE + 3     # (m) the rows' targets moved by [m]
