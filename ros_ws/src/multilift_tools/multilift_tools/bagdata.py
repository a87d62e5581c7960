"""Read a multilift run bag (rosbag2 directory, MCAP) into numpy arrays, without rclpy.

`load_run(bag_dir)` makes one pass over the bag with rosbags' AnyReader and returns a `Run`:
one `Series` per known topic (times from the header stamps, simulated seconds [s], sorted)
and typed accessors in the units and frames of README.md / docs/conventions.md: world frame
`world`, z up, SI units; UAV index i counts from 1 (1 = the leader), as the topic names do.
`summary.json` next to `metadata.yaml` (written by `scripts/multilift run`) is read when present.
What each message type becomes is `bagfields`.

`run_scenario(run)` finds the scenario the run was made from (by the summary's scenario name, or
a name/path given) for what the bag does not carry: rotor limits, k_T, gusts, formation geometry.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

from multilift_sim.kinematics import euler_from_quaternion
from multilift_sim.topics import (ATTITUDE_SETPOINT, CABLE_LENGTH, EVENTS, FORMATION_ERROR,
                                  FORMATION_STATE,
                                  ODOM, PAYLOAD_GUST, PAYLOAD_ODOM, REFERENCE_TOPIC, ROTOR_CMD,
                                  uav_topic)
from multilift_tools.bagfields import EXTRACT, RunDataError, wanted_type

if TYPE_CHECKING:
    from multilift_sim.scenario import Scenario


@dataclass(frozen=True)
class Series:
    """The samples of one topic: `t` header stamps [s] (T,), ascending; `fields` name -> array
    (T, ...) in the message's units (see the accessors of `Run`)."""

    topic: str
    t: np.ndarray
    fields: Mapping[str, np.ndarray]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.fields[name]

    def __len__(self) -> int:
        return len(self.t)


def _stack(topic: str, name: str, rows: list[Any]) -> np.ndarray:
    lengths = {np.size(r) for r in rows}
    if len(lengths) > 1:
        raise RunDataError(f'{topic}: field {name} changes length within the bag '
                           f'({sorted(lengths)})')
    return np.asarray([np.asarray(r) for r in rows])


def _series(topic: str, stamps: list[float], rows: list[dict[str, Any]]) -> Series:
    order = np.argsort(np.asarray(stamps), kind='stable')
    t = np.asarray(stamps, dtype=float)[order]
    fields = {name: _stack(topic, name, [rows[k][name] for k in order]) for name in rows[0]}
    return Series(topic, t, fields)


@dataclass(frozen=True)
class Run:
    """One recorded run. Times [s] are simulated (header stamps); positions world [m], z up.

    UAV indices i count from 1 (1 = the leader). Accessors raise `RunDataError` naming the
    topic when the bag lacks it; `has(topic)` asks first.
    """

    path: Path
    series: Mapping[str, Series]
    summary: Mapping[str, Any] = field(default_factory=dict)

    # -- topics ----------------------------------------------------------------------------
    def has(self, topic: str) -> bool:
        """Whether the bag holds at least one message of `topic`."""
        return topic in self.series

    def topic(self, topic: str) -> Series:
        """The `Series` of `topic`; RunDataError if the bag has none."""
        try:
            return self.series[topic]
        except KeyError:
            raise RunDataError(f'bag {self.path} has no messages on {topic}') from None

    def events(self) -> list[tuple[float, str]]:
        """The scenario's events the run met: (time [s] of the first state showing it, its
        description), from /formation/events (none in a bag without it)."""
        if not self.has(EVENTS):
            return []
        series = self.topic(EVENTS)
        return [(float(t), str(text)) for t, text in zip(series.t, series['description'])]

    @property
    def n_uavs(self) -> int:
        """Number of UAVs: /uav1/odom, /uav2/odom, ... without a gap."""
        n = 0
        while self.has(uav_topic(n + 1, ODOM)):
            n += 1
        return n

    @property
    def followers(self) -> list[int]:
        """Indices i >= 2 of the UAVs with a /uav{i}/formation_error topic."""
        return [i for i in range(2, self.n_uavs + 1) if self.has(uav_topic(i, FORMATION_ERROR))]

    @property
    def scenario_name(self) -> str | None:
        """The scenario name summary.json gives, if any."""
        name = self.summary.get('sim', {}).get('scenario')
        return str(name) if name else None

    @property
    def label(self) -> str:
        """A short name for legends: the scenario name, else the bag directory's name."""
        return self.scenario_name or self.path.name

    # -- UAVs ------------------------------------------------------------------------------
    @property
    def t(self) -> np.ndarray:
        """(T,) stamps [s] of /uav1/odom; the time base of `uav_positions` and `uav_euler`."""
        return self.topic(uav_topic(1, ODOM)).t

    def _uav_field(self, name: str) -> np.ndarray:
        base = self.t
        out = []
        for i in range(1, self.n_uavs + 1):
            s = self.topic(uav_topic(i, ODOM))
            values = s[name]
            if len(s.t) != len(base) or not np.array_equal(s.t, base):
                values = np.stack([np.interp(base, s.t, values[:, k])
                                   for k in range(values.shape[1])], axis=1)
            out.append(values)
        return np.stack(out)

    def uav_positions(self) -> np.ndarray:
        """(n, T, 3) UAV positions, world [m], on the time base `t`."""
        return self._uav_field('position')

    def uav_orientations(self) -> np.ndarray:
        """(n, T, 4) the UAVs' odometry quaternions (x, y, z, w), body FLU -> world."""
        return self._uav_field('orientation')

    def uav_euler(self) -> np.ndarray:
        """(n, T, 3) ZYX Euler angles (roll, pitch, yaw) [rad] from the odometry quaternions."""
        return euler_from_quaternion(self._uav_field('orientation'))

    def uav_body_velocities(self) -> np.ndarray:
        """(n, T, 3) UAV linear velocities in each UAV's body frame (FLU) [m/s]."""
        return self._uav_field('linear')

    # -- payload ---------------------------------------------------------------------------
    @property
    def payload_time(self) -> np.ndarray:
        """(T,) stamps [s] of /payload/odom."""
        return self.topic(PAYLOAD_ODOM).t

    def payload_position(self) -> np.ndarray:
        """(T, 3) payload position, world [m]."""
        return self.topic(PAYLOAD_ODOM)['position']

    def payload_velocity(self) -> np.ndarray:
        """(T, 3) payload velocity [m/s] in the child frame `payload` (a point payload's has the
        axes of `world`; a rigid body's turns with it, docs/rigid_payload.md)."""
        return self.topic(PAYLOAD_ODOM)['linear']

    def payload_euler(self) -> np.ndarray:
        """(T, 3) the payload's ZYX Euler angles (roll, pitch, yaw) [rad] from /payload/odom's
        orientation: zero for a point payload, a rigid body's attitude otherwise."""
        return euler_from_quaternion(self.topic(PAYLOAD_ODOM)['orientation'])

    # -- cables ----------------------------------------------------------------------------
    @property
    def formation_time(self) -> np.ndarray:
        """(T,) stamps [s] of /formation/state."""
        return self.topic(FORMATION_STATE).t

    def tensions(self) -> np.ndarray:
        """(T, n) cable tensions [N]; positive = taut, negative = compression of the rod."""
        return self.topic(FORMATION_STATE)['tension']

    def taut(self) -> np.ndarray:
        """(T, n) bool: which cables are taut (always all with cable_model: rigid)."""
        return self.topic(FORMATION_STATE)['taut'].astype(bool)

    def cable_lengths(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """((T,) times [s], (T,) lengths [m]) of UAV i's (from 1) cable, reeled by its winch
        (/uav{i}/cable_length, a run with winches; its log times, simulated)."""
        series = self.topic(uav_topic(i, CABLE_LENGTH))
        return series.t, series['data']

    def g(self) -> np.ndarray:
        """(T, n) cable constraints g_i = |r_p - r_i|^2 - l_i^2 [m^2]."""
        return self.topic(FORMATION_STATE)['g']

    def g_dot(self) -> np.ndarray:
        """(T, n) their rates g_i_dot [m^2/s]."""
        return self.topic(FORMATION_STATE)['g_dot']

    # -- rotors and set-points (per UAV i = 1..n) ------------------------------------------
    def rotor_time(self, i: int) -> np.ndarray:
        """(T,) stamps [s] of /uav{i}/rotor_cmd (the state time each command answers)."""
        return self.topic(uav_topic(i, ROTOR_CMD)).t

    def rotor_speeds(self, i: int) -> np.ndarray:
        """(T, n_r) commanded rotor speeds of UAV i after saturation [rad/s]."""
        return self.topic(uav_topic(i, ROTOR_CMD))['omega'].astype(float)

    def saturated(self, i: int) -> np.ndarray:
        """(T, n_r) bool: where UAV i's request was clipped to [omega_min, omega_max]."""
        return self.topic(uav_topic(i, ROTOR_CMD))['saturated'].astype(bool)

    def setpoint_time(self, i: int) -> np.ndarray:
        """(T,) stamps [s] of /uav{i}/attitude_setpoint."""
        return self.topic(uav_topic(i, ATTITUDE_SETPOINT)).t

    def attitude_setpoint(self, i: int) -> np.ndarray:
        """(T, 3) roll, pitch, yaw [rad] the outer loop of UAV i asks for."""
        return self.topic(uav_topic(i, ATTITUDE_SETPOINT))['euler']

    def thrust(self, i: int) -> np.ndarray:
        """(T,) collective thrust [N] the outer loop of UAV i asks for (body z)."""
        return self.topic(uav_topic(i, ATTITUDE_SETPOINT))['thrust']

    def thrusts(self) -> np.ndarray:
        """(n, T) thrust set-points [N] of every UAV, on UAV 1's set-point stamps."""
        base = self.setpoint_time(1)
        return np.stack([np.interp(base, self.setpoint_time(i), self.thrust(i))
                         for i in range(1, self.n_uavs + 1)])

    # -- formation control -----------------------------------------------------------------
    def formation_error_time(self, i: int) -> np.ndarray:
        """(T,) stamps [s] of /uav{i}/formation_error."""
        return self.topic(uav_topic(i, FORMATION_ERROR)).t

    def formation_errors(self, i: int) -> np.ndarray:
        """(T, m_i) follower i's virtual-constraint rows g_vc [m; m^2 for distance rows]."""
        return self.topic(uav_topic(i, FORMATION_ERROR))['error'].astype(float)

    def formation_error_rates(self, i: int) -> np.ndarray:
        """(T, m_i) their rates [m/s; m^2/s for distance rows]."""
        return self.topic(uav_topic(i, FORMATION_ERROR))['error_rate'].astype(float)

    # -- environment and reference ---------------------------------------------------------
    @property
    def gust_time(self) -> np.ndarray:
        """(T,) stamps [s] of /payload/gust."""
        return self.topic(PAYLOAD_GUST).t

    def gust_velocity(self) -> np.ndarray:
        """(T, 3) gust velocity at the payload, world [m/s]."""
        return self.topic(PAYLOAD_GUST)['vector']

    def gust_speed(self) -> np.ndarray:
        """(T,) gust speed at the payload [m/s]."""
        return np.linalg.norm(self.gust_velocity(), axis=1)

    @property
    def reference_time(self) -> np.ndarray:
        """(T,) stamps [s] of /uav1/reference."""
        return self.topic(REFERENCE_TOPIC).t

    def reference_position(self) -> np.ndarray:
        """(T, 3) the leader's mission reference position, world [m]."""
        return self.topic(REFERENCE_TOPIC)['position']

    def reference_velocity(self) -> np.ndarray:
        """(T, 3) the leader's mission reference velocity, world [m/s]."""
        return self.topic(REFERENCE_TOPIC)['velocity']

    @property
    def duration(self) -> float:
        """Last minus first stamp of /uav1/odom [s]."""
        t = self.t
        return float(t[-1] - t[0]) if len(t) else 0.0


def _bag_directory(bag_dir: str | Path) -> Path:
    path = Path(bag_dir)
    if not path.exists():
        raise FileNotFoundError(f'bag not found: {path}')
    if path.is_file() and path.suffix == '.mcap' and (path.parent / 'metadata.yaml').is_file():
        path = path.parent
    if not path.is_dir():
        raise RunDataError(f'{path} is not a bag directory (a directory with metadata.yaml)')
    if not (path / 'metadata.yaml').is_file():
        hint = (' (an unclosed bag: multilift_sim.bag.recover copies what is readable)'
                if any(path.glob('*.mcap')) else '')
        raise RunDataError(f'{path} has no metadata.yaml: not a rosbag2 bag directory{hint}')
    return path


def _summary(path: Path) -> dict[str, Any]:
    file = path / 'summary.json'
    if not file.is_file():
        return {}
    try:
        data = json.loads(file.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def load_run(bag_dir: str | Path) -> Run:
    """Read every multilift topic of the bag directory `bag_dir` in one pass.

    Raises FileNotFoundError if `bag_dir` does not exist and RunDataError (a ValueError) if it
    is not a readable rosbag2 bag or has no /uav1/odom; both messages name the path.
    """
    from rosbags.highlevel import AnyReader, AnyReaderError  # import cost only when used

    path = _bag_directory(bag_dir)
    stamps: dict[str, list[float]] = {}
    rows: dict[str, list[dict[str, Any]]] = {}
    try:
        with AnyReader([path]) as reader:
            connections = [c for c in reader.connections if wanted_type(c.topic) == c.msgtype]
            # (an empty list would mean every connection to rosbags)
            messages = reader.messages(connections=connections) if connections else ()
            for connection, log_ns, raw in messages:
                msg = reader.deserialize(raw, connection.msgtype)
                header = getattr(msg, 'header', None)  # none: its log time (simulated time in
                stamps.setdefault(connection.topic, []).append(  # our bags, recording.LogTime)
                    log_ns * 1e-9 if header is None else
                    header.stamp.sec + 1e-9 * header.stamp.nanosec)
                rows.setdefault(connection.topic, []).append(EXTRACT[connection.msgtype](msg))
    except AnyReaderError as exc:
        raise RunDataError(f'cannot read bag {path}: {exc}') from None
    except Exception as exc:  # noqa: BLE001 - a corrupt file raises many kinds of error
        raise RunDataError(f'cannot read bag {path}: {type(exc).__name__}: {exc}') from None
    series = {topic: _series(topic, stamps[topic], rows[topic]) for topic in stamps}
    run = Run(path, series, _summary(path))
    if not run.has(uav_topic(1, ODOM)):
        raise RunDataError(f'bag {path} has no /uav1/odom messages: not a multilift run')
    return run


# -- what the bag does not carry ---------------------------------------------------------
def run_scenario(run: Run, name_or_path: str | None = None) -> tuple[Scenario | None, str]:
    """The scenario (multilift_sim.scenario.Scenario) of `run`, and a note for the user.

    `name_or_path` if given, else the scenario name in the bag's summary.json. Returns
    (None, why) when there is none or it does not fit the bag (another number of UAVs).
    """
    from multilift_sim import scenario as scenario_io

    name = name_or_path or run.scenario_name
    if not name:
        return None, f'{run.path}: no summary.json with a scenario name (give --scenario)'
    try:
        scenario = scenario_io.load(name)
    except (scenario_io.ScenarioError, OSError) as exc:
        return None, f'scenario {name!r} not loaded: {exc}'
    if scenario.n_uavs != run.n_uavs:
        return None, (f'scenario {name!r} has {scenario.n_uavs} UAV(s), the bag '
                      f'{run.n_uavs}: not used')
    return scenario, f'vehicle parameters from scenario {scenario.source}'


def rotor_limits(run: Run, scenario: Scenario | None, i: int) -> tuple[float, float] | None:
    """(omega_min, omega_max) [rad/s] of UAV i: the scenario's, else inferred from the bag's
    saturation flags (the fastest flagged rotor sits at omega_max; omega_min is 0 unless rotors
    were flagged low), else None (no scenario and never clipped high)."""
    if scenario is not None:
        vehicle = scenario.uavs[i - 1].vehicle
        return float(vehicle.rotor_speed_min), float(vehicle.rotor_speed_max)
    omega, sat = run.rotor_speeds(i), run.saturated(i)
    if not sat.any():
        return None
    middle = float(np.median(omega))
    high = omega[sat & (omega >= middle)]
    low = omega[sat & (omega < middle)]
    if not high.size:
        return None
    return (float(low.min()) if low.size else 0.0), float(high.max())
