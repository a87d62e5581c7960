"""A Foxglove layout for any scenario (`multilift foxglove --layout FILE SCENARIO`).

The layout has the 3D panel (the markers of /visualization/markers and the tf frames of /tf,
following `world`) beside plots, every series against its message's header stamp: every
cable's tension, every UAV's rotor speeds (as many as its frame type has), the leader's position
against its mission reference, every UAV's attitude set-point, and every follower's formation
(virtual-constraint) errors, where UAVs carry winches each one's cable length, in a
reorganising formation (issue 35) each UAV's thrust margin, and with an
estimator each UAV's estimated position beside its true one (and the payload's with a
`payload_estimator:`). A scenario
with `events:` has, under the 3D panel, the messages
of /formation/events as they happen (docs/events.md).
"""
from __future__ import annotations

import json
from pathlib import Path

from multilift_sim.topics import EVENTS, PAYLOAD_ESTIMATE, PAYLOAD_ODOM, margin_topics

COLORS = ['#4e98e2', '#f5774d', '#61cbff', '#b87fd6', '#71c26a', '#f7df71', '#e96d9f',
          '#9b9b9b']


def _series(value: str, label: str, k: int, stamp: str = 'headerStamp') -> dict:
    """A plot's series; `stamp` 'receiveTime' for a message without a header (the bridge's
    time follows /clock: simulated)."""
    return {'value': value, 'enabled': True, 'timestampMethod': stamp,
            'label': label, 'color': COLORS[k % len(COLORS)]}


def _plot(title: str, series: list[dict]) -> dict:
    return {'paths': series, 'minYValue': '', 'maxYValue': '', 'showXAxisLabels': True,
            'showYAxisLabels': True, 'showLegend': True, 'legendDisplay': 'floating',
            'showPlotValuesInLegend': True, 'isSynced': True, 'xAxisVal': 'timestamp',
            'sidebarDimension': 240, 'foxglovePanelTitle': title}


def _three_d(frames: list[str]) -> dict:
    return {
        'cameraState': {'perspective': True, 'distance': 45, 'phi': 60, 'thetaOffset': 45,
                        'targetOffset': [0, 0, 0], 'target': [0, 0, 0],
                        'targetOrientation': [0, 0, 0, 1], 'fovy': 45, 'near': 0.5,
                        'far': 5000},
        'followMode': 'follow-none', 'followTf': 'world',
        'scene': {'enableStats': False, 'transforms': {'showLabel': True, 'axisScale': 0.5}},
        'transforms': {f'frame:{f}': {'visible': True} for f in frames},
        'topics': {'/visualization/markers': {'visible': True}, '/tf': {'visible': True}},
        'layers': {'grid': {'visible': True, 'frameLocked': True, 'label': 'Grid (1 m)',
                            'instanceId': 'grid', 'layerId': 'foxglove.Grid',
                            'frameId': 'world', 'size': 60, 'divisions': 60, 'lineWidth': 1,
                            'color': '#248eff40', 'position': [0, 0, 0],
                            'rotation': [0, 0, 0], 'order': 1}},
        'publish': {'type': 'point'}, 'imageMode': {},
        'foxglovePanelTitle': 'Formation (world, markers and tf frames)'}


def _stack(panels: list[str], direction: str = 'column'):
    """A binary split tree showing `panels` in equal parts."""
    if len(panels) == 1:
        return panels[0]
    half = len(panels) // 2
    return {'direction': direction, 'splitPercentage': round(100 * half / len(panels)),
            'first': _stack(panels[:half], direction),
            'second': _stack(panels[half:], direction)}


def formation_rows(scenario) -> list[int]:
    """How many virtual-constraint errors each follower (uav2..) publishes."""
    from multilift_control.formation import FormationFollower
    return [len(FormationFollower.from_scenario(scenario, i).constraints.rows_of(i))
            for i in range(1, scenario.n_uavs)]


def layout(scenario) -> dict:
    """The layout of `scenario` (a scenario.Scenario) as the Foxglove app reads it."""
    n = scenario.n_uavs
    plots: dict[str, dict] = {}
    plots['Plot!tensions'] = _plot('Cable tension [N] (/formation/state)', [
        _series(f'/formation/state.cable_tension[{k}]', f'cable {k + 1}', k) for k in range(n)])
    for i, uav in enumerate(scenario.uavs, start=1):
        role = ' (leader)' if i == 1 else ''
        plots[f'Plot!rotors{i}'] = _plot(
            f'Rotor speeds [rad/s], uav{i}{role} ({uav.vehicle.frame_type})', [
                _series(f'/uav{i}/rotor_cmd.angular_velocity[{k}]', f'rotor {k + 1}', k)
                for k in range(uav.vehicle.n_rotors)])
    tracking = []
    for k, axis in enumerate('xyz'):
        tracking.append(_series(f'/uav1/reference.position.{axis}', f'reference {axis}', k))
        tracking.append(_series(f'/uav1/odom.pose.pose.position.{axis}', f'uav1 {axis}', k + 3))
    plots['Plot!tracking'] = _plot('Leader position and reference [m]', tracking)
    plots['Plot!setpoints'] = _plot('Attitude set-points [rad]', [
        _series(f'/uav{i}/attitude_setpoint.{angle}', f'uav{i} {angle}', 3 * (i - 1) + a)
        for i in range(1, n + 1) for a, angle in enumerate(('roll', 'pitch'))])
    if n > 1:
        plots['Plot!formation'] = _plot('Formation errors g_vc [m]', [
            _series(f'/uav{i}/formation_error.error[{k}]', f'uav{i} row {k + 1}', j)
            for j, (i, k) in enumerate((i, k) for i, rows in
                                       zip(range(2, n + 1), formation_rows(scenario))
                                       for k in range(rows))])
    if scenario.winches:  # each winch's cable length (std_msgs/Float64, no header)
        plots['Plot!winches'] = _plot('Cable length [m] (/uav{i}/cable_length)', [
            _series(f'/uav{i}/cable_length.data', f'cable {i}', i - 1, 'receiveTime')
            for i in scenario.winches])
    if margin_topics(scenario):  # a reorganising formation: each UAV's thrust margin
        plots['Plot!margins'] = _plot('Thrust margin 1 - u_T / u_T,max (/uav{i}/thrust_margin)', [
            _series(f'/uav{i}/thrust_margin.data', f'uav{i}', i - 1, 'receiveTime')
            for i in range(1, n + 1)])
    if scenario.estimator is not None:  # each UAV's estimated position beside the truth
        for i in range(1, n + 1):
            plots[f'Plot!estimate{i}'] = _plot(
                f'uav{i} position [m]: estimate (/uav{i}/estimate) and truth (/uav{i}/odom)', [
                    _series(f'/uav{i}/{topic}.pose.pose.position.{axis}', f'{label} {axis}',
                            k + 3 * j)
                    for j, (topic, label) in enumerate((('estimate', 'estimate'),
                                                        ('odom', 'truth')))
                    for k, axis in enumerate('xyz')])
    if scenario.payload_estimator is not None:  # the payload's estimate beside the truth
        plots['Plot!payload_estimate'] = _plot(
            'payload position [m]: estimate (/payload/estimate) and truth (/payload/odom)', [
                _series(f'{topic}.pose.pose.position.{axis}', f'{label} {axis}', k + 3 * j)
                for j, (topic, label) in enumerate(((PAYLOAD_ESTIMATE, 'estimate'),
                                                    (PAYLOAD_ODOM, 'truth')))
                for k, axis in enumerate('xyz')])
    frames = ['world', 'payload'] + [f'uav{i}/base_link' for i in range(1, n + 1)]
    config = {'3D!multilift': _three_d(frames), **plots}
    scene: str | dict = '3D!multilift'
    if scenario.events:
        config['RawMessages!events'] = {
            'topicPath': EVENTS, 'diffEnabled': False, 'diffMethod': 'custom',
            'diffTopicPath': '', 'showFullMessageForDiff': False,
            'foxglovePanelTitle': f'Events ({EVENTS})'}
        scene = {'direction': 'column', 'splitPercentage': 75, 'first': scene,
                 'second': 'RawMessages!events'}
    return {'configById': config, 'globalVariables': {}, 'userNodes': {},
            'playbackConfig': {'speed': 1},
            'layout': {'direction': 'row', 'splitPercentage': 55, 'first': scene,
                       'second': _stack(list(plots))}}


def write_layout(path: str | Path, scenario_name: str) -> Path:
    """Write the layout of a scenario (name or path) to `path`."""
    from multilift_sim import scenario as scenario_io
    path = Path(path)
    path.write_text(json.dumps(layout(scenario_io.load(scenario_name)), indent=1) + '\n')
    return path
