"""The world's obstacles in the figures (`world:`, issue 34; docs/obstacles.md): their outlines
in the 3-D trajectories and the top view (`draw_obstacles_3d`, `draw_obstacles_top`, each
type's `outline`: a box's 12 edges turned by its yaw, a cylinder's rims and sides, a ball's
three great circles), and `fig_clearance`: the least clearance of each kind against time,
measured at the bag's samples by the tick's own function
(`multilift_sim.statistics.clearance.clearance_series`), the contact line at 0. World frame,
z up [m]."""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from multilift_sim.obstacles import OBSTACLE_TYPES
from multilift_sim.topics import PAYLOAD_ODOM
from multilift_tools.bagdata import Run, RunDataError
from multilift_tools.metrics import interp_rows
from multilift_tools.plot_style import Context, finish_time_plot, plt
from multilift_tools.plots.scene import body_polylines

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from multilift_sim.scenario import Scenario

OBSTACLE_COLOR = 'saddlebrown'
CIRCLE_POINTS = 48
# the kinds as the figure names them (statistics.clearance.KIND_NAMES' order)
KIND_LABELS = ('UAV - world', 'cable - world', 'payload - world', 'UAV - UAV',
               'UAV - another\'s cable', 'cable - cable')


def _circle(radius: float, axes: tuple[int, int], height: float = 0.0,
            normal: int = 2) -> np.ndarray:
    angle = np.linspace(0.0, 2.0 * np.pi, CIRCLE_POINTS + 1)
    ring = np.zeros((len(angle), 3))
    ring[:, axes[0]], ring[:, axes[1]] = radius * np.cos(angle), radius * np.sin(angle)
    ring[:, normal] = height
    return ring


def obstacle_polylines(obstacle) -> list[np.ndarray]:
    """An obstacle's outline, world [m]: polylines (k, 3) at its centre, turned by its yaw."""
    shape, size = OBSTACLE_TYPES[obstacle.type].outline(obstacle.half)
    if shape == 'cube':
        lines = body_polylines('box', tuple(size))
    elif shape == 'cylinder':
        radius, half_height = size[0] / 2.0, size[2] / 2.0
        lines = [_circle(radius, (0, 1), z) for z in (-half_height, half_height)]
        lines += [np.array([[radius * math.cos(a), radius * math.sin(a), -half_height],
                            [radius * math.cos(a), radius * math.sin(a), half_height]])
                  for a in np.linspace(0.0, 2.0 * np.pi, 4, endpoint=False)]
    else:
        radius = size[0] / 2.0
        lines = [_circle(radius, (0, 1), normal=2), _circle(radius, (0, 2), normal=1),
                 _circle(radius, (1, 2), normal=0)]
    c, s = math.cos(obstacle.yaw), math.sin(obstacle.yaw)
    turn = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return [line @ turn.T + np.asarray(obstacle.center) for line in lines]


def obstacle_points(scenario: Scenario | None) -> np.ndarray:
    """Every outline point (k, 3) [m] (for the axes' limits); (0, 3) without obstacles."""
    if scenario is None or scenario.world is None or not scenario.world.obstacles:
        return np.zeros((0, 3))
    return np.concatenate([line for o in scenario.world.obstacles
                           for line in obstacle_polylines(o)])


def draw_obstacles_3d(ax, scenario: Scenario | None) -> None:
    """The obstacles' outlines on a 3-D axes."""
    if scenario is None or scenario.world is None:
        return
    for k, obstacle in enumerate(scenario.world.obstacles):
        for j, line in enumerate(obstacle_polylines(obstacle)):
            ax.plot(*line.T, color=OBSTACLE_COLOR, lw=0.7, alpha=0.7,
                    label='obstacles' if k == 0 and j == 0 else None)


def draw_obstacles_top(ax: Axes, scenario: Scenario | None) -> None:
    """The obstacles seen from above (their outlines projected), filled."""
    if scenario is None or scenario.world is None:
        return
    for k, obstacle in enumerate(scenario.world.obstacles):
        shape, _ = OBSTACLE_TYPES[obstacle.type].outline(obstacle.half)
        lines = obstacle_polylines(obstacle)
        outline = lines[0] if shape != 'cube' else np.concatenate(lines)
        if shape == 'cube':  # the box's footprint: its corners' hull in x-y, in order
            corners = np.unique(outline[:, :2].round(12), axis=0)
            centre = corners.mean(axis=0)
            order = np.argsort(np.arctan2(*(corners - centre).T[::-1]))
            outline = corners[order]
        ax.fill(*outline[:, :2].T, color=OBSTACLE_COLOR, alpha=0.45, lw=0.8,
                label='obstacles (seen from above)' if k == 0 else None)
        ax.annotate(obstacle.name, obstacle.center[:2], fontsize='xx-small', color='0.2',
                    ha='center', va='center')


def lacks_world(run: Run) -> list[str]:
    """Why the bag has no clearance figure: its summary gives none (no `world:` section)."""
    if 'clearance' in run.summary.get('sim', {}):
        return []
    return ['no clearances (the summary gives none: the scenario has no world: section)']


def fig_clearance(ctx: Context) -> Figure:
    """The least clearance of each kind [m] against time, at the bag's samples."""
    from multilift_sim.statistics.clearance import clearance_series
    run, scenario = ctx.run, ctx.scenario
    if scenario is None or scenario.world is None:
        raise RunDataError('the clearances need the scenario and its world: (--scenario)')
    t = run.t
    payload = interp_rows(t, run.payload_time, run.payload_position())
    uav_q = run.uav_orientations()[..., [3, 0, 1, 2]]  # (x, y, z, w) -> (w, x, y, z)
    payload_q = None
    if scenario.payload.type == 'rigid_body':
        q = interp_rows(t, run.payload_time, run.topic(PAYLOAD_ODOM)['orientation'])
        payload_q = (q / np.linalg.norm(q, axis=1, keepdims=True))[:, [3, 0, 1, 2]]
    series = clearance_series(scenario, run.uav_positions(), uav_q, payload, payload_q)
    fig, ax = plt.subplots(figsize=(9, 4.8), layout='constrained')
    for kind, label in enumerate(KIND_LABELS):
        values = series[:, kind]
        if np.isfinite(values).any():
            least = np.nanmin(values)
            ax.plot(t, values, lw=1.1, label=f'{label}: least {least:.3f} m')
    ax.axhline(0.0, color='tab:red', lw=0.9, label='contact (clearance 0)')
    finish_time_plot(ax, 'least clearance [m]',
                     f'{run.label}: clearance of each kind (at the recorded ticks)',
                     loc='upper right')
    return fig
