"""`multilift reproduce [--out DIR] [--jobs N] [--bags DIR]`: the seed's §2.8 and Ch. 4, rerun.

Runs the seed's cases headless (multilift_control.headless: the physics, control laws and bag of
the ROS stack in one process) in parallel worker processes (`cases`); `write` then draws a
counterpart of every figure of the seed's §2.8 (Fig. 2.12) and Ch. 4 (Fig. 4.1-4.17) with the
figure functions of multilift_tools.figures, .compare, .modal_cli and .studies, measures every
number and qualitative claim of those sections, and writes DIR/reproduction.md (default
docs/) with the figures as PNG under DIR/figures/ (relative links). World frame, z up, SI units;
the seed's frame is z down, (x, y, z)_world = (x, -y, -z)_seed (multilift_sim.frames).

Exit codes: 0 done, 1 a case failed (named on stderr), 2 bad input, 130 interrupted.
"""
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

from multilift_sim.scenario import ScenarioError
from multilift_tools.report.cases import CASES, run_cases


class _UsageError(Exception):
    """A bad command line (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    """argparse raising _UsageError instead of exiting."""

    def error(self, message: str) -> None:      # one line, exit code 2 (not argparse's usage)
        raise _UsageError(message)


def _positive_int(text: str) -> int:
    """An int >= 1 for argparse."""
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f'{text} must be >= 1')
    return value


def reproduce_main(argv: list[str] | None = None) -> int:
    """`multilift reproduce [--out DIR] [--jobs N] [--bags DIR]` (argv without 'reproduce').

    Runs CASES in N worker processes (default: the CPU count), writes DIR/figures/*.png and
    DIR/reproduction.md (DIR default docs/), prints where and how long. Exit 0; 1 when a case
    fails (one line naming it); 2 for bad arguments; 130 on Ctrl-C.
    """
    parser = _Parser(prog='multilift reproduce', description="rerun the seed's §2.8 and Ch. 4 "
                     'and write DIR/reproduction.md with its figures')
    parser.add_argument('--out', default='docs', help='output directory (default docs/)')
    parser.add_argument('--jobs', type=_positive_int, default=os.cpu_count() or 1,
                        help='worker processes (default: the CPU count)')
    parser.add_argument('--bags', help='keep the bags and the study here (default: a temporary '
                        'directory, removed)')
    try:
        args = parser.parse_args(argv)
    except _UsageError as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 2
    started = time.monotonic()
    out = Path(args.out)
    figures = out / 'figures'
    figures.mkdir(parents=True, exist_ok=True)
    for old in [*figures.glob('fig2_*.png'), *figures.glob('fig4_*.png')]:
        old.unlink()
    work = Path(args.bags) if args.bags else Path(tempfile.mkdtemp(prefix='multilift-repro-'))
    work.mkdir(parents=True, exist_ok=True)
    jobs = min(args.jobs, len(CASES))
    print(f'multilift reproduce: {len(CASES)} cases in {jobs} processes; work in {work}',
          flush=True)
    try:
        results = run_cases(CASES, work, figures, jobs)
        print('  figures and report ...', flush=True)
        from multilift_tools.report.write import write_reproduction
        report = write_reproduction(out, results, work, jobs, started)
    except KeyboardInterrupt:
        print('interrupted', file=sys.stderr)
        return 130
    except (RuntimeError, ScenarioError) as exc:
        print(f'error: {exc}', file=sys.stderr)
        return 1
    finally:
        if not args.bags:
            shutil.rmtree(work, ignore_errors=True)
    pngs = sorted(figures.glob('fig*.png'))
    size = sum(p.stat().st_size for p in pngs) / 1e6
    print(f'wrote {report} and {len(pngs)} figures in {figures} ({size:.1f} MB) in '
          f'{time.monotonic() - started:.0f} s')
    return 0


if __name__ == '__main__':
    sys.exit(reproduce_main(sys.argv[1:]))
