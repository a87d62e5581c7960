"""docs/user_guide.md run as a reader would: every command of its fenced ```sh blocks, in page
order, each exiting 0, and then what the page says they wrote checked in the files.

The commands run in a temporary directory (pytest's tmp_path) on the test's own ROS domain
(multilift_domain), so the page's `runs/...` paths land there; a command's leading `scripts/`
is the repository's (an absolute path: scripts/env.sh finds the repository from its own
path, so a symlinked scripts/ would not do). An HTML comment right before a block tells the
test what the block is:
- `<!-- background -->`: a command that runs until Ctrl-C (`multilift foxglove`): started in the
  background (on a free port, not 8765: other tests and users on this machine may hold it),
  waited for until it serves and a WebSocket client is connected, stopped with SIGINT once the
  next block's commands have run;
- `<!-- output -->`: a ```text block showing the previous command's output: each of its lines'
  labels must be in what the command printed (the numbers are the page's run, not this one's);
- `<!-- file: NAME -->`: a ```python block the reader saves as NAME (a later command runs it).
Any other block (a python block without a file, a text block without output) fails the test.
"""
from __future__ import annotations

import csv
import json
import os
import re
import signal
import socket
import struct
import subprocess
import threading
from collections import Counter
from contextlib import ExitStack
from dataclasses import dataclass
from pathlib import Path

from websockets.sync.client import connect

from conftest import ROOT, wait_for

GUIDE = ROOT / 'docs' / 'user_guide.md'
TIMEOUT = 300.0  # [s] wall time of one command on a loaded machine (the first run: about 40)
FOXGLOVE_STOPPED = 0  # exit code of `multilift foxglove` after Ctrl-C (its docstring; README's
#                       contract for interrupted commands says 130: see test_foxglove.py)


@dataclass
class Block:
    lang: str
    text: str
    marker: str  # the HTML comment right before the block, '' if none
    line: int  # where the block starts in the page


def blocks(page: str) -> list[Block]:
    """The page's fenced blocks in order, each with the HTML comment on the line before it."""
    found = []
    for match in re.finditer(r'^(?:<!-- (.*?) -->\n)?```(\w*)\n(.*?)^```$', page,
                             re.MULTILINE | re.DOTALL):
        found.append(Block(match.group(2), match.group(3), match.group(1) or '',
                           page.count('\n', 0, match.start(2)) + 1))
    return found


def commands(text: str) -> list[str]:
    """A sh block's commands: backslash continuations joined, blank and comment lines left out."""
    joined = re.sub(r'\\\n\s*', ' ', text)
    return [line.strip() for line in joined.splitlines()
            if line.strip() and not line.strip().startswith('#')]


def localised(command: str) -> str:
    """The command with the page's relative `scripts/` made the repository's."""
    return re.sub(r'(?<![\w./-])scripts/', f'{ROOT}/scripts/', command)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


class Lines:
    """A process's stdout (text, stderr merged) read in a thread, line by line."""

    def __init__(self, process: subprocess.Popen) -> None:
        self.lines: list[str] = []
        self.thread = threading.Thread(target=self._read, args=(process.stdout,), daemon=True)
        self.thread.start()

    def _read(self, stream) -> None:
        for line in stream:
            self.lines.append(line)

    def text(self) -> str:
        return ''.join(self.lines)


class Client:
    """A Foxglove WebSocket client in a thread, as the app is: subscribes to every channel the
    server advertises; counts each topic's messages and keeps its latest log time."""

    def __init__(self, port: int) -> None:
        self.stack = ExitStack()  # websockets wants its connection used as a context manager
        self.ws = self.stack.enter_context(
            wait_for(lambda: self._connect(port), 60, 'a WebSocket connection to the bridge'))
        self.info = json.loads(self.ws.recv(timeout=60))
        self.topics: dict[int, str] = {}
        self.counts: Counter = Counter()
        self.last_time: dict[str, int] = {}
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    @staticmethod
    def _connect(port: int):
        try:
            return connect(f'ws://127.0.0.1:{port}', subprotocols=['foxglove.websocket.v1'],
                           max_size=None)
        except OSError:
            return None

    def _run(self) -> None:
        try:
            for frame in self.ws:
                if isinstance(frame, str):
                    message = json.loads(frame)
                    if message['op'] == 'advertise':
                        for channel in message['channels']:
                            self.topics[channel['id']] = channel['topic']
                        self.ws.send(json.dumps({'op': 'subscribe', 'subscriptions': [
                            {'id': c['id'], 'channelId': c['id']} for c in message['channels']]}))
                elif frame[0] == 0x01:  # message data: subscription id, log time, payload
                    sub_id, log_time = struct.unpack_from('<IQ', frame, 1)
                    topic = self.topics[sub_id]  # subscription id = channel id
                    self.counts[topic] += 1
                    self.last_time[topic] = log_time
        except Exception:  # noqa: BLE001 - the connection closed at the end of the test
            pass

    def close(self) -> None:
        self.stack.close()
        self.thread.join(timeout=10)


def layout_topics(layout: Path) -> set[str]:
    """Every topic a Foxglove layout's panels show (a plot path's message, the 3-D topics)."""
    found: set[str] = set()

    def walk(value) -> None:
        if isinstance(value, dict):
            for key, item in value.items():
                walk(key)
                walk(item)
        elif isinstance(value, list):
            for item in value:
                walk(item)
        elif isinstance(value, str) and (match := re.match(r'/[A-Za-z0-9_/]+', value)):
            found.add(match.group(0))
    walk(json.loads(layout.read_text()))
    return found


def label(line: str) -> str:
    """A summary line's label: what comes before its first number (not one inside a word such
    as uav1) or run of spaces."""
    return re.split(r'\s{2,}|(?<!\w)\d', line.strip(), maxsplit=1)[0].strip()


class Tour:
    """Runs the page's blocks in order in `cwd`; keeps each command's output."""

    def __init__(self, cwd: Path) -> None:
        self.cwd = cwd
        self.env = dict(os.environ)  # multilift_domain's domain, localhost discovery
        self.outputs: dict[str, str] = {}  # the page's command -> its stdout
        self.last = ''
        self.background: tuple[subprocess.Popen, Lines, Client] | None = None
        self.stop_after_next = False  # the background process, after the next sh block
        self.clock_end = 0  # [ns] the last /clock of the live view's run
        self.client_topics: set[str] = set()  # what the live view's client received

    def run(self, command: str) -> None:
        result = subprocess.run(['bash', '-c', localised(command)], cwd=self.cwd, env=self.env,
                                capture_output=True, text=True, timeout=TIMEOUT)
        assert result.returncode == 0, (command, result.returncode,
                                        result.stdout[-3000:], result.stderr[-3000:])
        self.outputs[command] = self.last = result.stdout

    def block(self, block: Block) -> None:
        where = f'docs/user_guide.md:{block.line}'
        if block.marker == 'output':
            assert block.lang == 'text', where
            for line in block.text.splitlines():
                assert label(line) in self.last, (where, label(line), self.last)
        elif block.marker.startswith('file: '):
            assert block.lang == 'python', where
            (self.cwd / block.marker[len('file: '):]).write_text(block.text)
        elif block.marker == 'background':
            assert block.lang == 'sh' and len(commands(block.text)) == 1, where
            self.start_background(commands(block.text)[0])
        else:
            assert block.lang == 'sh' and not block.marker, (where, 'not a block the test runs',
                                                             block.marker, block.lang)
            for command in commands(block.text):
                self.run(command)
                if self.background and (match := re.search(r'--duration (\S+)', command)):
                    self.clock_end = int(float(match.group(1)) * 1e9)
            if self.stop_after_next:
                self.stop_background()

    def start_background(self, command: str) -> None:
        assert re.fullmatch(r'scripts/multilift foxglove', command), command
        port = free_port()
        process = subprocess.Popen(['bash', '-c', f'exec {localised(command)} --port {port}'],
                                   cwd=self.cwd, env=self.env, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True,
                                   start_new_session=True)
        lines = Lines(process)

        def serving() -> bool:
            assert process.poll() is None, ('the bridge exited', process.returncode, lines.text())
            return f'serving ws://127.0.0.1:{port}' in lines.text()
        wait_for(serving, 60, 'the bridge printing that it serves')
        self.background = (process, lines, Client(port))
        self.stop_after_next = True

    def stop_background(self) -> None:
        process, lines, client = self.background
        if self.clock_end:  # the run's last /clock forwarded: the live view saw the whole run
            wait_for(lambda: client.last_time.get('/clock') == self.clock_end, 60,
                     'the run\'s last /clock at the client')
        self.client_topics = set(client.counts)
        client.close()
        os.killpg(process.pid, signal.SIGINT)  # Ctrl-C in the bridge's terminal
        assert process.wait(timeout=60) == FOXGLOVE_STOPPED, lines.text()
        lines.thread.join(timeout=10)
        assert 'stopped after forwarding' in lines.text(), lines.text()
        self.background, self.stop_after_next = None, False

    def close(self) -> None:
        """Stop a background process the tour left running (a failed test)."""
        if self.background:
            process, _, client = self.background
            client.close()
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait(timeout=30)


def test_every_command_of_the_user_guide(multilift_domain, tmp_path):
    page = GUIDE.read_text()
    tour = Tour(tmp_path)
    try:
        for block in blocks(page):
            tour.block(block)
        assert tour.background is None, 'the background command was not stopped'
    finally:
        tour.close()
    runs = tmp_path / 'runs'
    out = tour.outputs

    # every `runs/...` path and every figure the page names was written
    for path in re.findall(r'`(runs/[^`\s]+)`', page):
        assert (tmp_path / path).exists(), path
    for name in re.findall(r'`(\w+\.png)`', page):
        assert (runs / 'twin_lift' / 'plots' / name).is_file(), name

    # the first run: its bag, summary; `bag info`'s counts as the page gives them
    summary = json.loads((runs / 'twin_lift' / 'summary.json').read_text())
    assert abs(summary['sim']['simulated_time'] - 120.0) < 1e-9
    info = out['scripts/multilift bag info runs/twin_lift']
    counts = dict(re.findall(r'Topic: (\S+) \| .*?Count: (\d+)', info))
    assert counts['/clock'] == counts['/payload/odom'] == counts['/formation/state'] == '12001'
    assert counts['/uav1/rotor_cmd'] == counts['/formation/snapshot'] == '12000'
    assert int(counts['/visualization/markers']) in (1200, 1201)
    assert 'Duration:          120.0' in info

    # plots: "Eleven PNG figures"
    assert 'Eleven PNG figures' in page
    assert len(list((runs / 'twin_lift' / 'plots').glob('*.png'))) == 11

    # the headless run: 5 s simulated
    headless = json.loads((runs / 'twin_lift_5s' / 'summary.json').read_text())
    assert abs(headless['sim']['simulated_time'] - 5.0) < 1e-9

    # the sweep: one row per value of the page's --set, in order, every run ok; the columns the
    # page names; tension and tracking grow with the mass
    values = [float(v) for v in re.search(r'--set payload\.mass=(\S+)', page).group(1).split(',')]
    with open(runs / 'mass.csv', newline='') as stream:
        rows = list(csv.DictReader(stream))
    assert [float(row['payload.mass']) for row in rows] == values
    assert [row['run'] for row in rows] == [str(k) for k in range(len(values))]
    assert all(row['status'] == 'ok' for row in rows)
    for column in ('seed', 'message', 'max_abs_g', 'saturated_time', 'min_tension', 'max_tension',
                   'tracking_error_max', 'wall_time'):
        assert column in rows[0], column
    for column in ('max_tension', 'tracking_error_max'):
        series = [float(row[column]) for row in rows]
        assert series == sorted(series) and len(set(series)) == len(series), (column, series)
    worst = (runs / 'mass_plots' / 'worst_runs.md').read_text()
    assert 'tracking_error_max' in worst

    # the live view: the client got every topic the layout's panels show, the whole run
    assert tour.clock_end == 10 * 10**9
    assert layout_topics(runs / 'twin_lift_layout.json') <= tour.client_topics

    # the learning episode: the spaces' shapes, a return of at most 1 a tick, the bag; no
    # reference in it
    episode = out['source scripts/env.sh && python episode.py']
    assert 'observation (38,) action (8,)' in episode, episode
    assert 0 < float(re.search(r'return (\S+) at t = 5\.00 s', episode).group(1)) < 500, episode
    assert 'bag runs/episodes/episode_0001' in episode, episode
    episode_info = out['scripts/multilift bag info runs/episodes/episode_0001']
    assert 'Duration:          5.0' in episode_info
    assert '/uav1/rotor_cmd' in episode_info and '/uav2/rotor_cmd' in episode_info
    assert '/uav1/reference' not in episode_info and '/uav2/formation_error' not in episode_info
