"""`Engine`: B formations of the same shape stepped together by the compiled tick."""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from multilift_control import laws
from multilift_control.engine import tick as compiled
from multilift_control.engine.arrays import (FINISHED, RUNNING, FormationArrays, FormationMemory,
                                             TickRecord, batch_arrays, empty_record)
from multilift_control.laws.layout import REFERENCE_SIZE, UAV_STATE_SIZE
from multilift_sim.estimators.published import ESTIMATE_LINEAR, ESTIMATE_POSITION
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario import Scenario
from multilift_sim.physics.layout import STATUS_CONTACT
from multilift_sim.simulation import stop_message
from multilift_sim.statistics.clearance import clearance_figures, contact_message
from multilift_sim.schedules import event_records, run_seeds
from multilift_sim.tick_arrays import STOP_CHECKS
from multilift_sim.statistics import (FormationErrorStatistics, RunStatistics,
                                     TrackingStatistics)


class Engine:
    """B formations (scenarios of the same n, rotors, gusts, mission segments and formation
    rows; each with its own values) flown tick by tick, seed Algorithm 1, in one compiled call
    per `step` (`engine.tick.run_ticks`), or its uncompiled run under MULTILIFT_KERNEL=python.

        engine = Engine(scenario_io.load('twin_lift'), batch=64)   # or Engine([s1, s2, ...])
        engine.step(1000)            # up to 1000 ticks of each running formation
        engine.positions             # (B, n, 3) [m], world
        engine.finished              # (B,) bool

    A formation stops where Algorithm 1 stops it (`stopped`, `stop_reason`) and finishes at its
    scenario's duration; the others go on.
    """

    def __init__(self, scenarios: Scenario | Sequence[Scenario], batch: int | None = None,
                 fields: Sequence[tuple[dict, dict]] | None = None):
        if isinstance(scenarios, Scenario):
            scenarios = [scenarios] * (1 if batch is None else batch)
        elif batch is not None and batch != len(scenarios):
            raise ValueError(f'batch={batch} for {len(scenarios)} scenarios')
        self.scenarios = tuple(scenarios)
        if batch is not None and batch < 1:
            raise ValueError(f'batch must be >= 1, got {batch}')
        self.arrays: FormationArrays
        self.memory: FormationMemory
        self.arrays, self._initial = batch_arrays(self.scenarios, fields)
        self.n_uavs = self.arrays.uavs.shape[1]
        self.layout = StateLayout(self.n_uavs)
        (self._run_ticks, self._start, self._measure_all, self._answer_all,
         self._run_commanded, self._attitude_commands, self._mission_references) = map(
            laws.runnable, (compiled.run_ticks, compiled.start, compiled.measure_all,
                            compiled.answer_all, compiled.run_commanded,
                            compiled.attitude_commands, compiled.mission_references))
        rotors = self.arrays.allocation.shape[-1]
        self._tension = np.zeros((self.batch, self.n_uavs))
        self._measured = np.empty((self.batch, self.n_uavs, UAV_STATE_SIZE))
        self._answer = (np.zeros((self.batch, self.n_uavs, rotors)),
                        np.zeros((self.batch, self.n_uavs, rotors), dtype=bool))
        self._no_record = empty_record(self.arrays, 0)
        self.reset()

    @property
    def batch(self) -> int:
        return len(self.scenarios)

    def reset(self, which: np.ndarray | None = None) -> None:
        """Every formation (or those where `which` (B,) bool is set) back to its scenario's
        start (t = 0, controllers' memories and run figures empty)."""
        if which is None or not hasattr(self, 'memory'):
            self.memory = FormationMemory(*(np.array(field, copy=True)
                                            for field in self._initial))
            which = np.ones(self.batch, dtype=bool)
        else:
            which = np.asarray(which, dtype=bool)
            if which.shape != (self.batch,):
                raise ValueError(f'which must be ({self.batch},) bool, got {which.shape}')
            for field, initial in zip(self.memory, self._initial):
                field[which] = initial[which]
        self._start(self.arrays, self.memory, which)

    def step(self, ticks: int = 1, record: TickRecord | None = None) -> np.ndarray:
        """Up to `ticks` control ticks of each running formation; with `record`
        (`new_record(ticks)`) every tick's state, answers and cable figures kept at its row.
        Returns the ticks flown per formation (B,)."""
        if ticks < 0:
            raise ValueError(f'ticks must be >= 0, got {ticks}')
        if record is not None and record.speeds.shape[0] < ticks:
            raise ValueError(f'the record holds {record.speeds.shape[0]} ticks, not {ticks}')
        return self._run_ticks(self.arrays, self.memory, int(ticks),
                               self._no_record if record is None else record)

    def measured(self) -> np.ndarray:
        """Every formation's measured UAV states (B, n, UAV_STATE_SIZE) at its current tick
        (multilift_control.laws.layout slots: position, velocity (world), roll/pitch/yaw,
        body rates); a view the next call overwrites."""
        self._measure_all(self.arrays, self.memory, self._measured)
        return self._measured

    def answer(self, states: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The scenario's own controllers' rotor speeds (B, n, rotors) [rad/s] and saturation
        flags for every running formation at its current tick, as a tick computes them (the
        controllers' memories advance: call it once per tick, before `step_commanded`), to
        the formations' measured `states` (B, n, UAV_STATE_SIZE) if given (a state received
        from elsewhere), else to their own. Views the next call overwrites."""
        speeds, saturated = self._answer
        states = self.measured() if states is None else np.ascontiguousarray(states, float)
        self._answer_all(self.arrays, self.memory, states, speeds, saturated)
        return speeds, saturated

    def references(self, t: np.ndarray | None = None) -> np.ndarray:
        """Every formation's mission reference (B, REFERENCE_SIZE: position [m], velocity
        [m/s], acceleration [m/s^2], world) at times t (B,) [s], its own by default; NaN rows
        for a leader without a mission."""
        t = self.t if t is None else np.ascontiguousarray(t, float)
        out = np.empty((self.batch, REFERENCE_SIZE))
        self._mission_references(self.arrays, t, out)
        return out

    def attitude_speeds(self, setpoints: np.ndarray, thrust: np.ndarray,
                        states: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Rotor speeds (B, n, rotors) [rad/s] and saturation flags holding attitude
        `setpoints` (B, n, 3: roll, pitch, yaw [rad]) with collective `thrust` (B, n) [N]:
        every UAV's attitude loop and mixer (the cascade's inner half, seed Ch. 3) at the
        measured `states` (B, n, UAV_STATE_SIZE), the formations' own by default."""
        states = self.measured() if states is None else np.ascontiguousarray(states, float)
        speeds = np.empty(self._answer[0].shape)
        saturated = np.empty(self._answer[1].shape, dtype=bool)
        self._attitude_commands(self.arrays, self.memory, states,
                                np.ascontiguousarray(setpoints, float),
                                np.ascontiguousarray(thrust, float), speeds, saturated)
        return speeds, saturated

    def step_commanded(self, speeds: np.ndarray, saturated: np.ndarray | None = None,
                       which: np.ndarray | None = None) -> np.ndarray:
        """One control tick of every running formation (those in `which` (B,) bool) under the
        given rotor speeds (B, n, rotors) [rad/s], held over the control period (seed Eq.
        2.14, RK4), then Algorithm 1's check; `saturated` flags speeds at a limit (the run's
        saturation figure; default none). Returns the cable tensions (B, n) [N] of the tick
        (a formation not stepped keeps its row)."""
        speeds = np.ascontiguousarray(speeds, dtype=float)
        if speeds.shape != self._answer[0].shape:
            raise ValueError(f'speeds must be {self._answer[0].shape}, got {speeds.shape}')
        if saturated is None:
            saturated = np.zeros(speeds.shape, dtype=bool)
        which = np.ones(self.batch, dtype=bool) if which is None else np.asarray(which, bool)
        self._run_commanded(self.arrays, self.memory, speeds,
                            np.ascontiguousarray(saturated, dtype=bool), which, self._tension)
        return self._tension

    def new_record(self, ticks: int) -> TickRecord:
        """Arrays for `ticks` ticks of every formation (`step`'s record)."""
        return empty_record(self.arrays, ticks)

    # ------------------------------------------------------------------------- state views
    @property
    def state(self) -> np.ndarray:
        """The formation states (B, len(x): docs/conventions.md) at the
        current tick (docs/conventions.md, docs/rigid_payload.md)."""
        return self.memory.state

    @property
    def t(self) -> np.ndarray:
        """Simulated time of each formation (B,) [s]."""
        return self.memory.tick * self.arrays.period_ns * 1e-9

    @property
    def t_max(self) -> np.ndarray:
        """Each formation's duration (B,) [s]: its last tick's time."""
        return self.arrays.tick_count * self.arrays.period_ns * 1e-9

    @property
    def positions(self) -> np.ndarray:
        """UAV positions (B, n, 3) [m], world."""
        return StateLayout(self.n_uavs).uav_positions(self.memory.state)

    def payload_estimates(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Every formation's payload estimate at its current tick (`payload_estimator:`):
        (positions, velocities) (B, 3) [m, m/s], world, as /payload/estimate publishes them
        (the estimator runs in `measured`, which is called first); None without one."""
        memory = self.memory.payload_estimator_memory
        if not memory.shape[1]:
            return None
        self.measured()
        return (memory[:, 0, ESTIMATE_POSITION:ESTIMATE_POSITION + 3].copy(),
                memory[:, 0, ESTIMATE_LINEAR:ESTIMATE_LINEAR + 3].copy())

    @property
    def payload_positions(self) -> np.ndarray:
        """Payload positions (B, 3) [m], world."""
        return StateLayout(self.n_uavs).payload_position(self.memory.state)

    @property
    def running(self) -> np.ndarray:
        return self.memory.status == RUNNING

    @property
    def finished(self) -> np.ndarray:
        return self.memory.status == FINISHED

    @property
    def stopped(self) -> np.ndarray:
        """Formations Algorithm 1 stopped (B,) bool."""
        return self.memory.status > FINISHED

    def stop_reason(self, b: int) -> str | None:
        """Why formation b stopped, in the simulator's words (None while it has not)."""
        if int(self.memory.status[b]) == STATUS_CONTACT:
            return contact_message(self.scenarios[b], self.memory.contact[b])
        check = STOP_CHECKS.get(int(self.memory.status[b]))
        if check is None:
            return None
        return stop_message(check, int(self.memory.worst_cable[b]),
                            float(self.memory.worst_value[b]), float(self.t[b]),
                            self.scenarios[b].simulation, self.scenarios[b].n_uavs)

    # ----------------------------------------------------------------------------- figures
    def summary(self, b: int = 0, wall_time: float | None = None) -> dict:
        """Formation b's run statistics as a run reports them ({'sim': ..., 'leader': ...,
        'follower2': ...}: `multilift_control.headless.HeadlessRun.summary`'s keys, order and
        definitions, `multilift_sim.statistics`); the wall time [s] given or left out."""
        run = RunStatistics(self.n_uavs)
        run.run[:] = self.memory.run[b]
        leader = TrackingStatistics()
        leader.acc[:] = self.memory.tracking[b]
        sim = run.as_dict()
        if wall_time is not None:
            sim['wall_time'] = wall_time
        happened = event_records(self.arrays.events[b, :self.memory.next_event[b]])
        out = {'sim': dict(sim, error=self.stop_reason(b), scenario=self.scenarios[b].name,
                           events=happened, seeds=run_seeds(self.scenarios[b]),
                           **clearance_figures(self.scenarios[b], self.memory.clearance[b],
                                               self.memory.contact[b]))}
        if not self.scenarios[b].controlled:  # every UAV prescribed: no controller to report
            return out
        out['leader'] = leader.as_dict()
        for i in range(1, self.n_uavs):
            follower = FormationErrorStatistics()
            follower.acc[:] = self.memory.formation_errors[b, i]
            out[f'follower{i + 1}'] = follower.as_dict()
        return out
