"""`multilift animate BAG [--out FILE.gif|FILE.mp4] [--fps N] [--speed X]`: the formation in
3-D over time (world frame, z up), cables coloured by tension. Exit codes: 0 done, 2 bad input.
"""
from __future__ import annotations

import argparse
import math
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import animation, cm, colors
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from multilift_sim.topics import FORMATION_STATE
from multilift_tools.bagdata import Run
from multilift_tools.metrics import interp_rows
from multilift_tools.plot_style import (PAYLOAD_COLOR, WORLD, Parser, equal_3d, parse_and_load,
                                        plt, uav_color, uav_label)
from multilift_tools.plots.scene import released_cables


@dataclass(frozen=True)
class AnimationData:
    """The run on the animation's frame times: t (F,) [s], UAVs (n, T, 3), payload (T, 3) [m],
    tensions (T, n) [N] on the odometry time base T, and `frames` (F,) indices into it."""

    t: np.ndarray
    uavs: np.ndarray
    payload: np.ndarray
    tensions: np.ndarray
    frames: np.ndarray
    attached: np.ndarray | None = None  # (n, T) bool: the cable holds the payload (not released)


def animation_data(run: Run, fps: float, speed: float) -> AnimationData:
    """Sample the run every `speed / fps` simulated seconds (`speed` x real time at `fps`)."""
    t = run.t
    uavs = run.uav_positions()
    payload = interp_rows(t, run.payload_time, run.payload_position())
    attached = np.ones((uavs.shape[0], len(t)), dtype=bool)
    for i, release in released_cables(run).items():
        attached[i - 1] = t < release
    tensions = (interp_rows(t, run.formation_time, run.tensions()) if run.has(FORMATION_STATE)
                else np.zeros((len(t), run.n_uavs)))
    times = np.arange(t[0], t[-1] + 1e-9, speed / fps)
    frames = np.unique(np.clip(np.searchsorted(t, times), 0, len(t) - 1))
    return AnimationData(t, uavs, payload, tensions, frames, attached)


def _tension_norm(tensions: np.ndarray) -> colors.Normalize:
    lo, hi = float(tensions.min()), float(tensions.max())
    if hi - lo < 1e-9:
        lo, hi = lo - 0.5, hi + 0.5
    return colors.Normalize(lo, hi)


class FormationAnimator:
    """The formation in 3-D (world frame, z up): UAVs, cables coloured by tension, payload, and
    the paths so far. `render(k)` draws odometry sample k by blitting the moving artists on a
    background drawn once (axes, ticks, colour bar) and returns the RGBA pixels."""

    def __init__(self, data: AnimationData, title: str, dpi: int = 80,
                 figsize: tuple[float, float] = (7.0, 5.6)) -> None:
        self.data = data
        self.fig = plt.figure(figsize=figsize, dpi=dpi)
        self.ax = ax = self.fig.add_axes((0.0, 0.05, 0.82, 0.85), projection='3d')
        n = data.uavs.shape[0]
        equal_3d(ax, np.concatenate([data.uavs.reshape(-1, 3), data.payload]))
        ax.set_xlabel('x [m]')
        ax.set_ylabel('y [m]')
        ax.set_zlabel('z [m]')
        self.fig.suptitle(f'{title} ({WORLD})', fontsize='medium')
        self.norm = _tension_norm(data.tensions)
        self.cmap = plt.get_cmap('plasma')
        self.cables = Line3DCollection(self._segments(0), cmap=self.cmap, norm=self.norm, lw=2.2,
                                       animated=True)
        ax.add_collection(self.cables)
        self.fig.colorbar(cm.ScalarMappable(norm=self.norm, cmap=self.cmap),
                          cax=self.fig.add_axes((0.86, 0.2, 0.025, 0.6)),
                          label='cable tension [N] (< 0: compression)')
        self.uav_paths = [ax.plot([], [], [], color=uav_color(i + 1), lw=0.8, animated=True)[0]
                          for i in range(n)]
        self.uav_dots = [ax.plot([], [], [], 'o', color=uav_color(i + 1), ms=7, animated=True,
                                 label=uav_label(i + 1))[0] for i in range(n)]
        self.payload_path = ax.plot([], [], [], color=PAYLOAD_COLOR, lw=0.8, animated=True)[0]
        self.payload_dot = ax.plot([], [], [], 's', color=PAYLOAD_COLOR, ms=6, animated=True,
                                   label='payload')[0]
        self.clock = ax.text2D(0.02, 0.95, '', transform=ax.transAxes, animated=True)
        ax.legend(loc='upper right', fontsize='x-small')
        dt = float(np.median(np.diff(data.t))) if len(data.t) > 1 else 1.0
        self.stride = max(1, int(round(0.1 / dt)))  # paths drawn at about 10 Hz
        self._background: Any = None

    def _segments(self, k: int) -> np.ndarray:
        d = self.data
        ends = np.repeat(d.payload[k][None], d.uavs.shape[0], 0)
        if d.attached is not None:  # a released cable: no segment (both ends at its UAV)
            ends[~d.attached[:, k]] = d.uavs[~d.attached[:, k], k]
        return np.stack([d.uavs[:, k], ends], axis=1)

    def _path(self, points: np.ndarray, k: int) -> np.ndarray:
        """points[:k + 1] thinned to every `stride`-th sample, ending exactly at sample k."""
        return np.concatenate([points[:k + 1:self.stride], points[k:k + 1]])

    def update(self, k: int) -> list[Any]:
        """Move the artists to odometry sample k; returns them."""
        d = self.data
        self.cables.set_segments(self._segments(k))
        self.cables.set_array(d.tensions[k])
        for i, (path, dot) in enumerate(zip(self.uav_paths, self.uav_dots)):
            path.set_data_3d(*self._path(d.uavs[i], k).T)
            dot.set_data_3d(*d.uavs[i, k:k + 1].T)
        self.payload_path.set_data_3d(*self._path(d.payload, k).T)
        self.payload_dot.set_data_3d(*d.payload[k:k + 1].T)
        self.clock.set_text(f't = {d.t[k]:6.1f} s')
        return [self.cables, *self.uav_paths, self.payload_path, *self.uav_dots,
                self.payload_dot, self.clock]

    def render(self, k: int) -> np.ndarray:
        """(H, W, 4) uint8 RGBA pixels of the figure at odometry sample k."""
        canvas = self.fig.canvas
        if self._background is None:
            canvas.draw()  # everything but the animated artists; sets the 3-D projection
            self._background = canvas.copy_from_bbox(self.fig.bbox)
        canvas.restore_region(self._background)
        for artist in self.update(k):
            if isinstance(artist, Line3DCollection):
                artist.do_3d_projection()
            self.ax.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba())


class _PixelPillowWriter(animation.PillowWriter):
    """matplotlib's PillowWriter fed with ready RGBA frames (`add`) instead of one full
    `savefig` per frame; `finish` writes the GIF as PillowWriter does."""

    def setup(self, fig: Figure, outfile: str | Path, dpi: float | None = None) -> None:
        super().setup(fig, outfile, dpi=dpi)
        self._images: list[Any] = []

    def add(self, rgba: np.ndarray) -> None:
        """Append one (H, W, 4) uint8 frame."""
        from PIL import Image
        self._images.append(Image.fromarray(rgba[..., :3].copy(), 'RGB'))

    def grab_frame(self, **savefig_kwargs: Any) -> None:
        self.add(np.asarray(self.fig.canvas.buffer_rgba()))

    def finish(self) -> None:
        self._images[0].save(self.outfile, save_all=True, append_images=self._images[1:],
                             duration=int(1000 / self.fps), loop=0)


def _check_output(out: Path) -> str:
    kind = out.suffix.lower()
    if kind not in ('.gif', '.mp4'):
        raise ValueError(f'{out}: the output must end in .gif or .mp4')
    if kind == '.mp4' and shutil.which('ffmpeg') is None:
        raise ValueError(f'{out}: writing .mp4 needs an ffmpeg binary on PATH and there is '
                         'none; write a .gif instead')
    return kind


def write_animation(run: Run, out: Path, fps: float, speed: float, dpi: int = 80) -> int:
    """Write the formation animation to `out` (.gif, or .mp4 when ffmpeg is on PATH), showing
    `speed` simulated seconds per second at `fps` frames per second; returns the frame count.
    ValueError (naming `out`) for another suffix or a missing ffmpeg."""
    kind = _check_output(out)
    data = animation_data(run, fps, speed)
    anim = FormationAnimator(data, f'{run.label}, {speed:g}x real time', dpi=dpi)
    writer: animation.AbstractMovieWriter = (
        _PixelPillowWriter(fps=fps) if kind == '.gif'
        else animation.FFMpegWriter(fps=fps, bitrate=1800))
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        with writer.saving(anim.fig, str(out), dpi=dpi):
            for k in data.frames:
                if isinstance(writer, _PixelPillowWriter):
                    writer.add(anim.render(int(k)))
                else:  # ffmpeg: a full draw per frame, the moving artists included
                    for artist in anim.update(int(k)):
                        artist.set_animated(False)
                    writer.grab_frame()
    finally:
        plt.close(anim.fig)
    return len(data.frames)


def _positive(text: str) -> float:
    value = float(text)
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f'{text} must be a finite number > 0')
    return value


def animate_main(argv: list[str]) -> int:
    """`multilift animate BAG [--out FILE] [--fps N] [--speed X]`: the formation in 3-D over
    time. Returns the exit code (0 done, 2 bad input)."""
    parser = Parser(prog='multilift animate', description='animate a recorded run in 3-D')
    parser.add_argument('bag', help='a bag directory written by `multilift run --bag`')
    parser.add_argument('--out', help='FILE.gif or FILE.mp4 (mp4 needs ffmpeg; default: '
                        'BAG/animation.gif)')
    parser.add_argument('--fps', type=_positive, default=10.0, help='frames per second (10)')
    parser.add_argument('--speed', type=_positive, default=5.0,
                        help='simulated seconds per second of animation (5)')
    parser.add_argument('--dpi', type=int, default=80, help='resolution (80: 560 x 448 px)')
    started = time.perf_counter()
    loaded = parse_and_load(parser, argv, 'animation.gif')
    if isinstance(loaded, int):
        return loaded
    args, run, out = loaded
    try:
        frames = write_animation(run, out, args.fps, args.speed, args.dpi)
    except (ValueError, OSError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    print(out)
    print(f'{frames} frames ({frames / args.fps:.1f} s at {args.fps:g} fps), '
          f'{out.stat().st_size / 1e6:.1f} MB, {time.perf_counter() - started:.1f} s',
          file=sys.stderr)
    return 0
