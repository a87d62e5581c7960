"""What `multilift plot` draws in space and for the rotors, checked on the drawn artists' data
(plots/scene.py, views.py, rotors.py): a released cable has no segment after its release and
the tension figure calls it released; a rigid payload is drawn as its body (its corners, from
the bag's attitude) with the cables ending at its attach points; six rotors stay apart and the
clipped strip sits at the limit it hit; the 3-D axis labels clear the tick labels; the skipped
figures say why in words."""
from __future__ import annotations

import matplotlib

matplotlib.use('Agg')

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import yaml  # noqa: E402

from conftest import SCENARIOS  # noqa: E402
from multilift_sim import scenario as scenario_io  # noqa: E402
from multilift_sim.topics import PAYLOAD_ODOM  # noqa: E402
from multilift_tools import figures  # noqa: E402
from multilift_tools.bagdata import load_run  # noqa: E402
from multilift_tools.headless_bag import record_headless  # noqa: E402
from multilift_tools.plot_style import Context, plt  # noqa: E402
from multilift_tools.plots import rotors, views  # noqa: E402
from multilift_tools.plots.scene import formation_scene  # noqa: E402

RELEASE = 1.0  # [s] uav3 lets go


def _scenario(name: str, duration: float, **top) -> scenario_io.Scenario:
    data = yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())
    data['simulation']['duration'] = duration
    data.update(top)
    return scenario_io.loads(yaml.safe_dump(data))


def _recorded(tmp_path_factory, scenario, name: str) -> Context:
    """`scenario` flown headless into a bag of its own, loaded for the figures."""
    bag = tmp_path_factory.mktemp(name) / 'bag'
    record_headless(scenario, bag)
    return Context(load_run(bag), scenario)


@pytest.fixture(scope='module')
def released(tmp_path_factory):
    return _recorded(tmp_path_factory, _scenario(
        'multi_lift', 2.5, events=[{'time': RELEASE, 'type': 'cable_release', 'uav': 3}]),
        'released')


@pytest.fixture(scope='module')
def box(tmp_path_factory):
    return _recorded(tmp_path_factory, scenario_io.load('box_lift').with_duration(2.0), 'box')


def _close(a, b, tol=1e-9) -> bool:
    return np.allclose(a, b, rtol=0.0, atol=tol)


def _lines_3d(fig, color):
    """(2, 3) data of every 3-D line of colour `color` on the figure's first axes."""
    out = []
    for line in fig.axes[0].lines:
        if line.get_color() == color:
            x, y, z = line.get_data_3d()
            out.append(np.stack([x, y, z], axis=1))
    return out


def test_a_released_cable_has_no_segment_after_its_release(released):
    run = released.run
    scene = formation_scene(run, released.scenario)
    assert scene.released == {3: pytest.approx(RELEASE)}
    end = len(scene.t) - 1
    assert scene.cable(3, end) is None and scene.cable(3, 0) is not None
    fig = views.fig_trajectories_3d(released)
    cables = _lines_3d(fig, views.CABLE_GREY)
    # start: three cables; end: two, none of them UAV 3's
    assert len(cables) == 5
    ends = [c for c in cables if any(_close(c[0], scene.uavs[i, end]) for i in range(3))]
    assert len(ends) == 2
    assert not any(_close(c[0], scene.uavs[2, end]) for c in cables)
    plt.close(fig)
    fig = views.fig_top_view(released)
    drawn = [np.stack(line.get_data(), axis=1) for line in fig.axes[0].lines
             if line.get_color() == '0.55' and line.get_linestyle() == '-']
    snapshots = np.linspace(0, end, views.SNAPSHOTS).astype(int)
    after = [k for k in snapshots if scene.t[k] >= RELEASE]
    assert after  # snapshots after the release exist and show no segment from UAV 3
    for k in after:
        assert not any(_close(c[0], scene.uavs[2, k, :2]) for c in drawn)
        assert any(_close(c[0], scene.uavs[1, k, :2]) for c in drawn)
    before = [k for k in snapshots if scene.t[k] < RELEASE]
    assert any(_close(c[0], scene.uavs[2, before[0], :2]) for c in drawn)
    plt.close(fig)


def test_the_tension_figure_calls_a_released_cable_released(released):
    fig = figures.fig_tensions(released)
    labels = [text.get_text() for text in fig.axes[0].get_legend().get_texts()]
    assert 'cable 3 released (1 s on)' in labels
    assert not any(label.startswith('cable 3 slack') for label in labels)
    plt.close(fig)


def _rotation(q):
    """R of the unit quaternion (x, y, z, w), written independently of scene.py."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_a_rigid_box_is_drawn_with_its_corners_and_its_attach_points(box):
    run, scenario = box.run, box.scenario
    odom = run.topic(PAYLOAD_ODOM)
    assert np.array_equal(odom.t, run.t)  # the same stamps: no interpolation below
    q, centre = odom['orientation'][-1], odom['position'][-1]
    rotation = _rotation(q)
    assert not _close(rotation, np.eye(3), 1e-6)  # it has turned
    half = np.array(scenario.payload.size) / 2
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    expected = (corners * half) @ rotation.T + centre
    attach = np.array(scenario.payload.attach_points) @ rotation.T + centre
    fig = views.fig_trajectories_3d(box)
    edges = _lines_3d(fig, views.PAYLOAD_COLOR)
    body = [e for e in edges if len(e) == 2]
    at_end = [e for e in body if any(_close(e[0], c, 1e-6) for c in expected)]
    assert len(at_end) == 12  # its 12 edges, each between two of its corners
    drawn = np.unique(np.round(np.concatenate(at_end), 9), axis=0)
    assert len(drawn) == 8 and all(any(_close(d, c, 1e-6) for c in expected) for d in drawn)
    cables = _lines_3d(fig, views.CABLE_GREY)
    last = [c for c in cables if any(_close(c[0], p, 1e-9) for p in run.uav_positions()[:, -1])]
    assert len(last) == 4
    for i, cable in enumerate(last):
        assert _close(cable[1], attach[i], 1e-6)  # the cable ends at b_i, not the centre
        assert not _close(cable[1], centre, 0.1)
    plt.close(fig)
    fig = views.fig_top_view(box)
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert 'payload box (outline)' in labels
    plt.close(fig)


def test_a_cylinder_is_drawn_along_its_axis():
    scenario = scenario_io.load('beam_lift')
    from multilift_tools.plots.scene import body_corners, body_polylines
    axis, *rims = body_polylines(scenario.payload.shape, scenario.payload.size)
    assert _close(axis, [[-1.5, 0, 0], [1.5, 0, 0]])
    assert len(rims) == 2 and _close(np.hypot(rims[0][:, 1], rims[0][:, 2]), 0.03)
    assert body_corners('box', (1.0, 0.6, 0.4)).shape == (8, 3)


@pytest.mark.parametrize('which', ['box', 'released'])
def test_3d_axis_labels_clear_their_tick_labels(which, request):
    """(matplotlib's default labelpad of 4 pt overlapped a tick label on both)"""
    fig = views.fig_trajectories_3d(request.getfixturevalue(which))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        label = axis.label.get_window_extent(renderer)
        # the tick labels as drawn (get_ticklabels() would place them anew)
        ticks = [tick.label1.get_window_extent(renderer) for tick in axis.majorTicks
                 if tick.label1.get_visible() and tick.label1.get_text()]
        assert len(ticks) >= 3
        assert not any(label.overlaps(t) for t in ticks), axis.label.get_text()
    plt.close(fig)


@pytest.fixture(scope='module')
def hexa(tmp_path_factory):
    return _recorded(tmp_path_factory,
                     scenario_io.load('hexa_rotor_failure').with_duration(31.0), 'hexa')


def test_six_rotors_are_told_apart_and_the_clipped_strip_is_at_the_lower_limit(hexa):
    fig = rotors.fig_rotor_speeds(hexa)
    leader = fig.axes[0]
    lines = [line for line in leader.lines if line.get_label().startswith('rotor ')]
    assert len(lines) == 6
    styles = {(line.get_color(), str(line.get_linestyle()), str(line.get_dashes()
                                                                  if hasattr(line, 'get_dashes')
                                                                  else '')) for line in lines}
    assert len({rotors.rotor_style(k)['ls'] for k in range(6)}) == 6
    assert len({rotors.rotor_style(k)['color'] for k in range(6)}) == 6
    assert len(styles) == 6
    strips = {c.get_label(): c for c in leader.collections if c.get_label().startswith('clipped')}
    # the failed rotor and the one its reallocation pins at omega_min are not saturation
    # (issue 37: the hexa's rotors are never held at a limit they were wanted beyond)
    assert not strips
    texts = [t.get_text() for t in leader.texts]
    assert 'rotors 1, 4' in texts  # the failed rotor 1 and its opposite share the line at 0
    plt.close(fig)


def test_clipped_sides_split_by_the_nearer_limit():
    omega = np.array([[2100.0, 50.0], [0.0, 2100.0], [1000.0, 1000.0]])
    sat = np.array([[True, False], [True, True], [False, False]])
    high, low = rotors.clipped_sides(omega, sat, (0.0, 2100.0))
    assert high.tolist() == [True, True, False] and low.tolist() == [False, True, False]


def test_skipped_figures_say_why_in_words(hexa, released):
    assert figures._lacks_payload_attitude(hexa.run) == [
        'the payload is a point (no attitude; a rigid_body has one)']
    assert figures._lacks_followers(released.run) == []

    class Lone:
        n_uavs, followers = 1, []

    class Silent:
        n_uavs, followers = 3, []
    assert figures._lacks_followers(Lone()) == ['one UAV: no follower']
    message = figures._lacks_followers(Silent())[0]
    assert message.startswith('no messages on /uav2/formation_error .. /uav3/formation_error')
    assert figures._topics('/x')(hexa.run) == ['no messages on /x']
