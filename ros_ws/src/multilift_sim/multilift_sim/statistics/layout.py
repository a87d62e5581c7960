"""The named slots of the run statistics' accumulator arrays, in one place (numba freezes these
module-level integers into the compiled code). Every array is float64; counts are kept as
floats (exact below 2^53).

- a peak/rms block (PEAK_*): the max, the sum of squares and the count of a non-negative
  signal sampled once per tick; the swing's and the tracking error's;
- the simulator's run (RUN_*, `run_size(n)` floats): the scalars, then a block of
  RUN_UAV_COLUMNS per UAV i at `run_uav_slot(i, column)`;
- a leader's tracking error (TRACKING_*), a follower's formation error (FORMATION_*).

Units: SI, world frame z up (docs/conventions.md).
"""
from __future__ import annotations

# -- a peak/rms block: max and root mean square of a signal sampled once per tick ---------------
PEAK_MAX = 0            # the largest sample
PEAK_SUM_SQ = 1         # the sum of the squared samples
PEAK_SAMPLES = 2        # how many samples
PEAK_SIZE = 3

# -- the simulator's run (RunStatistics) -------------------------------------------------------
RUN_MAX_ABS_G = 0           # max_i,t |g_i| over taut cables [m^2]
RUN_MAX_ABS_G_DOT = 1       # max_i,t |g_i_dot| over taut cables [m^2/s]
RUN_MIN_TENSION = 2         # min over cables and ticks of T_i [N] (+inf: none yet)
RUN_MAX_TENSION = 3         # max over cables and ticks of T_i [N] (-inf: none yet)
RUN_SIMULATED_TIME = 4      # the time of the last state checked [s]
RUN_MAX_GUST_SPEED = 5      # the peak gust speed met by the payload [m/s]
RUN_SWING = 6               # a peak/rms block (PEAK_*): the payload swing [m], from SWING_FROM
RUN_COMPRESSED_TIME = RUN_SWING + PEAK_SIZE  # time with a cable pushing (T_i < 0: rigid) [s]
# the estimators' errors against the truth (statistics.estimation), at every tick flown with an
# estimator (issue 33 item 6): how many, then the payload's sums (with payload_estimator:)
RUN_ESTIMATION_SAMPLES = RUN_COMPRESSED_TIME + 1  # ticks with an estimate
RUN_PAYLOAD_POSITION_SQ = RUN_ESTIMATION_SAMPLES + 1  # sum of |p_hat - p|^2 [m^2]
RUN_PAYLOAD_VELOCITY_SQ = RUN_ESTIMATION_SAMPLES + 2  # sum of |v_hat - v|^2 [m^2/s^2]
RUN_PAYLOAD_NEES = RUN_ESTIMATION_SAMPLES + 3  # sum of its position NEES (3 dof)
RUN_SCALARS = RUN_ESTIMATION_SAMPLES + 4
# the payload swing is measured from this time on [s]: before it, a released payload's first
# swing (twin_lift's 15 deg release: 2.6 m) would be every run's maximum, the same whatever
# the controllers do
SWING_FROM = 10.0
# a UAV's block, RUN_UAV_COLUMNS floats from run_uav_slot(i, 0)
RUN_MAX_ROTOR_SPEED = 0     # its peak commanded rotor speed [rad/s]
RUN_SATURATED_TIME = 1      # time with a rotor held at a speed limit the allocator wanted it
#                             beyond (the mixer's `saturated`; not a failed or pinned rotor) [s]
RUN_SLACK_TIME = 2          # time its cable was slack (cable_model: slack) [s]
RUN_LEAST_THRUST_MARGIN = 3  # least share of its largest thrust left by its commands (1 -
#                              u_T / u_T,max with the rotors' effectiveness; +inf: none yet)
RUN_MAX_STRETCH = 4         # its rope's largest stretch L_i - l_i [m] (cable_model: elastic;
#                             -inf: none yet, and in every other cable model's run)
RUN_PEAK_TENSION = 5        # its rope's largest tension T_i [N] (cable_model: elastic; -inf)
RUN_SHORTEST_CABLE = 6      # its cable's shortest length l_i [m] reeled by its winch (+inf:
#                             none yet, and in every run without winches)
RUN_LONGEST_CABLE = 7       # its cable's longest length [m] (-inf)
RUN_MAX_SAG = 8             # its chain's largest sag [m]: an inner node's distance from the
#                             chord UAV -> payload (cable_model: chain; -inf: none, and in
#                             every other cable model's run)
RUN_POSITION_ERROR_SQ = 9   # with an estimator: sum of |r_hat - r|^2 [m^2]
RUN_ATTITUDE_ERROR_SQ = 10  # sum of |Log(q_hat^-1 q)|^2 [rad^2]
RUN_POSITION_NEES = 11      # sum of its position NEES (3 dof)
RUN_ATTITUDE_NEES = 12      # sum of its attitude NEES (3 dof)
RUN_UAV_COLUMNS = 13


def run_size(n_uavs: int) -> int:
    """Length of a run's accumulator array for n UAVs."""
    return RUN_SCALARS + RUN_UAV_COLUMNS * n_uavs


def run_uav_slot(uav: int, column: int) -> int:
    """Index of UAV `uav`'s (from 0) `column` (RUN_MAX_ROTOR_SPEED, ...) in a run's array
    (the compiled functions spell out the same sum: numba cannot call this)."""
    return RUN_SCALARS + RUN_UAV_COLUMNS * uav + column


# -- a leader's tracking error |r_ref - r_1| [m] (TrackingStatistics): one peak/rms block ------
TRACKING_ERROR = 0
TRACKING_SIZE = PEAK_SIZE

# -- a follower's virtual-constraint residual g_vc [m] (FormationErrorStatistics) --------------
FORMATION_MAX_ABS = 0       # max over rows and ticks of |g_vc| [m]
FORMATION_NORM_SUM = 1      # sum over ticks of |g_vc| (Euclidean) [m]
FORMATION_SAMPLES = 2       # ticks answered
FORMATION_SIZE = 3

# -- what the Algorithm-1 check (accumulators.run_check) returns -------------------------------
CHECK_OK = 0
CHECK_NON_FINITE = 1        # the formation state is not finite
CHECK_G = 2                 # a taut cable's |g| exceeds the constraint tolerance
CHECK_G_DOT = 3             # a taut cable's |g_dot| exceeds the rate tolerance
CHECK_QUATERNION = 4        # a body's attitude quaternion lost its unit norm
# how far a body's |q| may be from 1 before the state no longer represents an attitude: each
# RK4 step scales every quaternion back to unit length, so |q| - 1 is rounding (~1e-16) in any
# state the model made; past this a state is broken (a tumble itself never is: a unit
# quaternion represents every attitude)
QUATERNION_NORM_TOLERANCE = 1e-9
