"""The topics of a multilift run and their message types: the one table (no rclpy).

The simulator, the controllers, the recorder, the headless bag writer, the bag reader and the
tools all name topics from here. UAV indices count from 1 (1 = the leader). Types are written
`pkg/msg/Type`, as rosbag2 and `ros2 topic` write them. Frames and units: README.md.
"""
from __future__ import annotations

import re
from collections.abc import Sequence

# message types
CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'
ODOMETRY_TYPE = 'nav_msgs/msg/Odometry'
VECTOR3_STAMPED_TYPE = 'geometry_msgs/msg/Vector3Stamped'
MARKER_ARRAY_TYPE = 'visualization_msgs/msg/MarkerArray'
FORMATION_STATE_TYPE = 'multilift_msgs/msg/FormationState'
FORMATION_SNAPSHOT_TYPE = 'multilift_msgs/msg/FormationSnapshot'
ROTOR_COMMAND_TYPE = 'multilift_msgs/msg/RotorCommand'
ATTITUDE_SETPOINT_TYPE = 'multilift_msgs/msg/AttitudeSetpoint'
TRACKING_REFERENCE_TYPE = 'multilift_msgs/msg/TrackingReference'
FORMATION_ERROR_TYPE = 'multilift_msgs/msg/VirtualConstraintError'
FORMATION_EVENT_TYPE = 'multilift_msgs/msg/FormationEvent'
TF_TYPE = 'tf2_msgs/msg/TFMessage'
POSE_STAMPED_TYPE = 'geometry_msgs/msg/PoseStamped'
PATH_TYPE = 'nav_msgs/msg/Path'
FLOAT64_TYPE = 'std_msgs/msg/Float64'
WINCH_COMMAND_TYPE = 'multilift_msgs/msg/WinchCommand'

# topics of the whole run
CLOCK = '/clock'                        # simulated time, the simulator only
PAYLOAD_ODOM = '/payload/odom'          # payload position and velocity
PAYLOAD_GUST = '/payload/gust'          # gust velocity at the payload [m/s], world
PAYLOAD_ESTIMATE = '/payload/estimate'  # the payload's estimate with its covariance
FORMATION_STATE = '/formation/state'    # per cable: tension, g_i, g_i_dot
FORMATION_SNAPSHOT = '/formation/snapshot'  # what the controllers read, one message a tick
MARKERS = '/visualization/markers'      # the formation drawn for RViz / Foxglove
MARKER_DECIMATION = 10                  # MARKERS every this many control ticks
TF = '/tf'                              # world -> uav{i}/base_link, world -> payload
EVENTS = '/formation/events'            # the scenario's events as they happen
WIND = '/formation/wind'                # the air's velocity everywhere [m/s], world
GOAL = '/formation/goal'                # a live goal for the leader (run --live), world
PATH = '/formation/path'                # a live path for the leader (run --live), world

# leaves of the per-UAV topics /uav{i}/{leaf}
ODOM = 'odom'                           # UAV i's state (every UAV)
MEASURED_ODOM = 'measured_odom'         # what UAV i's controllers receive (with `sensors:`)
ESTIMATE = 'estimate'                   # UAV i's estimate with its covariance (an estimator)
ROTOR_CMD = 'rotor_cmd'                 # UAV i's rotor speeds (every UAV)
ATTITUDE_SETPOINT = 'attitude_setpoint'  # UAV i's outer-loop output (every UAV)
REFERENCE = 'reference'                 # the mission reference (the leader only)
FORMATION_ERROR = 'formation_error'     # follower i's rows of g_vc (followers only)
CABLE_LENGTH = 'cable_length'           # UAV i's cable length [m] (a UAV with a winch)
THRUST_MARGIN = 'thrust_margin'         # UAV i's thrust margin (a reorganising formation)
WINCH_CMD = 'winch_cmd'                 # a live reel rate for UAV i's winch [m/s] (run --live)
WINCH_CMD_STAMPED = 'winch_cmd_stamped'  # the same from its stamp's tick (simulated time)

UAV_TYPES = {ODOM: ODOMETRY_TYPE, MEASURED_ODOM: ODOMETRY_TYPE, ESTIMATE: ODOMETRY_TYPE,
             ROTOR_CMD: ROTOR_COMMAND_TYPE,
             ATTITUDE_SETPOINT: ATTITUDE_SETPOINT_TYPE, REFERENCE: TRACKING_REFERENCE_TYPE,
             FORMATION_ERROR: FORMATION_ERROR_TYPE, CABLE_LENGTH: FLOAT64_TYPE,
             WINCH_CMD: FLOAT64_TYPE, WINCH_CMD_STAMPED: WINCH_COMMAND_TYPE,
             THRUST_MARGIN: FLOAT64_TYPE}
RUN_TYPES = {CLOCK: CLOCK_TYPE, PAYLOAD_ODOM: ODOMETRY_TYPE,
             FORMATION_STATE: FORMATION_STATE_TYPE, FORMATION_SNAPSHOT: FORMATION_SNAPSHOT_TYPE,
             PAYLOAD_GUST: VECTOR3_STAMPED_TYPE,
             MARKERS: MARKER_ARRAY_TYPE, TF: TF_TYPE}
# the topic of a run with a payload estimator (run_topics(payload_estimate=True))
PAYLOAD_ESTIMATE_TYPES = {PAYLOAD_ESTIMATE: ODOMETRY_TYPE}
# the topic of a run whose scenario has `events:` (run_topics(events=True))
EVENT_TYPES = {EVENTS: FORMATION_EVENT_TYPE}
# the topic of a run whose air moves everywhere (run_topics(wind=True), Scenario.has_wind)
WIND_TYPES = {WIND: VECTOR3_STAMPED_TYPE}
# the topics a live run's leader reads (run_topics(live=True), `multilift run --live`)
LIVE_TYPES = {GOAL: POSE_STAMPED_TYPE, PATH: PATH_TYPE}

_UAV_TOPIC = re.compile(r'^/uav([1-9][0-9]*)/(' + '|'.join(UAV_TYPES) + r')$')


def uav_topic(index: int, leaf: str) -> str:
    """`/uav{index}/{leaf}`, index from 1 (1 is the leader)."""
    return f'/uav{index}/{leaf}'


REFERENCE_TOPIC = uav_topic(1, REFERENCE)


def state_topics(n_uavs: int, sensors: bool = False) -> list[str]:
    """The topics carrying the simulator's state at t, any of which a controller may read to
    answer it (every UAV's odometry, with `sensors` what the controllers receive of it, the
    snapshot our controllers read, the payload's odometry, /tf): before t = 0 the simulator
    waits for an external controller to subscribe to one (`SimNode.missing_peers`). Not
    /clock: every node with use_sim_time reads it."""
    leaves = (ODOM, MEASURED_ODOM) if sensors else (ODOM,)
    return ([FORMATION_SNAPSHOT] + [uav_topic(i, leaf) for i in range(1, n_uavs + 1)
                                    for leaf in leaves] + [PAYLOAD_ODOM, TF])


def parse_uav_topic(topic: str) -> tuple[int, str] | None:
    """(index, leaf) of a per-UAV topic such as `/uav2/odom`, or None for any other name."""
    match = _UAV_TOPIC.match(topic)
    return (int(match.group(1)), match.group(2)) if match else None


def topic_type(topic: str) -> str | None:
    """The type a multilift topic has (`pkg/msg/Type`), or None for a name not of a run."""
    every = {**RUN_TYPES, **EVENT_TYPES, **WIND_TYPES, **LIVE_TYPES, **PAYLOAD_ESTIMATE_TYPES}
    if topic in every:
        return every[topic]
    parsed = parse_uav_topic(topic)
    return UAV_TYPES[parsed[1]] if parsed else None


def run_topics(n_uavs: int, controllers: bool = True, events: bool = False,
               sensors: bool = False, wind: bool = False, commands: bool = True,
               live: bool = False, winches: Sequence[int] = (), estimates: bool = False,
               payload_estimate: bool = False, margins: bool = False) -> list[tuple[str, str]]:
    """Every topic a run of n UAVs publishes, with its type: what the recorder records. Without
    `controllers`, only the rotor commands of what the controllers publish (a policy's run,
    which has no reference, set-points or formation errors); with `events` (a scenario with
    `events:`), /formation/events; with `sensors` (a scenario with `sensors:`), every
    /uav{i}/measured_odom; with `wind` (Scenario.has_wind), /formation/wind; without
    `commands` (every UAV prescribed) not even the rotor commands; with `live` (`run --live`),
    /formation/goal and /formation/path; for each UAV of `winches` (from 1: those with a
    winch) /uav{i}/cable_length, and with `live` /uav{i}/winch_cmd and
    /uav{i}/winch_cmd_stamped; with `estimates` (an
    estimator, docs/estimation.md) every /uav{i}/estimate; with `payload_estimate` (a payload
    estimator) /payload/estimate; with `margins` (a reorganising formation, `margin_topics`)
    every /uav{i}/thrust_margin."""
    topics = list(RUN_TYPES.items()) + (list(EVENT_TYPES.items()) if events else []) + (
        list(WIND_TYPES.items()) if wind else []) + (list(LIVE_TYPES.items()) if live else []) + (
        list(PAYLOAD_ESTIMATE_TYPES.items()) if payload_estimate else [])
    if controllers:
        topics.append((REFERENCE_TOPIC, TRACKING_REFERENCE_TYPE))
    for i in range(1, n_uavs + 1):
        topics += [(uav_topic(i, leaf), UAV_TYPES[leaf])
                   for leaf in ((ODOM, ROTOR_CMD, ATTITUDE_SETPOINT) if controllers
                                else (ODOM, ROTOR_CMD) if commands else (ODOM,))]
        if sensors:
            topics.append((uav_topic(i, MEASURED_ODOM), ODOMETRY_TYPE))
        if estimates:
            topics.append((uav_topic(i, ESTIMATE), ODOMETRY_TYPE))
        if i > 1 and controllers:
            topics.append((uav_topic(i, FORMATION_ERROR), FORMATION_ERROR_TYPE))
        if margins:
            topics.append((uav_topic(i, THRUST_MARGIN), FLOAT64_TYPE))
        if i in winches:
            topics += [(uav_topic(i, leaf), UAV_TYPES[leaf])
                       for leaf in ((CABLE_LENGTH, WINCH_CMD, WINCH_CMD_STAMPED) if live
                                    else (CABLE_LENGTH,))]
    return topics


def scenario_topics(scenario, controllers: bool = True, live: bool = False
                    ) -> list[tuple[str, str]]:
    """`run_topics` of a scenario (multilift_sim.scenario.Scenario): its n, and the topics its
    `events:`, `sensors:`, estimator, wind, winches and reorganisation add (and a live run's,
    `live`); none of
    the controllers' when every UAV's motion is prescribed (`uavs[i].trajectory`: no
    controller runs)."""
    return run_topics(scenario.n_uavs, controllers and scenario.controlled,
                      bool(scenario.events), scenario.measures, scenario.has_wind,
                      commands=scenario.controlled, live=live, winches=scenario.winches,
                      estimates=scenario.estimator is not None,
                      payload_estimate=scenario.payload_estimator is not None,
                      margins=margin_topics(scenario))


def margin_topics(scenario) -> bool:
    """Whether the run publishes each UAV's /uav{i}/thrust_margin: a formation that
    reorganises to share its load (`formation.reorganize: thrust_margin` or `cable_forces`,
    issue 35), whose controllers fly; the others' bags keep their topics."""
    formation = scenario.formation
    return (scenario.controlled and formation is not None
            and formation.reorganize in ('thrust_margin', 'cable_forces'))


def parse_external(text: str, n_uavs: int) -> list[int]:
    """`uav1,uav3` (or `1,3`) -> [1, 3]: the UAVs whose controllers are the user's own."""
    indices = []
    for part in (p.strip() for p in text.split(',')):
        if not part:
            continue
        digits = part[3:] if part.startswith('uav') else part
        if not digits.isdigit() or not 1 <= int(digits) <= n_uavs:
            raise ValueError(f'external UAV {part!r} is not one of uav1..uav{n_uavs}')
        if int(digits) not in indices:
            indices.append(int(digits))
    return sorted(indices)
