"""Starts, watches and stops the processes of one run (what `ros2 launch` would do).

Children run in their own sessions, so a Ctrl-C reaches only this supervisor, which stops
them in order: simulator and controllers first, the recorder last so it drains and closes the
bag. Every child also gets SIGTERM if the supervisor itself dies (PR_SET_PDEATHSIG), so no
process outlives a run.
"""
from __future__ import annotations

import ctypes
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    try:
        ctypes.CDLL('libc.so.6', use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGTERM)
    except OSError:
        pass


def find_executable(package: str, executable: str) -> Path:
    """`<prefix>/lib/<package>/<executable>` on AMENT_PREFIX_PATH, as `ros2 run` finds it."""
    prefixes = [p for p in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if p]
    for prefix in prefixes:
        candidate = Path(prefix) / 'lib' / package / executable
        if candidate.is_file() and os.access(candidate, os.X_OK):
            return candidate
    for prefix in prefixes:
        folder = Path(prefix) / 'lib' / package
        if folder.is_dir():
            known = sorted(p.name for p in folder.iterdir() if os.access(p, os.X_OK))
            raise FileNotFoundError(f'package {package} has no executable {executable} '
                                    f'(it has: {", ".join(known) or "none"})')
    raise FileNotFoundError(f'package {package} not found on AMENT_PREFIX_PATH '
                            '(run scripts/setup)')


@dataclass
class Child:
    name: str             # e.g. 'sim_node', 'leader_node', 'follower_node (uav2)'
    argv: list[str]
    log_path: Path
    role: str             # 'sim', 'controller' or 'recorder'
    process: subprocess.Popen | None = field(default=None, repr=False)

    def start(self) -> None:
        log = open(self.log_path, 'wb')
        # PYTHONFAULTHANDLER: a child that dies of a fatal signal (SIGSEGV, SIGABRT in the DDS
        # library) leaves its Python stacks in its log instead of nothing
        self.process = subprocess.Popen(self.argv, stdout=log, stderr=subprocess.STDOUT,
                                        stdin=subprocess.DEVNULL, start_new_session=True,
                                        preexec_fn=_die_with_parent,
                                        env=dict(os.environ, PYTHONFAULTHANDLER='1'))
        log.close()

    def returncode(self) -> int | None:
        return None if self.process is None else self.process.poll()

    def exit_text(self) -> str:
        """'exit code 1', 'killed by SIGSEGV' or 'still running'."""
        code = self.returncode()
        if code is None:
            return 'still running'
        if code < 0:
            try:
                return f'killed by {signal.Signals(-code).name}'
            except ValueError:
                return f'killed by signal {-code}'
        return f'exit code {code}'

    def signal(self, sig: int) -> None:
        """Send `sig` to the child's process group, and SIGCONT after it: a stopped child
        (SIGSTOP, Ctrl-Z: a frozen controller) handles SIGINT and SIGTERM only once it runs
        again, and would otherwise sit out both deadlines of `Supervisor.stop` (13 s)."""
        if self.process is not None and self.process.poll() is None:
            try:
                os.killpg(self.process.pid, sig)
                if sig != signal.SIGKILL:
                    os.killpg(self.process.pid, signal.SIGCONT)
            except ProcessLookupError:
                pass

    def _log_lines(self) -> list[str]:
        try:
            return self.log_path.read_text(errors='replace').splitlines()
        except OSError:
            return []

    def teardown_cut_short(self) -> bool:
        """Whether the node's teardown watchdog ended it holding the GIL (faulthandler's
        `Timeout (...)!` and exit code 1; multilift_sim.ros.common.TeardownGuard). The watchdog
        is armed only after the node's loop ended and its publishers were flushed, so unless
        the node also reported an error, it had done its work."""
        lines = self._log_lines()
        return (self.returncode() == 1 and any(line.startswith('Timeout (') for line in lines)
                and not any(line.startswith('error:') for line in lines))

    def ended_well(self) -> bool:
        """Exit code 0, or a teardown cut short after the work was done."""
        return self.returncode() == 0 or self.teardown_cut_short()

    def warnings(self) -> list[str]:
        """The child's own `warning:` lines (a node whose teardown had to be cut short says so:
        multilift_sim.ros.common.TeardownGuard), and one for a teardown cut short holding the
        GIL (its stacks are in the log)."""
        lines = [line for line in self._log_lines() if line.startswith('warning:')]
        if self.teardown_cut_short():
            lines.append('warning: its teardown hung holding the GIL and was cut short by its '
                         'watchdog after its messages were flushed (stacks in its log)')
        return lines

    def last_error(self, lines: int = 6) -> str:
        """The tail of the child's log: its own words on why it stopped."""
        text = self._log_lines()
        while text and not text[-1].strip():
            text.pop()
        errors = [line for line in text if line.startswith('error:')]
        return errors[-1] if errors else '\n'.join(text[-lines:])


class Interrupted(Exception):
    pass


class Supervisor:
    """Runs children until the simulator ends, one dies, or the user interrupts."""

    def __init__(self, children: list[Child]):
        self.children = children
        self._interrupted = False

    def _on_signal(self, signum, frame) -> None:
        self._interrupted = True

    def stop(self, *roles: str, timeout: float = 10.0) -> None:
        """SIGINT every child of these roles at once, then SIGTERM, then SIGKILL as needed."""
        group = [c for c in self.children if c.role in roles]
        for sig, wait in ((signal.SIGINT, timeout), (signal.SIGTERM, 3.0),
                          (signal.SIGKILL, 3.0)):
            alive = [c for c in group if c.returncode() is None]
            if not alive:
                return
            for child in alive:
                child.signal(sig)
            deadline = time.monotonic() + wait
            while time.monotonic() < deadline and any(c.returncode() is None for c in alive):
                time.sleep(0.05)

    def stop_all(self) -> None:
        """Simulator and controllers together (their flushes overlap), the recorder last."""
        self.stop('sim', 'controller')
        self.stop('recorder')

    def run(self, on_tick=None) -> tuple[str, Child | None]:
        """('finished' | 'died' | 'interrupted', the child that died or None)."""
        old_int = signal.signal(signal.SIGINT, self._on_signal)
        old_term = signal.signal(signal.SIGTERM, self._on_signal)
        try:
            for child in self.children:
                child.start()
            while True:
                if self._interrupted:
                    self.stop_all()
                    return 'interrupted', None
                for child in self.children:
                    code = child.returncode()
                    if code is None:
                        continue
                    if child.role == 'sim' and child.ended_well():
                        self.stop('controller')
                        self.stop('recorder')
                        dead = [c for c in self.children
                                if c.role != 'sim' and c.returncode() is not None
                                and not c.ended_well() and c.returncode() != -signal.SIGINT]
                        return ('finished', None) if not dead else ('died', dead[0])
                    self.stop_all()
                    return 'died', child
                if on_tick is not None:
                    on_tick()
                time.sleep(0.1)
        finally:
            signal.signal(signal.SIGINT, old_int)
            signal.signal(signal.SIGTERM, old_term)
            if any(c.returncode() is None for c in self.children):
                self.stop_all()


def python_tty() -> bool:
    return sys.stdout.isatty()
