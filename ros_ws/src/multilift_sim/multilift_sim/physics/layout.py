"""The slots of every packed array the physics functions read or write: the one place they are
named (numba freezes these module-level integers into the compiled code).

- the formation state x (docs/conventions.md): the translations as a point-mass DAE
  (q, q_dot), q = (r_1, ..., r_n, r_p) [m] (UAV i's POSITION block at `uav_slot(i)`, r_p at
  `payload_slot(n)`), q_dot their velocities [m/s] from `n_coordinates(n)`; then every body's
  attitude block (BODY_*: its unit quaternion, body -> world, and its body rates [rad/s]),
  UAV i's at `uav_attitude_slot(n, i)`, a rigid payload's after the UAVs' at
  `attitude_slot(n)` (the length of a point payload's state);
- the seed's generalised coordinates q_f (Eq. 2.41, SEED_*: per UAV r_i and ZYX eta_i, then
  r_p), which the analysis linearises in (multilift_sim.analysis.coordinates);
- a UAV's constants row (UAV_*, UAV_COLUMNS columns, one row per UAV) and its rotors'
  actuator row (ACTUATOR_*);
- a gust's row (GUST_*, seed Eq. 2.55);
- the formation's scalars (FORMATION_*);
- the scratch of a solve per cable (CABLE_*) and of an RK4 step (WORK_*);
- a UAV's measured state (MEASURED_*: what a sensor model measures, multilift_sim.sensors) and
  its odometry row
  (ODOMETRY_*: the measured state, then its attitude and body-frame velocity as the messages
  carry them).
"""
from __future__ import annotations

# -- the state x -----------------------------------------------------------------------------
UAV_COORDINATES = 3         # coordinates of one UAV in q: r_i (3)
POSITION = 0                # r_i [m] within a UAV's block
PAYLOAD_COORDINATES = 3     # r_p [m]
# a body's attitude block (each UAV's, then a rigid payload's; issue 31, item 6), appended to x
# after q_dot and stepped with it in RK4, each quaternion scaled back to unit length at the
# end of a step: its unit quaternion (w, x, y, z), body -> world, then its angular velocity
# omega [rad/s] in the body frame (FLU for a UAV)
BODY_QUATERNION = 0         # (w, x, y, z) (4 slots)
BODY_RATES = 4              # omega [rad/s], body frame (3)
BODY_ATTITUDE = 7           # the block's length
PAYLOAD_QUATERNION = BODY_QUATERNION    # a rigid payload's block: the same slots
PAYLOAD_BODY_RATES = BODY_RATES
PAYLOAD_ATTITUDE = BODY_ATTITUDE


# The offsets below are plain functions, each written from the constants alone (no calls), so
# that physics.state_slots compiles these same functions for the kernels (numba calls no plain
# function); numpy code reads the state through formation_params.StateLayout's views.
def uav_slot(i: int) -> int:
    """Offset of UAV i's position r_i (from 0) in q (and of its velocity in q_dot)."""
    return UAV_COORDINATES * i


def payload_slot(n_uavs: int) -> int:
    """Offset of r_p in q (and of v_p in q_dot) for n UAVs."""
    return UAV_COORDINATES * n_uavs


def n_coordinates(n_uavs: int) -> int:
    """Length of q: 3n + 3 (the velocities q_dot start there in x)."""
    return UAV_COORDINATES * n_uavs + PAYLOAD_COORDINATES


def uav_attitude_slot(n_uavs: int, i: int) -> int:
    """Offset of UAV i's attitude block (BODY_*) in x: after q and q_dot."""
    return 2 * (UAV_COORDINATES * n_uavs + PAYLOAD_COORDINATES) + BODY_ATTITUDE * i


def attitude_slot(n_uavs: int) -> int:
    """Offset of a rigid payload's attitude block (after the UAVs' blocks): the length of a
    point payload's state, 2 (3n + 3) + 7n."""
    return 2 * (UAV_COORDINATES * n_uavs + PAYLOAD_COORDINATES) + BODY_ATTITUDE * n_uavs


# a heavy cable's inner nodes (`cable_model: chain`, physics.chain_cables): each cable of N
# links has N - 1 point masses between its UAV and the payload, node k (1 .. N - 1) from the
# UAV; their blocks end the state (after the attitude blocks: the UAVs', a rigid payload's),
# cable by cable, node by node, each its position [m] then its velocity [m/s], world (z up)
NODE_POSITION = 0           # r_ik [m] (3 slots)
NODE_VELOCITY = 3           # r_ik_dot [m/s] (3)
NODE_STATE = 6              # a node's block


def chain_node_slot(size: int, n_uavs: int, inner_nodes: int, i: int, k: int) -> int:
    """Offset of cable i's node k (1 .. inner_nodes, from the UAV) in a state x of length
    `size`, each cable holding `inner_nodes` = N - 1 inner nodes (`cable_model: chain`): the
    node blocks end the state."""
    return size - NODE_STATE * (inner_nodes * n_uavs - (inner_nodes * i + k - 1))


def chain_inner_nodes(size: int, n_uavs: int) -> int:
    """The inner nodes per cable (N - 1) a state of length `size` holds for n UAVs: 0 but for
    a chain's state, a point payload's (a rigid payload's with its PAYLOAD_ATTITUDE = 7) plus
    n (N - 1) node blocks of NODE_STATE = 6 (7 is 1 more than a multiple of 6: the two
    cannot be confused)."""
    extra = size - (2 * (UAV_COORDINATES * n_uavs + PAYLOAD_COORDINATES)
                    + BODY_ATTITUDE * n_uavs)
    if extra % NODE_STATE == PAYLOAD_ATTITUDE % NODE_STATE:
        extra -= PAYLOAD_ATTITUDE
    if extra <= 0 or extra % (NODE_STATE * n_uavs) != 0:
        return 0
    return extra // (NODE_STATE * n_uavs)


def rigid_payload_state(size: int, n_uavs: int) -> bool:
    """Whether a state of length `size` for n UAVs holds a rigid payload's attitude block
    (PAYLOAD_ATTITUDE = 7 after the UAVs' blocks, a chain's node blocks of 6 after it)."""
    extra = size - (2 * (UAV_COORDINATES * n_uavs + PAYLOAD_COORDINATES)
                    + BODY_ATTITUDE * n_uavs)
    return extra > 0 and extra % NODE_STATE == PAYLOAD_ATTITUDE % NODE_STATE


# -- the seed's generalised coordinates q_f (Eq. 2.41): the analysis' minimal coordinates -----
# (multilift_sim.analysis: per UAV r_i [m] and ZYX eta_i [rad], then r_p [m]; a rigid payload's
# rotation vector after them), which the state maps to and from (analysis.coordinates)
SEED_UAV_COORDINATES = 6    # r_i (3), eta_i (3)
SEED_EULER = 3              # eta_i = (phi, theta, psi) [rad] within a UAV's block


def seed_uav_slot(i: int) -> int:
    """Offset of UAV i's block (r_i, eta_i) in q_f."""
    return SEED_UAV_COORDINATES * i


def seed_payload_slot(n_uavs: int) -> int:
    """Offset of r_p in q_f for n UAVs."""
    return SEED_UAV_COORDINATES * n_uavs


def seed_coordinates(n_uavs: int) -> int:
    """Length of q_f: 6n + 3."""
    return SEED_UAV_COORDINATES * n_uavs + PAYLOAD_COORDINATES


# -- a UAV's constants (one row per UAV) ------------------------------------------------------
UAV_MASS = 0                # m_i [kg]
UAV_LENGTH_SQ = 1           # l_i^2 [m^2], its cable's length squared
UAV_INV_INERTIA = 2         # 1/I_xx, 1/I_yy, 1/I_zz [1/(kg m^2)], body FLU axes (3 slots)
UAV_GYRO = 5                # (I_zz - I_yy)/I_xx, (I_xx - I_zz)/I_yy, (I_yy - I_xx)/I_zz (3)
UAV_DRAG = 8                # c_d [N s^2/m^2]: the UAV's quadratic drag in the wind; 0: none
UAV_PAYLOAD_ATTACH = 9      # b_i [m]: where its cable holds a rigid payload, payload frame (3)
UAV_ATTACH = 12             # a_i [m]: where its cable holds the UAV, body FLU; 0: its centre (3)
UAV_CABLE_STIFFNESS = 15    # k_i [N/m]: its cable's axial stiffness (`cable_model: elastic`)
UAV_CABLE_DAMPING = 16      # c_i [N s/m]: its cable's axial damping (`cable_model: elastic`)
# its winch (`uavs[i].winch`, physics.winch; all 0: none): the reel's limits
UAV_WINCH_RATE_LIMIT = 17   # the largest |l_dot| [m/s]
UAV_WINCH_ACCELERATION_LIMIT = 18  # the largest |l_ddot| [m/s^2]
UAV_WINCH_MIN_LENGTH = 19   # its stops: the shortest and longest cable [m] (2 slots)
UAV_WINCH_MAX_LENGTH = 20
# the reel's motion over the current control period (a period's copy of the rows holds them;
# physics.winch.reel_period): from length l_0 [m] and rate v_0 [m/s] at time t_0 [s] towards
# the target rate [m/s] at the acceleration limit
UAV_REEL_START = 21         # t_0 [s]
UAV_REEL_LENGTH = 22        # l_0 [m]
UAV_REEL_RATE = 23          # v_0 [m/s]
UAV_REEL_TARGET = 24        # the rate it heads for [m/s] (positive pays out)
# its cable's inner nodes (`cable_model: chain`, physics.chain_cables; 0: none)
UAV_NODE_MASS = 25          # each inner node's mass [kg]: the cable's mu l over N - 1 nodes
UAV_NODE_DRAG = 26          # each node's quadratic drag 0.5 rho C_d d (l / N) [N s^2/m^2]
UAV_COLUMNS = 27

# -- a UAV's body wrench (one row per UAV; FormationModel.wrenches) ----------------------------
WRENCH_THRUST = 0           # u_T [N], along the body z axis
WRENCH_TORQUE = 1           # tau_x, tau_y, tau_z [N m], body FLU (3 slots)
WRENCH_COLUMNS = 4

# -- a UAV's rotor actuators (one row per UAV; physics.actuators) -----------------------------
ACTUATOR_TIME_CONSTANT = 0  # tau_m [s]: each rotor's first-order lag to its command; 0: none
ACTUATOR_RATE_LIMIT = 1     # the largest |d omega / dt| [rad/s^2]; inf: none
ACTUATOR_COLUMNS = 2

# -- an event of the scenario's `events:` (rows of (k, EVENT_COLUMNS) in time order;
# physics.events); its kinds are registered parts, `multilift_sim.events.EVENT_KINDS` -------
EVENT_TICK = 0              # the control tick it happens at (the first at or after its time)
EVENT_TIME = 1              # the time the scenario gives [s]
EVENT_KIND = 2              # its kind's index in multilift_sim.events.EVENT_KINDS
EVENT_UAV = 3               # the UAV it concerns, from 0 (-1: none)
EVENT_ROTOR = 4             # the rotor, from 0 (rotor_effectiveness; else 0)
EVENT_VALUE = 5             # rotor_effectiveness: its new effectiveness; silence: seconds;
#                             gust: its peak speed [m/s]
EVENT_END_TICK = 6          # controller_silence: the first tick whose command arrives again
EVENT_DURATION = 7          # gust: how long it blows [s]
EVENT_VELOCITY = 8          # gust: its peak velocity [m/s], world (3)
EVENT_COLUMNS = 11

# -- a UAV's winch as a tick leaves it (the memory's `reel`, (n, REEL_COLUMNS); physics.winch) --
REEL_LENGTH = 0             # l_i [m]: its cable's (rest) length now
REEL_RATE = 1               # l_i_dot [m/s], positive paying out
REEL_COMMAND = 2            # the reel rate commanded [m/s] (events `winch`, /uav{i}/winch_cmd)
REEL_COLUMNS = 3

# -- a gust (seed Eq. 2.55; wind.gusts.Gust) --------------------------------------------------
GUST_CENTER = 0             # (x, y) of its centre [m], world (2 slots)
GUST_DIRECTION = 2          # unit direction, world (3 slots)
GUST_GRADIENT_DISTANCE = 5  # h [m]
GUST_REFERENCE_SPEED = 6    # U_ref [m/s]
GUST_COLUMNS = 7

# -- the formation's scalars ------------------------------------------------------------------
FORMATION_PAYLOAD_MASS = 0      # m_p [kg]
FORMATION_INV_PAYLOAD_MASS = 1  # 1/m_p [1/kg]
FORMATION_GRAVITY = 2           # g [m/s^2], along -z of the world
FORMATION_TWO_ALPHA = 3         # 2 alpha_f [1/s] (seed Eq. 2.59)
FORMATION_BETA_SQ = 4           # beta_f^2 [1/s^2] (seed Eq. 2.59)
FORMATION_DRAG = 5              # c_pd [N s^2/m^2] (seed Eq. 2.53); 0: no drag
FORMATION_WIND = 6              # the steady wind [m/s], world, everywhere (3 slots)
FORMATION_NULL_SPACE = 9        # 1: q_ddot by the null-space form (Eq. 2.71-2.72, 2.57), the
#                                 `nullspace` formulation; 0: the multipliers (Eq. 2.59-2.60)
FORMATION_PAYLOAD_INERTIA = 10  # a rigid payload's principal moments J_p [kg m^2], payload
#                                 frame (3 slots; whether it is rigid: x's length)
FORMATION_PROJECTION_STEPS = 13  # the null-space form's Newton steps onto g = 0 after each RK4
#                                 step (physics.nullspace.project); 0: no projection
FORMATION_PROJECTION_TOLERANCE = 14  # |g_i| / l_i^2 the projection accepts
FORMATION_SUBSTEPS = 15      # RK4 sub-steps per physics step (>= 1; the formation's parts
#                                 stepped at that multiple of the physics rate: stiff cables)
FORMATION_ELASTIC = 16      # 1: the cables are elastic ropes (physics.elastic_cables: no
#                             multipliers, each pulls k stretch + c stretch rate when taut)
FORMATION_PRESCRIBED = 17  # 1: some UAV's motion is prescribed (`uavs[i].trajectory`,
#                             physics.prescribed): the drive table follows the scalars
FORMATION_TIME = 18         # with FORMATION_PRESCRIBED or FORMATION_WINCH: the time [s] the
#                             drives and reels are evaluated at (the RK4 stage's; a period's
#                             copy of these scalars holds it)
FORMATION_WINCH = 19        # 1: some UAV carries a winch (physics.winch): cable lengths l_i(t)
FORMATION_CHAIN_LINKS = 20  # N, the links of every cable (`cable_model: chain`); 0: no chain
FORMATION_SCALARS = 21

# -- the drive table of prescribed UAVs (physics.prescribed), after the formation's scalars
# when FORMATION_PRESCRIBED: n slots (UAV i's at FORMATION_SCALARS + i: the offset of its drive
# in the formation's array, 0: not prescribed), then each drive: its piece count m, its
# m + 1 knots [s], then m pieces of DRIVE_AXES x DRIVE_ORDER coefficients (piece k, axis a,
# power j at DRIVE_KNOTS + m + 1 + (k DRIVE_AXES + a) DRIVE_ORDER + j: sum_j c_j (t - t_k)^j)
DRIVE_PIECES = 0            # m
DRIVE_KNOTS = 1             # t_0 .. t_m [s], increasing
DRIVE_AXES = 6              # x, y, z [m], world z up; roll, pitch, yaw [rad] (ZYX)
DRIVE_POSITION = 0          # the position axes (3)
DRIVE_EULER = 3             # the attitude axes (3)
DRIVE_ORDER = 6             # coefficients a piece and axis: degree 5 at most

# -- per cable, what a solve keeps between its passes (scratch, (n, CABLE_COLUMNS)) ------------
CABLE_OFFSET = 0            # d_i = r_p - r_i [m] (3 slots; from the attach points)
CABLE_RHS = 3               # row i of the right-hand side of the multiplier equation
CABLE_INV_DELTA = 4         # 1 / delta_i = m_i / (4 |d_i|^2) [kg/m^2] (+ the UAV's rotation)
CABLE_THRUST = 5            # UAV i's thrust (and drag) acceleration u_T R e_z / m_i [m/s^2] (3)
CABLE_MOMENT = 8            # k_i = a_i x R_i^T d_i [m^2], body FLU: the pull's moment arm (3)
CABLE_PAYLOAD_MOMENT = 11   # c_i = b_i x R_p^T d_i [m^2], a rigid payload's frame: its moment
#                             arm there (3; physics.rigid_payload)
CABLE_COLUMNS = 14

# -- a chain's solve scratch (`cable_model: chain`, physics.chain_cables): per cable, a row a
# link k = 1 .. N (at k - 1) and a row a node j = 0 .. N - 1 (node 0 the UAV) ----------------
CHAIN_LINK_OFFSET = 0       # d_k = r_k - r_(k-1) [m] (3 slots)
CHAIN_LINK_DIAGONAL = 3     # the links' matrix A's diagonal entry, then the eliminated one
CHAIN_LINK_UPPER = 4        # A[k, k + 1]
CHAIN_LINK_U = 5            # the right-hand side, then u = A^-1 of it, then lambda_k [N/m]
CHAIN_LINK_W = 6            # e_N, then w = A^-1 e_N
CHAIN_LINK_COLUMNS = 7
CHAIN_NODE_FREE = 0         # the node's acceleration without the links [m/s^2], gravity
#                             excluded (3 slots)
CHAIN_NODE_INV_MASS = 3     # 1 / its mass [1/kg]
CHAIN_NODE_COLUMNS = 4

# -- an RK4 step's scratch (rows of a (WORK_ROWS, len(x)) array) ---------------------------
WORK_K1, WORK_K2, WORK_K3, WORK_K4 = 0, 1, 2, 3     # the stage derivatives (consecutive rows)
WORK_STAGE = 4              # the stage's state
WORK_ACC = 5                # the stage's q_ddot, then its attitude blocks' rates
WORK_MULTIPLIERS = 6        # Lambda of the later stages (its first n entries)
WORK_ROWS = 7

# -- a slack step's scratch: states (rows of (SLACK_STATES, len(x))), per cable values
# (rows of (SLACK_CABLE_ROWS, n)) and flags (rows of a bool (SLACK_FLAGS, n)) ------------------
SLACK_END = 0               # the state at the end of the (rest of the) step
SLACK_EVENT = 1             # the state at the located event (the last guard evaluated)
SLACK_BRACKET = 2           # the state at the bracket's upper end
SLACK_STATES = 3
SLACK_G_END, SLACK_G_DOT_END = 0, 1     # g [m^2], g_dot [m^2/s] at the end
SLACK_VALUE, SLACK_VALUE_BRACKET = 2, 3     # g / l^2 at the event's and bracket's states
SLACK_TARGET = 4            # the g each taut cable is projected to [m^2]
SLACK_SOLUTION = 5          # the solution of a solve in the mass metric
SLACK_MULTIPLIERS = 6       # Lambda of a taut set's update
SLACK_CABLE_ROWS = 7
SLACK_WATCHED, SLACK_CROSSING, SLACK_SNAPPING = 0, 1, 2
SLACK_FLAGS = 3

# -- a UAV's measured state: what the controllers read, one row of (n, MEASURED_COLUMNS) -------
MEASURED_POSITION = 0       # r_i [m], world (3 slots)
MEASURED_VELOCITY = 3       # r_i_dot [m/s], world (3)
MEASURED_EULER = 6          # eta_i = (roll, pitch, yaw) [rad] of its quaternion (3)
MEASURED_BODY_RATES = 9     # omega_i [rad/s], body FLU (3)
MEASURED_COLUMNS = 12
# -- what a sensor model reads of its UAV (`sensors.sensing.sensed_states`): its measured state
# (the MEASURED_* slots), then its cable's, one row of (n, SENSED_COLUMNS) ----------------------
SENSED_CABLE_DIRECTION = 12  # the cable's unit direction from its attach point on the UAV to
#                              the payload, world (3)
SENSED_CABLE_TENSION = 15   # its tension T_i [N] at the last tick flown (NaN before the first)
SENSED_COLUMNS = 16

# -- a UAV's odometry: its measured state (the MEASURED_* slots), then the rest of what its
# messages carry (/formation/snapshot, /uav{i}/odom, /tf), one row of (n, ODOMETRY_COLUMNS) ---
ODOMETRY_ROTATION = 12      # R = Rz(psi) Ry(theta) Rx(phi), body -> world, row by row (9)
ODOMETRY_BODY_VELOCITY = 21  # R^T r_i_dot [m/s], body FLU (3)
ODOMETRY_QUATERNION = 24    # (x, y, z, w) of R, scalar last as geometry_msgs orders it (4)
ODOMETRY_COLUMNS = 28

# -- a formation's status in a batch (the memory's `status`; physics.tick) ----------------------
STATUS_RUNNING = 0          # ticks left
STATUS_FINISHED = 1         # reached its duration (the state at t_max is the last)
STATUS_NOT_FINITE = 2       # stopped: the state became non-finite (Algorithm 1)
STATUS_OFF_CONSTRAINT = 3   # stopped: a taut cable's |g| left constraint_tolerance (Algorithm 1)
STATUS_OFF_RATE = 4         # stopped: a taut cable's |g_dot| left constraint_rate_tolerance
STATUS_QUATERNION = 5       # stopped: a body's attitude quaternion lost its unit norm
STATUS_CONTACT = 6          # stopped: a body touched another or the world (clearance <= 0;
#                             world.on_contact: stop, physics.clearance)

# -- an obstacle of `world.obstacles` (one row of (k, OBSTACLE_COLUMNS); its type a registered
# part, multilift_sim.obstacles.OBSTACLE_TYPES, whose compiled `distance` reads the row) -------
OBSTACLE_TYPE = 0           # its type's index in OBSTACLE_TYPES
OBSTACLE_CENTER = 1         # its centre [m], world (3 slots)
OBSTACLE_HALF = 4           # half its extent along its own axes [m] (box: size / 2; cylinder:
#                             radius, radius, height / 2; sphere: radius, radius, radius) (3)
OBSTACLE_COS_YAW = 7        # cos and sin of its yaw about world z (its x axis from world x)
OBSTACLE_SIN_YAW = 8
OBSTACLE_BOUND = 9          # the radius of a sphere about its centre that holds it [m]
OBSTACLE_COLUMNS = 10

# -- the world's scalars (one row of WORLD_COLUMNS per formation; physics.clearance) ------------
WORLD_CHECKED = 0           # 1: clearances measured (a `world:` section or vehicle.radius); 0: none
WORLD_GROUND = 1            # the ground's height [m], world z (NaN: no ground)
WORLD_PAYLOAD_RADIUS = 2    # the payload's radius [m] about r_p (a rigid body's bounding sphere)
WORLD_RECORD_CONTACT = 3    # 1: world.on_contact: record (fly on); 0: stop
WORLD_COLUMNS = 4

# -- the least clearance of each kind (one row of CLEARANCE_COLUMNS per kind in the memory's
# `clearance`, (CLEARANCE_KINDS, CLEARANCE_COLUMNS); the first contact in `contact`) -----------
CLEARANCE_UAV_WORLD = 0     # a UAV's sphere to an obstacle or the ground
CLEARANCE_CABLE_WORLD = 1   # a cable's segment to an obstacle or the ground
CLEARANCE_PAYLOAD_WORLD = 2  # the payload's sphere to an obstacle or the ground
CLEARANCE_UAV_UAV = 3       # two UAVs' spheres
CLEARANCE_UAV_CABLE = 4     # a UAV's sphere to another UAV's cable
CLEARANCE_CABLE_CABLE = 5   # two cables that do not meet at the payload (a rigid body's)
CLEARANCE_KINDS = 6
CLEARANCE_VALUE = 0         # the least clearance [m] (+inf: none measured)
CLEARANCE_TIME = 1          # when [s]
CLEARANCE_FIRST = 2         # between what: a UAV or cable (from 0), or 0 the payload
CLEARANCE_SECOND = 3        # and what: an obstacle (from 0), OBSTACLE_GROUND, or a UAV / cable
CLEARANCE_KIND = 4          # (the `contact` row only) its kind, -1: no contact yet
CLEARANCE_COLUMNS = 5
OBSTACLE_GROUND = -1        # CLEARANCE_SECOND of the ground
