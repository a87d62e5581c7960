"""The formation seen in space: `fig_trajectories_3d` (paths, the cables and the payload at the
start and the end) and `fig_top_view` (x-y paths, five snapshots, the gust regions), with the
world's obstacles (`obstacles`). Cables end
at their attach points, a released cable is drawn only while it holds the payload, and a rigid
payload is drawn as its body (`scene`). World frame, z up [m].
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from multilift_sim.topics import REFERENCE_TOPIC
from multilift_tools.plot_style import (PAYLOAD_COLOR, WORLD, Context, equal_3d, legend, plt,
                                        uav_color, uav_label)
from multilift_tools.plots.obstacles import (draw_obstacles_3d, draw_obstacles_top,
                                             obstacle_points)
from multilift_tools.plots.scene import Scene, formation_scene

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from multilift_sim.scenario import Scenario

CABLE_GREY = '0.45'
SNAPSHOTS = 5
LABEL_PAD = 22  # [pt] from a 3-D axis label to its tick labels (14 still touched on beam_lift)


def _released_note(scene: Scene) -> str:
    return ', '.join(f'cable {i} released at {t:.0f} s' for i, t in sorted(scene.released.items()))


def fig_trajectories_3d(ctx: Context) -> Figure:
    """3-D paths of the UAVs and the payload, with the cables (and a rigid payload's body) at
    the start and the end."""
    run = ctx.run
    scene = formation_scene(run, ctx.scenario)
    r, rp = scene.uavs, scene.payload
    fig = plt.figure(figsize=(10, 6.5))
    ax = fig.add_axes((-0.02, 0.0, 0.8, 0.94), projection='3d')
    for i in range(1, run.n_uavs + 1):
        ax.plot(*r[i - 1].T, color=uav_color(i), label=uav_label(i), lw=1.4)
    ax.plot(*rp.T, color=PAYLOAD_COLOR, lw=1.4, label='payload (centre)')
    for k, (style, what) in enumerate(((':', 'start'), ('--', 'end'))):
        idx = 0 if k == 0 else len(scene.t) - 1
        first = True
        for i in range(1, run.n_uavs + 1):
            cable = scene.cable(i, idx)
            if cable is None:
                continue
            ax.plot(*cable.T, color=CABLE_GREY, ls=style, lw=1.0,
                    label=f'cables at {what} (t = {scene.t[idx]:.0f} s)' if first else None)
            first = False
        for j, line in enumerate(scene.outline(idx)):
            ax.plot(*line.T, color=PAYLOAD_COLOR, lw=1.3,
                    label=f'payload {scene.shape}' if k == 0 and j == 0 else None)
        ax.scatter(*r[:, idx].T, color=[uav_color(i) for i in range(1, run.n_uavs + 1)],
                   marker='o' if k == 0 else 's', s=30, depthshade=False)
        ax.scatter(*rp[idx], color=PAYLOAD_COLOR, marker='o' if k == 0 else 's', s=30,
                   depthshade=False)
    if scene.released:
        ax.plot([], [], color='none', label=_released_note(scene))
    bodies = [scene.corners(0), scene.corners(len(scene.t) - 1)]
    draw_obstacles_3d(ax, ctx.scenario)
    equal_3d(ax, np.concatenate([r.reshape(-1, 3), rp, *bodies, obstacle_points(ctx.scenario)]))
    ax.set_xlabel('x [m]', labelpad=LABEL_PAD)
    ax.set_ylabel('y [m]', labelpad=LABEL_PAD)
    ax.set_zlabel('z [m]', labelpad=LABEL_PAD)
    ax.plot([], [], 'o', color='0.3', label='start')
    ax.plot([], [], 's', color='0.3', label='end')
    fig.suptitle(f'{run.label}: trajectories ({WORLD})')
    fig.legend(loc='center right', fontsize='small')
    return fig


def _gust_regions(ax: Axes, scenario: Scenario | None) -> None:
    if scenario is None:
        return
    for k, gust in enumerate(scenario.gusts, start=1):
        cx, cy = gust.center
        ax.add_patch(plt.Circle((cx, cy), gust.gradient_distance, color='tab:cyan',
                                alpha=0.25, lw=0,
                                label='gust regions (radius H)' if k == 1 else None))
        dx, dy = gust.direction[0], gust.direction[1]
        ax.annotate('', xy=(cx + dx * gust.gradient_distance, cy + dy * gust.gradient_distance),
                    xytext=(cx, cy), arrowprops={'arrowstyle': '->', 'color': 'tab:blue'})
        ax.text(cx, cy, f' gust {k}\n {gust.reference_speed:g} m/s', fontsize='x-small',
                color='tab:blue', va='top')


def _snapshot_times(ax: Axes, t: np.ndarray, payload: np.ndarray, idxs: np.ndarray,
                    near: float = 0.6) -> None:
    """'t = ... s' next to the payload at the snapshot samples; snapshots whose payloads lie
    within `near` [m] of each other share one label."""
    groups: list[list[int]] = []
    for idx in idxs:
        for group in groups:
            if np.linalg.norm(payload[group[0], :2] - payload[idx, :2]) < near:
                group.append(idx)
                break
        else:
            groups.append([idx])
    for group in groups:
        text = ', '.join(f'{t[k]:.0f}' for k in group)
        ax.annotate(f't = {text} s', payload[group[0], :2], textcoords='offset points',
                    xytext=(4, -10), fontsize='x-small', color='0.3')


def fig_top_view(ctx: Context) -> Figure:
    """x-y paths seen from above, formation snapshots (UAVs, the cables that hold the payload,
    a rigid payload's outline) and gust regions."""
    run = ctx.run
    scene = formation_scene(run, ctx.scenario)
    r, rp = scene.uavs, scene.payload
    fig, ax = plt.subplots(figsize=(8, 7), layout='constrained')
    _gust_regions(ax, ctx.scenario)
    draw_obstacles_top(ax, ctx.scenario)
    if run.has(REFERENCE_TOPIC):
        ax.plot(*run.reference_position()[:, :2].T, color='0.5', ls='--', lw=1.0,
                label='leader reference')
    for i in range(1, run.n_uavs + 1):
        ax.plot(*r[i - 1, :, :2].T, color=uav_color(i), lw=1.4, label=uav_label(i))
    ax.plot(*rp[:, :2].T, color=PAYLOAD_COLOR, lw=1.4, label='payload (centre)')
    snapshots = np.linspace(0, len(scene.t) - 1, SNAPSHOTS).astype(int)
    labelled = set()
    for idx in snapshots:
        holding = [i for i in range(1, run.n_uavs + 1) if scene.cable_attached(i, idx)]
        for i in holding:
            ax.plot(*scene.cable(i, idx)[:, :2].T, color='0.55', lw=0.8,
                    label=None if 'cable' in labelled else 'cables (projected), snapshots')
            labelled.add('cable')
        if len(holding) > 1:
            ring = r[[i - 1 for i in holding + holding[:1]], idx, :2]
            ax.plot(*ring.T, color='0.55', lw=0.8, ls=':')
        for line in scene.outline(idx):
            ax.plot(*line[:, :2].T, color=PAYLOAD_COLOR, lw=1.0,
                    label=None if 'body' in labelled else f'payload {scene.shape} (outline)')
            labelled.add('body')
        ax.scatter(*r[:, idx, :2].T, color=[uav_color(i) for i in range(1, run.n_uavs + 1)],
                   s=18, zorder=3)
        ax.scatter(*rp[idx, :2], color=PAYLOAD_COLOR, marker='s', s=14, zorder=3)
    if scene.released:
        ax.plot([], [], color='none', label=_released_note(scene))
    _snapshot_times(ax, scene.t, rp, snapshots)
    ax.set_aspect('equal', adjustable='datalim')
    ax.set_xlabel('x [m]')
    ax.set_ylabel('y [m]')
    ax.set_title(f'{run.label}: top view ({WORLD}, seen from above)')
    ax.grid(True, alpha=0.35)
    legend(ax, loc='best')
    return fig
