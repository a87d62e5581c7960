"""`multilift sweep` campaigns and `multilift plot-sweep`.

The campaign logic without Dask (parsing, grid, seeded draws, tables); campaigns on a local
Dask cluster (rows against an in-process run, stopped rows, bad input, SIGTERM, Ctrl-C and a
hang-up); and through a real command-line cluster: `dask scheduler` and two `dask worker` hosts
(each its own process group: nanny, worker and multiprocessing's resource tracker) on
127.0.0.1, ports chosen by the OS, dashboards off, every process stopped at teardown. One worker
host SIGKILLed mid-campaign still gives every row exactly once; the same sampled campaign twice
gives the same table; a drawn value the scenario rejects is an `error` row. No sweep, finished
or interrupted, and no cluster leaves a multiprocessing semaphore (/dev/shm/sem.mp-*) behind:
the nannies' queues are made of them, and nothing else would ever remove them."""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import threading
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest import ROOT, SCENARIOS
from multilift_control.headless import run_headless
from multilift_sim import scenario as scenario_io
from multilift_sim.statistics import summary_row
from multilift_tools import campaign as cp
from multilift_tools.campaign.plot_sweep import plot_sweep_main
from multilift_tools.campaign.sweep import sweep_main

PYTHON = str(ROOT / '.venv' / 'bin' / 'python')
DASK = str(ROOT / '.venv' / 'bin' / 'dask')


def _base(name: str) -> dict:
    return yaml.safe_load((SCENARIOS / f'{name}.yaml').read_text())


def _campaign(sets=(), samples=(), n=None, seed=0, name='single_lift_swing'):
    return cp.build_campaign(name, _base(name), [cp.parse_set(s) for s in sets],
                             [cp.parse_sample(s) for s in samples], n, seed)


def _table(path: Path) -> list[dict]:
    return cp.read_table(path)[1]


# --------------------------------------------------------------------------- campaign logic
def test_grid_is_the_product_in_order_and_samples_repeat_each_point():
    c = _campaign(['payload.mass=0.3,0.5', 'payload.drag_coefficient=0,0.1'],
                  ['vehicle.mass=uniform(2.4, 2.6)'], n=3)
    assert [r.index for r in c.runs] == list(range(12))
    assert [(r.params['payload.mass'], r.params['payload.drag_coefficient'])
            for r in c.runs[::3]] == [(0.3, 0), (0.3, 0.1), (0.5, 0), (0.5, 0.1)]
    assert all(2.4 <= r.params['vehicle.mass'] <= 2.6 for r in c.runs)
    assert len({r.seed for r in c.runs}) == 12


def test_each_run_draws_from_its_own_seeded_stream():
    c = _campaign(samples=['payload.mass=normal(0.4, 0.05)',
                           'payload.drag_coefficient=choice(0, 0.1, 0.2)'], n=5, seed=7)
    again = _campaign(samples=['payload.mass=normal(0.4, 0.05)',
                               'payload.drag_coefficient=choice(0, 0.1, 0.2)'], n=5, seed=7)
    assert [r.params for r in c.runs] == [r.params for r in again.runs]
    for run in c.runs:   # the row's seed alone gives its draws, in --sample order
        rng = np.random.default_rng(run.seed)
        assert run.params['payload.mass'] == rng.normal(0.4, 0.05)
        assert run.params['payload.drag_coefficient'] == (0, 0.1, 0.2)[rng.integers(3)]
    # run i's stream does not depend on how many runs there are
    assert [r.params for r in _campaign(samples=['payload.mass=normal(0.4, 0.05)',
                                                 'payload.drag_coefficient=choice(0, 0.1, 0.2)'],
                                        n=8, seed=7).runs[:5]] == [r.params for r in c.runs]
    other = _campaign(samples=['payload.mass=normal(0.4, 0.05)'], n=5, seed=8)
    assert [r.params['payload.mass'] for r in other.runs] != \
        [r.params['payload.mass'] for r in c.runs]


@pytest.mark.parametrize('option,message', [
    ('payload.mass', 'expected KEY=uniform(a,b)'),
    ('payload.mass=gauss(1,2)', "'gauss(1,2)' is not uniform(a,b)"),
    ('payload.mass=uniform(1)', 'uniform takes 2 numbers, got 1'),
    ('payload.mass=uniform(2,1)', 'needs a < b'),
    ('payload.mass=normal(1,0)', 'needs sigma > 0'),
    ('payload.mass=normal(x,1)', "'x' is not a number"),
    ('payload.mass=uniform(0,inf)', 'inf is not finite'),
    ('payload.mass=choice(1,,2)', 'an empty argument'),
    ('payload..mass=choice(1)', 'is not a key'),
])
def test_bad_sample_spec_is_named(option, message):
    with pytest.raises(cp.SweepError, match=re.escape(message)):
        cp.parse_sample(option)


def test_csv_and_parquet_tables_read_back(tmp_path):
    columns = ['run', 'vehicle.inertia', 'payload.mass', 'seed', 'status', 'message', 'x']
    rows = [{'run': 0, 'vehicle.inertia': [1, 1, 2], 'payload.mass': 0.4, 'seed': 2 ** 62,
             'status': 'ok', 'message': '', 'x': 0.1},
            {'run': 1, 'vehicle.inertia': [1, 1, 3], 'payload.mass': 1, 'seed': 5,
             'status': 'error', 'message': 'a, "b"', 'x': None}]
    meta_in = {'grid': {'payload.mass': ['0.4', '1']}, 'sample': {'vehicle.inertia': 'x'}}
    for name in ('t.csv', 't.parquet'):
        cp.write_table(tmp_path / name, columns, rows, meta_in)
        got_columns, got, meta = cp.read_table(tmp_path / name)
        assert got_columns == columns
        assert [r['vehicle.inertia'] for r in got] == ['[1, 1, 2]', '[1, 1, 3]']
        assert [r['payload.mass'] for r in got] == [0.4, 1.0]
        assert [r['seed'] for r in got] == [2 ** 62, 5]
        assert got[1]['message'] == 'a, "b"' and got[1]['x'] is None and got[0]['x'] == 0.1
        assert meta == meta_in   # in the Parquet file, beside the CSV (t.csv.campaign.json)


def test_run_one_turns_a_rejected_value_into_an_error_row():
    base = _base('single_lift_swing')
    row = cp.run_one('single_lift_swing', base, [('payload.mass', ('payload', 'mass'), -0.2)],
                     0.05)
    assert row['status'] == 'error' and 'payload.mass: -0.2 must be > 0' in row['message']
    assert row['simulated_time'] is None and row['wall_time'] >= 0
    ok = cp.run_one('single_lift_swing', base, [('payload.mass', ('payload', 'mass'), 0.3)],
                    0.05)
    assert ok['status'] == 'ok' and ok['message'] == ''
    assert ok['simulated_time'] == pytest.approx(0.05)


def test_run_one_reports_a_simulation_that_stopped_itself():
    base = _base('single_lift_swing')
    edits = [('simulation.baumgarte_alpha', ('simulation', 'baumgarte_alpha'), 0.0),
             ('simulation.baumgarte_beta', ('simulation', 'baumgarte_beta'), 0.0),
             ('simulation.constraint_tolerance', ('simulation', 'constraint_tolerance'), 1e-12)]
    row = cp.run_one('single_lift_swing', base, edits, 1.0)
    assert row['status'] == 'stopped'
    assert row['message'].startswith('cable 1: constraint residual |g|')
    assert 0 < row['simulated_time'] < 1.0 and row['max_abs_g'] > 1e-12


WALL_TIMES = """
import json, sys
from multilift_tools import campaign as cp
source, base = cp.load_base('twin_lift')
edits = lambda m: [('payload.mass', ('payload', 'mass'), m)]
masses = (0.6, 0.7, 0.8, 0.9, 1.0)
if sys.argv[1] == 'run_one':
    times = [cp.run_one(source, base, edits(m), 5.0)['wall_time'] for m in masses]
else:
    times = [cp.run_chunk(source, base, [(edits(m), None)], 20.0)[0]['wall_time']
             for m in masses]
print(json.dumps(times))
"""


@pytest.mark.parametrize('kind', ['run_one', 'run_chunk'])
def test_a_workers_first_run_reports_no_loading_of_compiled_code(kind):
    """In a fresh process (a new worker), five runs tick by tick (`run_one`) or five engine
    batches of one run (`run_chunk`): the first used to carry the loading of the compiled code
    (0.43 s against 0.015 s for the next ones), now loaded untimed before it
    (`runs.warm_up`). Each run takes 0.01-0.05 s here, and another process on the machine
    can add 0.1 s to any one of them: a fresh process is tried up to three times; the old
    offset was in every one."""
    seen = []
    for _ in range(3):
        out = subprocess.run([PYTHON, '-c', WALL_TIMES, kind], capture_output=True, text=True,
                             timeout=120, check=True).stdout
        times = json.loads(out.splitlines()[-1])
        seen.append(times)
        assert all(t > 0 for t in times), times
        if times[0] - float(np.median(times[1:])) < 0.1:
            return
    pytest.fail(f'the first run of a fresh process took 0.1 s longer than the others: {seen}')


# --------------------------------------------------------------------------- local cluster
def test_rows_in_product_order_equal_an_in_process_run(tmp_path):
    out = tmp_path / 'sweep.csv'
    code = sweep_main(['twin_lift', '--set', 'payload.mass=0.4,0.8', '--set',
                       'formation.alpha_vc=1.0,2.1', '--duration', '2', '--jobs', '2',
                       '--out', str(out), '--no-progress'])
    assert code == 0
    rows = _table(out)
    assert [(r['payload.mass'], r['formation.alpha_vc']) for r in rows] == \
        [(0.4, 1.0), (0.4, 2.1), (0.8, 1.0), (0.8, 2.1)]
    assert [r['run'] for r in rows] == [0, 1, 2, 3]
    for row in rows:
        assert row['status'] == 'ok' and row['message'] is None
        assert row['simulated_time'] == pytest.approx(2.0)
        assert 0 < row['max_rotor_speed'] <= 2100
        assert row['max_abs_g'] < 0.02
        assert row['tracking_error_rms'] <= row['tracking_error_max']
        assert row['formation_error_max'] >= 0
    # a row computed on a Dask worker equals the same variant run here
    data = _base('twin_lift')
    data['payload']['mass'] = 0.8
    data['formation']['alpha_vc'] = 2.1
    scenario = scenario_io.loads(yaml.safe_dump(data), 'here.yaml')
    run = run_headless(replace(scenario, simulation=replace(scenario.simulation,
                                                            duration=2.0)))
    assert rows[3]['max_abs_g'] == run.simulator.stats.max_abs_constraint
    assert rows[3]['max_rotor_speed'] == max(run.simulator.stats.max_rotor_speed)
    assert {k: rows[3][k] for k in cp.STATISTICS} == summary_row(run.summary())


def test_a_stopped_run_is_a_stopped_row_with_bags(tmp_path):
    out = tmp_path / 'sweep.parquet'
    code = sweep_main(['single_lift_swing', '--set', 'simulation.baumgarte_alpha=0.0,20.0',
                       '--set', 'simulation.baumgarte_beta=0.0', '--set',
                       'simulation.constraint_tolerance=1e-12', '--duration', '1', '--workers',
                       '1', '--out', str(out), '--bags', str(tmp_path / 'bags'),
                       '--no-progress'])
    assert code == 0
    rows = _table(out)
    assert [r['status'] for r in rows] == ['stopped', 'stopped']
    assert rows[0]['message'].startswith('cable 1: constraint residual |g|')
    assert rows[0]['simulated_time'] < 1.0
    for row in rows:
        assert Path(row['bag']) == tmp_path / 'bags' / f'run_{row["run"]:05d}'
        assert (Path(row['bag']) / 'metadata.yaml').is_file()


@pytest.mark.parametrize('args,message', [
    (['--set', 'payload.mas=0.4'], 'payload.mas: unknown key'),
    (['--set', 'payload.mass=0.4,-1'], 'payload.mass: -1.0 must be > 0'),
    (['--set', 'vehicle.frame_type=quad_x,tri'], "vehicle.frame_type: 'tri' must be one of"),
    (['--set', 'uavs[7].cable_length=3'], 'uavs[7].cable_length: index 7 is out of range'),
    (['--set', 'payload.mass'], 'expected KEY=V1,V2'),
    (['--set', 'payload.mass=0.4', '--set', 'payload.mass=0.5'], 'given twice'),
    (['--set', 'payload.mass=0.4', '--sample', 'payload.mass=uniform(0,1)', '--samples', '2'],
     'given twice'),
    (['--set', 'payload..mass=1'], 'is not a key'),
    (['--set', 'payload.mass=1', '--jobs', '0'], '--workers: 0 must be >= 1'),
    (['--sample', 'payload.mas=uniform(0.3,0.5)', '--samples', '2'], 'payload.mas: unknown key'),
    (['--sample', 'payload.mass=uniform(-2,-1)', '--samples', '2'], 'must be > 0'),
    (['--sample', 'payload.mass=beta(1,2)', '--samples', '2'], 'is not uniform(a,b)'),
    (['--sample', 'payload.mass=uniform(0.3,0.5)'], '--sample needs --samples N'),
    (['--samples', '3'], '--samples without --sample'),
    (['--sample', 'payload.mass=uniform(0.3,0.5)', '--samples', '0'], '--samples: 0 must be'),
    (['--scheduler', '127.0.0.1:8786'], 'expected tcp://HOST:PORT'),
])
def test_bad_input_is_one_line_and_exit_2_before_anything_starts(args, message, capsys):
    assert sweep_main(['twin_lift', *args]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count('\n') == 0 and err.startswith('error: ') and message in err, err


def test_per_uav_keys_make_the_uav_list(tmp_path):
    out = tmp_path / 'sweep.csv'
    assert sweep_main(['multi_lift', '--set', 'uavs[2].cable_length=10.26,10.5',
                       '--duration', '0.5', '--workers', '1', '--out', str(out),
                       '--no-progress']) == 0
    rows = _table(out)
    assert [r['uavs[2].cable_length'] for r in rows] == [10.26, 10.5]
    assert all(r['status'] == 'ok' for r in rows)
    assert _base('multi_lift').get('uavs') is None  # the file is untouched


def _descendants(pid: int) -> list[int]:
    found = subprocess.run(['pgrep', '-P', str(pid)], capture_output=True, text=True)
    children = [int(p) for p in found.stdout.split()]
    return children + [d for c in children for d in _descendants(c)]


def _running(pid: int) -> bool:
    try:
        return Path(f'/proc/{pid}/stat').read_text().split()[2] != 'Z'
    except FileNotFoundError:
        return False


class _Lines:
    """A child's stderr lines, read in a thread; `wait_for` a matching line."""

    def __init__(self, stream):
        self.lines: list[str] = []
        self.cond = threading.Condition()
        self.thread = threading.Thread(target=self._read, args=(stream,), daemon=True)
        self.thread.start()

    def _read(self, stream) -> None:
        for line in stream:
            with self.cond:
                self.lines.append(line)
                self.cond.notify_all()

    def wait_for(self, pattern: str, timeout: float) -> re.Match:
        deadline = time.monotonic() + timeout
        with self.cond:
            while True:
                for line in self.lines:
                    match = re.search(pattern, line)
                    if match:
                        return match
                left = deadline - time.monotonic()
                assert left > 0, f'no line matching {pattern!r} in {self.lines[-20:]}'
                self.cond.wait(left)

    def text(self) -> str:
        self.thread.join(timeout=10)
        return ''.join(self.lines)


def _group(pgid: int) -> list[int]:
    """The live processes of process group `pgid` (zombies are gone)."""
    pids = []
    for entry in Path('/proc').iterdir():
        try:
            fields = (entry / 'stat').read_text().rsplit(')', 1)[1].split()
        except (OSError, IndexError):   # not a process, or gone meanwhile
            continue
        if fields[0] != 'Z' and int(fields[2]) == pgid:
            pids.append(int(entry.name))
    return pids


class _Semaphores:
    """The multiprocessing semaphores (/dev/shm/sem.mp-*) that the processes of some process
    groups have open (mapped, in /proc/PID/maps), `sample`d now or polled in a thread. `left`:
    those of them still in /dev/shm once the groups ended. Only names that our processes
    opened count, so semaphores of other processes on the machine, made or left meanwhile, do
    not."""

    def __init__(self, *pgids: int, poll: bool = False):
        self.pgids = pgids
        self.names: set[str] = set()
        self.lock = threading.Lock()
        self.stop = threading.Event()
        self.thread = None
        if poll:
            self.thread = threading.Thread(target=self._poll, daemon=True)
            self.thread.start()

    def _poll(self) -> None:
        while True:
            self.sample()
            if self.stop.wait(0.05):
                return

    def sample(self) -> None:
        found = set()
        for pgid in self.pgids:
            for pid in _group(pgid):
                try:
                    found.update(re.findall(r'/dev/shm/(sem\.mp-[^\s/]+)',
                                            Path(f'/proc/{pid}/maps').read_text()))
                except OSError:   # gone meanwhile
                    pass
        with self.lock:
            self.names |= found

    def left(self, timeout: float = 10.0) -> set[str]:
        """The names seen that are still in /dev/shm `timeout` s after the processes ended
        (a resource tracker unlinks what it holds as it exits, after the last of them)."""
        self.stop.set()
        if self.thread is not None:
            self.thread.join()
        assert self.names, 'no process of ours had a sem.mp-* open: nothing was checked'
        deadline = time.monotonic() + timeout
        while True:
            left = {name for name in self.names if (Path('/dev/shm') / name).exists()}
            if not left or time.monotonic() > deadline:
                return left
            time.sleep(0.1)


# as a terminal starts it: Ctrl-C raises KeyboardInterrupt even should this test run with SIGINT
# ignored (a background job of a script), which a child would inherit
CLI = [PYTHON, '-c', 'import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler)'
       '; from multilift_tools.cli import main; sys.exit(main())']


def test_a_finished_local_sweep_leaves_no_semaphore(tmp_path):
    out = tmp_path / 'sweep.csv'
    proc = subprocess.Popen([*CLI, 'sweep', 'twin_lift', '--set', 'payload.mass=0.8,0.9',
                             '--duration', '1', '--workers', '2', '--out', str(out),
                             '--no-progress'],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    semaphores = _Semaphores(proc.pid, poll=True)
    try:
        err = _Lines(proc.stderr)
        assert proc.wait(timeout=180) == 0, err.text()
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert not semaphores.left(), err.text()
    assert [r['status'] for r in _table(out)] == ['ok', 'ok']


@pytest.mark.parametrize('how', ['SIGTERM', 'Ctrl-C', 'hang-up'])
def test_an_interrupted_local_sweep_stops_its_cluster_and_writes_what_finished(tmp_path, how):
    """SIGTERM to the sweep; Ctrl-C and a closed terminal signal its whole process group
    (SIGINT, SIGHUP): the workers too and multiprocessing's resource tracker."""
    out = tmp_path / 'sweep.csv'
    proc = subprocess.Popen([*CLI, 'sweep', 'twin_lift',
                             '--set', 'payload.mass=0.5,0.6,0.7,0.8,0.9,1.0', '--workers', '2',
                             '--out', str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    semaphores = _Semaphores(proc.pid, poll=True)
    try:
        err = _Lines(proc.stderr)
        err.wait_for(r'\[sweep\] 6 run\(s\) submitted', 120)   # 120 s missions: none done
        children = _descendants(proc.pid)
        assert len(children) >= 2   # the two worker processes
        semaphores.sample()   # the nannies' queues, open now
        if how == 'SIGTERM':
            proc.send_signal(signal.SIGTERM)
        else:
            os.killpg(proc.pid, signal.SIGINT if how == 'Ctrl-C' else signal.SIGHUP)
        code = proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    for pid in children:   # every worker (and multiprocessing's helpers) gone within 10 s
        gone = time.monotonic() + 10.0
        while time.monotonic() < gone and _running(pid):
            time.sleep(0.1)
        assert not _running(pid), pid
    assert not semaphores.left(), err.text()
    assert code == 130 and '(interrupted)' in err.text(), err.text()
    columns, rows, _ = cp.read_table(out)
    assert columns[:2] == ['run', 'payload.mass'] and len(rows) < 6


# --------------------------------------------------------------------------- plot-sweep
def test_plot_sweep_draws_each_parameter_and_lists_the_worst(tmp_path, capsys):
    c = _campaign(['payload.mass=0.3,0.5'], ['payload.drag_coefficient=uniform(0, 0.2)'], n=3)
    rows = []
    for run in c.runs:
        bad = run.index == 4
        rows.append(cp.make_row(run, {'status': 'error' if bad else 'ok',
                                      'message': 'boom' if bad else '',
                                      **dict.fromkeys(cp.STATISTICS),
                                      'max_abs_g': None if bad else 1e-3 * run.index,
                                      'max_tension': 2.0 + run.params['payload.mass'],
                                      'wall_time': 0.5}))
    table = tmp_path / 'c.parquet'
    cp.write_table(table, cp.table_columns(c, False), rows, c.metadata())
    assert plot_sweep_main([str(table), '--out', str(tmp_path / 'plots'), '--worst', '2']) == 0
    for name in ('payload.mass.png', 'payload.drag_coefficient.png'):
        assert (tmp_path / 'plots' / name).read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    worst = (tmp_path / 'plots' / 'worst_runs.md').read_text()
    lines = [line for line in worst.splitlines() if line.startswith('| ') and 'run' not in line]
    assert [line.split('|')[1].strip() for line in lines] == ['4', '5', '3']
    assert 'boom' in lines[0] and worst == capsys.readouterr().out
    assert plot_sweep_main([str(table), '--rank', 'nope']) == 2


# --------------------------------------------------------------------------- command-line cluster
class Cluster:
    """`dask scheduler` and two `dask worker` hosts on 127.0.0.1, each in its own session;
    `semaphores`: the multiprocessing semaphores their processes opened (each nanny's queues
    to its worker)."""

    def __init__(self, tmp_path: Path):
        self.procs: list[subprocess.Popen] = []
        self.hosts: dict[str, subprocess.Popen] = {}
        self.logs = tmp_path
        env = dict(os.environ, PYTHONUNBUFFERED='1')
        log = open(tmp_path / 'scheduler.log', 'w+')
        scheduler = self._start([DASK, 'scheduler', '--host', '127.0.0.1', '--port', '0',
                                 '--no-dashboard', '--no-show'], env, log)
        self.address = self._wait_log(tmp_path / 'scheduler.log', r'Scheduler at:\s+(tcp://\S+)',
                                      scheduler)
        for name in ('host_a', 'host_b'):
            log = open(tmp_path / f'{name}.log', 'w')
            self.hosts[name] = self._start(
                [DASK, 'worker', self.address, '--host', '127.0.0.1', '--nworkers', '1',
                 '--nthreads', '1', '--no-dashboard', '--name', name], env, log)
        from distributed import Client
        self.client = Client(self.address, timeout='30s')
        self.client.wait_for_workers(2, timeout=120)
        self.semaphores = _Semaphores(*(proc.pid for proc in self.procs))
        self.semaphores.sample()

    def _start(self, argv, env, log) -> subprocess.Popen:
        proc = subprocess.Popen(argv, env=env, stdout=log, stderr=subprocess.STDOUT,
                                start_new_session=True)
        self.procs.append(proc)
        return proc

    @staticmethod
    def _wait_log(path: Path, pattern: str, proc, timeout: float = 60) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            match = re.search(pattern, path.read_text())
            if match:
                return match.group(1)
            assert proc.poll() is None, path.read_text()
            time.sleep(0.1)
        raise AssertionError(f'{path}: no {pattern!r}: {path.read_text()}')

    def worker_of(self, name: str) -> str:
        return next(address for address, info in
                    self.client.scheduler_info(n_workers=-1)['workers'].items()
                    if info['name'] == name)

    def worker_names(self) -> list[str]:
        return sorted(info['name'] for info in
                      self.client.scheduler_info(n_workers=-1)['workers'].values())

    def log(self, name: str) -> str:
        return (self.logs / f'{name}.log').read_text()

    def kill_host(self, name: str) -> None:
        """SIGKILL the host's nanny and worker at once: its process group but multiprocessing's
        resource tracker. A dead host's /dev/shm goes with it; these hosts share this
        machine's, and the tracker unlinks the host's semaphores once the others are gone."""
        nanny = self.hosts[name].pid
        os.kill(nanny, signal.SIGKILL)   # first: it starts no worker after this
        for pid in _group(nanny):
            try:
                if b'multiprocessing.resource_tracker' not in \
                        Path(f'/proc/{pid}/cmdline').read_bytes():
                    os.kill(pid, signal.SIGKILL)
            except (FileNotFoundError, ProcessLookupError):
                pass
        self.hosts[name].wait(timeout=30)

    def close(self) -> None:
        """Stop every process as Ctrl-C would: SIGTERM to each session's leader (a nanny stops
        its worker), the hosts first; SIGKILL for what is left of a session after 30 s."""
        self.semaphores.sample()
        try:
            self.client.close(timeout=10)
        finally:
            for proc in reversed(self.procs):
                if proc.poll() is None:
                    proc.send_signal(signal.SIGTERM)
                    try:
                        proc.wait(timeout=30)
                    except subprocess.TimeoutExpired:
                        pass
                deadline = time.monotonic() + 30
                while _group(proc.pid) and time.monotonic() < deadline:
                    time.sleep(0.1)   # the worker, then the resource tracker, end after it
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:   # the session is empty, as it should be
                    pass
                proc.wait(timeout=30)


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path)
    try:
        yield c
    finally:
        c.close()
    # every host's semaphores went with it, the SIGKILLed host's too
    assert not c.semaphores.left()


SAMPLED = ['single_lift_swing', '--sample', 'payload.mass=uniform(0.3, 0.6)', '--sample',
           'payload.drag_coefficient=choice(0, 0.05, 0.1)', '--set',
           'simulation.baumgarte_alpha=10,20', '--samples', '8', '--seed', '41',
           '--duration', '1.5']


def test_a_worker_host_killed_mid_campaign_loses_and_doubles_no_row(cluster, tmp_path):
    out = tmp_path / 'killed.parquet'
    # runs long enough that a task (a chunk of runs flown as one engine batch: tenths of a
    # second) is still on host_a when it is killed
    longer = [*SAMPLED[:-1], '60']
    proc = subprocess.Popen([PYTHON, '-m', 'multilift_tools.cli', 'sweep', *longer,
                             '--scheduler', cluster.address, '--out', str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        err = _Lines(proc.stderr)
        err.wait_for(r'\[sweep\] [1-9]\d*/16 done', 180)
        victim = cluster.worker_of('host_a')
        deadline = time.monotonic() + 60
        while not cluster.client.processing(workers=[victim])[victim]:  # a run on host_a now
            assert time.monotonic() < deadline and proc.poll() is None, err.text()
            time.sleep(0.05)
        cluster.kill_host('host_a')
        assert proc.wait(timeout=300) == 0, err.text()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    rows = _table(out)
    expected = _campaign(['simulation.baumgarte_alpha=10,20'],
                         ['payload.mass=uniform(0.3, 0.6)',
                          'payload.drag_coefficient=choice(0, 0.05, 0.1)'], n=8, seed=41)
    assert [r['run'] for r in rows] == list(range(16))
    assert [(r['seed'], r['payload.mass']) for r in rows] == \
        [(run.seed, run.params['payload.mass']) for run in expected.runs]
    assert all(r['status'] == 'ok' for r in rows), [r['message'] for r in rows]
    assert all(r['simulated_time'] == pytest.approx(60.0) for r in rows)
    # the scheduler lets the killed host go and keeps the other (a nanny may be restarting
    # its worker at this moment: wait for the settled state, with the logs if it never comes)
    deadline = time.monotonic() + 60
    while (names := cluster.worker_names()) != ['host_b']:
        assert time.monotonic() < deadline, (
            f'workers {names}\nhost_b:\n{cluster.log("host_b")[-3000:]}\nscheduler:\n'
            f'{cluster.log("scheduler")[-3000:]}')
        time.sleep(0.2)


def test_the_same_sampled_campaign_twice_gives_the_same_table(cluster, tmp_path):
    tables = []
    for k in range(2):
        out = tmp_path / f'run{k}.parquet'
        assert sweep_main([*SAMPLED, '--scheduler', cluster.address, '--out', str(out),
                           '--no-progress']) == 0
        tables.append([{c: v for c, v in row.items() if c != 'wall_time'}
                       for row in _table(out)])
    assert len(tables[0]) == 16 and tables[0] == tables[1]
    assert len({row['payload.mass'] for row in tables[0]}) == 16
    assert all(row['status'] == 'ok' for row in tables[0])


def test_a_run_that_raises_is_an_error_row_and_the_campaign_goes_on(cluster, tmp_path):
    out = tmp_path / 'errors.csv'
    assert sweep_main(['single_lift_swing', '--sample', 'payload.mass=uniform(-0.3, 0.6)',
                       '--samples', '12', '--seed', '3', '--duration', '0.5', '--scheduler',
                       cluster.address, '--out', str(out), '--no-progress']) == 0
    rows = _table(out)
    assert [r['run'] for r in rows] == list(range(12))
    bad = [r for r in rows if r['payload.mass'] <= 0]
    assert bad and len(bad) < 12   # seed 3 draws both kinds
    for row in rows:
        if row['payload.mass'] <= 0:
            assert row['status'] == 'error', row
            assert f'payload.mass: {row["payload.mass"]} must be > 0' in row['message']
            assert row['simulated_time'] is None
        else:
            assert row['status'] == 'ok' and row['simulated_time'] == pytest.approx(0.5)


def test_an_unreachable_scheduler_is_exit_1(capsys):
    import socket
    with socket.socket() as s:   # a port nobody listens on
        s.bind(('127.0.0.1', 0))
        port = s.getsockname()[1]
    assert sweep_main(['single_lift_swing', '--scheduler', f'tcp://127.0.0.1:{port}',
                       '--no-progress']) == 1
    assert 'cannot reach the Dask scheduler' in capsys.readouterr().err
