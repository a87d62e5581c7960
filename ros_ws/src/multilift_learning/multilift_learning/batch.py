"""B formations of one task on the batched engine, as the environments see them: actions in,
observations, rewards and episode ends out, every array with the batch axis first. The one
place that defines them (`FormationEnv` is B = 1, `FormationVectorEnv` B = num_envs).

Actions: `multilift_learning.actions` (0 = hover; rotor speeds, or collective thrust and body
rates). Observations: `multilift_learning.observations` (float32, their scales).

Reward, per tick, in [0, 1]: exp(-cost), cost = sum of weight * term (REWARD_WEIGHTS):
- tracking: |payload position error| [m];
- swing: |horizontal payload velocity error| [m/s];
- effort: mean over rotors of ((omega - omega_hover) / omega_max)^2;
- health: max over taut cables of |g_i| / constraint_tolerance (the seed's Eq. 2.59 residual);
and 0 at a step that terminates the episode. Every tick pays at least 0, so ending an episode
early never pays more than flying on.

An episode terminates (`TERMINATIONS`, the reason in `info['termination']`) when Algorithm 1
stops the formation (a physical failure: non-finite state, |g| or |g_dot| beyond tolerance),
a UAV tilts beyond the tilt limit, a UAV or the payload is below the ground, or the payload
leaves the bound about its target (multilift_learning.options); it is truncated at the
episode's duration.
"""
from __future__ import annotations

import numpy as np

from multilift_control import laws
from multilift_control.engine import Engine
from multilift_control.laws.layout import (UAV_BODY_RATES, UAV_EULER, UAV_POSITION,
                                           UAV_VELOCITY)
from multilift_learning.actions import centred, uncentred
from multilift_learning.laws import body_rates
from multilift_learning.observations import (finished_observation, observation_names,
                                             observation_scales)
from multilift_learning.options import GROUND_BELOW_REST, TaskOptions
from multilift_learning.tasks import Targets, task, task_scenario
from multilift_sim.formation_params import StateLayout
from multilift_sim.physics.layout import REEL_COMMAND
from multilift_sim.scenario import Scenario
from multilift_sim.start import cable_reach
from multilift_sim.statistics.swing import equilibrium_point

REWARD_WEIGHTS = {'tracking': 1.0, 'swing': 0.5, 'effort': 0.1, 'health': 1.0}
# why an episode terminated, in the order they are checked (info['termination'])
TERMINATIONS = ('physical failure', 'tilt limit', 'ground contact', 'bound')

__all__ = ['FormationBatch', 'REWARD_WEIGHTS', 'TERMINATIONS', 'observation_names']


class FormationBatch:
    """B formations (`scenarios`, of the same shape) of task `task_name` on one Engine, with
    `options` (multilift_learning.options.TaskOptions; their duration already applied to the
    scenarios)."""

    def __init__(self, scenarios: list[Scenario], task_name: str,
                 options: TaskOptions | None = None):
        options = TaskOptions() if options is None else options
        self.options = options
        kind = task(task_name)
        if kind.needs_mission and any(s.control.mode != 'cascade' for s in scenarios):
            raise ValueError(f'task {task_name!r} needs a scenario whose leader flies its '
                             'mission (control.mode: cascade)')
        scenarios = [task_scenario(s, task_name, options.start) for s in scenarios]
        self.scenarios = scenarios
        self.engine = Engine(scenarios)
        self.batch = self.engine.batch
        self.n = n = self.engine.n_uavs
        self.rotors = self.engine.arrays.allocation.shape[-1]
        self.layout = StateLayout(n)
        limits = np.array([[(u.vehicle.rotor_speed_min, u.vehicle.rotor_speed_max)
                            for u in s.uavs] for s in scenarios])        # (B, n, 2)
        self.speed_min = limits[:, :, :1]                                # (B, n, 1)
        self.speed_max = limits[:, :, 1:]
        weight_share = np.array([[(u.vehicle.mass + s.payload.mass / n) * s.simulation.gravity
                                  for u in s.uavs] for s in scenarios])  # (B, n) [N]
        k_t = np.array([[u.vehicle.thrust_coefficient for u in s.uavs] for s in scenarios])
        self.speed_hover = np.sqrt(weight_share / (self.rotors * k_t))[:, :, None]
        self.thrust_hover = weight_share                                 # (B, n) [N]
        self.thrust_max = k_t * self.rotors * limits[:, :, 1] ** 2       # (B, n) [N]
        self.tension_share = np.array([s.payload.mass * s.simulation.gravity / n
                                       for s in scenarios])[:, None]     # (B, 1) [N]
        self.tolerance = np.array([s.simulation.constraint_tolerance for s in scenarios])
        # the payload's rest place under the UAVs' start, and each UAV's offset from it
        # (B, n, 3) [m]
        rest_place = laws.runnable(equilibrium_point)
        rest = np.array([rest_place(self.engine.positions[b], cable_reach(s))
                         for b, s in enumerate(scenarios)])
        self.start_offsets = self.engine.positions.copy() - rest[:, None, :]
        self.ground = (rest[:, 2] - GROUND_BELOW_REST if options.ground_height is None
                       else np.full(self.batch, float(options.ground_height)))   # (B,) [m]
        self.targets = Targets(task_name, self.engine, rest, self.start_offsets,
                               options.target_radius)
        self.scales = observation_scales(n) if options.normalise else None
        self.tension = np.zeros((self.batch, n))
        self.rngs = [np.random.default_rng() for _ in range(self.batch)]
        self._expert_at: np.ndarray | None = None
        self._expert = np.zeros((self.batch, n * self.rotors))
        self._rate_commands = laws.runnable(body_rates.body_rate_commands)
        self.reel_limits = _reel_limits(scenarios) if options.winch_actions else None  # (B, n)

    @property
    def uav_action_size(self) -> int:
        """The length of one UAV's action: its rotors' speeds (or a collective thrust and
        three body rates), then with winch_actions its reel rate."""
        flight = self.rotors if self.options.action_mode == 'rotor_speeds' else 4
        return flight + (self.reel_limits is not None)

    @property
    def action_size(self) -> int:
        """The length of one formation's action (each UAV's `uav_action_size` in turn)."""
        return self.n * self.uav_action_size

    # -------------------------------------------------------------------------- episodes
    def seed(self, seeds: list[int | None]) -> None:
        self.rngs = [np.random.default_rng(s) for s in seeds]

    def reset(self, which: np.ndarray | None = None) -> None:
        """The formations in `which` (all by default) back to their start, new targets; with
        start_speed, every body of each given one common velocity (its own generator)."""
        which = np.ones(self.batch, dtype=bool) if which is None else which
        self.engine.reset(which)
        self.targets.reset(which, self.rngs)
        if self.options.start_speed > 0:
            state = self.engine.state
            for b in np.flatnonzero(which):
                direction = self.rngs[b].normal(size=3)
                speed = self.options.start_speed * self.rngs[b].uniform() ** (1 / 3)
                velocity = speed * direction / np.linalg.norm(direction)
                self.layout.uav_velocities(state[b])[:] += velocity
                self.layout.payload_velocity(state[b])[:] += velocity
        self.tension[which] = 0.0
        self._expert_at = None

    def speeds(self, actions: np.ndarray,
               states: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Actions (B, action_size) in [-1, 1] (clipped) -> rotor speeds (B, n, rotors)
        [rad/s] and which sit at a vehicle limit (saturated), in this batch's action mode; the
        rate loop of thrust_body_rates at the measured `states` (B, n, UAV_STATE_SIZE), the
        engine's own by default."""
        a = self._uav_actions(actions)
        if self.reel_limits is not None:
            a = a[:, :, :-1]   # the reel rates: `step`
        if self.options.action_mode == 'rotor_speeds':
            speeds = centred(a, self.speed_hover, self.speed_min, self.speed_max)
            return speeds, (speeds <= self.speed_min) | (speeds >= self.speed_max)
        a = np.clip(a, -1.0, 1.0)
        # symmetric about hover (zero-mean exploration keeps the mean thrust), at least 0
        span = self.thrust_max - self.thrust_hover
        thrust = np.maximum(self.thrust_hover + a[:, :, 0] * span, 0.0)
        rates = np.ascontiguousarray(a[:, :, 1:] * self.options.body_rate_limit)
        speeds = np.empty((self.batch, self.n, self.rotors))
        saturated = np.empty(speeds.shape, dtype=bool)
        self._rate_commands(self.engine.arrays.cascade, self.engine.memory.mixers,
                            self.engine.measured() if states is None
                            else np.ascontiguousarray(states, dtype=float),
                            rates, thrust, speeds, saturated)
        return speeds, saturated

    def _uav_actions(self, actions: np.ndarray) -> np.ndarray:
        """Actions (B, action_size) as (B, n, uav_action_size), or a ValueError."""
        a = np.asarray(actions, dtype=float)
        if a.shape != (self.batch, self.action_size):
            raise ValueError(f'actions must be ({self.batch}, {self.action_size}) in '
                             f'action_mode {self.options.action_mode!r}'
                             f'{" with winch_actions" if self.reel_limits is not None else ""}'
                             f', got {a.shape}')
        return a.reshape(self.batch, self.n, self.uav_action_size)

    def actions(self, speeds: np.ndarray) -> np.ndarray:
        """Rotor speeds (B, n, rotors) [rad/s] -> `rotor_speeds` actions (B, n * rotors)."""
        a = uncentred(speeds, self.speed_hover, self.speed_min, self.speed_max)
        return a.reshape(self.batch, self.n * self.rotors)

    def expert_actions(self) -> np.ndarray:
        """The scenario's own controllers' answer (seed Ch. 3: the leader's cascade, the
        followers' virtual-constraint law) at each formation's current tick, as rotor_speeds
        actions. The controllers' memories advance once per tick: asked again before the next
        step, the same actions come back."""
        if self.options.action_mode != 'rotor_speeds':
            raise ValueError('the baseline answers in rotor speeds: action_mode '
                             f'{self.options.action_mode!r} has no expert action')
        tick = self.engine.memory.tick
        if self._expert_at is None or not np.array_equal(self._expert_at, tick):
            speeds, _ = self.engine.answer()
            self._expert[:] = self.actions(speeds)
            self._expert_at = tick.copy()
        if self.reel_limits is None:
            return self._expert.copy()
        # with winch_actions: each UAV's reel rate as the scenario commands it now (events)
        reels = self.engine.memory.reel[:, :, REEL_COMMAND] / self.reel_limits
        return np.concatenate([self._expert.reshape(self.batch, self.n, self.rotors),
                               reels[:, :, None]], axis=2).reshape(self.batch, -1)

    def step(self, actions: np.ndarray, which: np.ndarray | None = None) -> np.ndarray:
        """One control tick of every running formation (those in `which`) under `actions`;
        returns the rotor speeds commanded (B, n, rotors) [rad/s]."""
        speeds, saturated = self.speeds(actions)
        if self.reel_limits is not None:  # each winch's reel rate [m/s] (physics.winch)
            rows = slice(None) if which is None else np.asarray(which, dtype=bool)
            rates = np.clip(self._uav_actions(actions)[:, :, -1], -1.0, 1.0) * self.reel_limits
            self.engine.memory.reel[rows, :, REEL_COMMAND] = rates[rows]
        tension = self.engine.step_commanded(speeds, saturated, which)
        if which is None:
            self.tension[:] = tension
        else:
            self.tension[which] = tension[which]
        return speeds

    # ----------------------------------------------------------------------- what they see
    def observe(self) -> tuple[np.ndarray, dict]:
        """Observations (B, size) float32 of the engine's formations, and the pieces the
        reward and the ends use (float64). With an estimator the UAVs' rows are their
        estimates (`engine.measured`) and with `payload_estimator:` the payload's too; the
        reward and the ends read the true payload."""
        state = self.engine.state
        truth = self.layout.payload_position(state), self.layout.payload_velocity(state)
        estimate = self.engine.payload_estimates()
        observation, seen = self.observation_of(
            self.engine.measured(), *(truth if estimate is None else estimate), self.tension,
            self.engine.t)
        if estimate is not None:  # observed: the estimate; the reward and the ends: the truth
            target, target_velocity = self.targets.at(self.engine.t)
            seen.update(position_error=truth[0] - target,
                        velocity_error=truth[1] - target_velocity, payload=truth[0].copy())
        return observation, seen

    def observation_of(self, measured: np.ndarray, payload: np.ndarray,
                       payload_velocity: np.ndarray, tension: np.ndarray,
                       t: np.ndarray) -> tuple[np.ndarray, dict]:
        """`observe` from measured UAV states (B, n, UAV_STATE_SIZE), the payload's position
        and velocity (B, 3), the last tick's cable tensions (B, n) [N] at times t (B,) [s]: what
        a node computes from /formation/snapshot (multilift_learning.ros.policy_node)."""
        target, target_velocity = self.targets.at(t)
        positions = measured[:, :, UAV_POSITION:UAV_POSITION + 3]
        cable = positions - payload[:, None, :]
        cable /= np.linalg.norm(cable, axis=2, keepdims=True)
        per_uav = np.concatenate([
            positions - (target[:, None, :] + self.start_offsets),
            measured[:, :, UAV_VELOCITY:UAV_VELOCITY + 3] - target_velocity[:, None, :],
            measured[:, :, UAV_EULER:UAV_EULER + 3],
            measured[:, :, UAV_BODY_RATES:UAV_BODY_RATES + 3],
            cable,
            (tension / self.tension_share)[:, :, None]], axis=2)
        position_error = payload - target
        velocity_error = payload_velocity - target_velocity
        raw = np.concatenate([per_uav.reshape(self.batch, -1), position_error, velocity_error],
                             axis=1)
        return finished_observation(raw, self.scales), {
            'position_error': position_error, 'velocity_error': velocity_error,
            'measured': measured.copy(), 'payload': payload.copy()}

    def reward(self, seen: dict, speeds: np.ndarray,
               terminated: np.ndarray) -> tuple[np.ndarray, dict]:
        """Each formation's reward (B,) in [0, 1] for a tick flown at rotor `speeds` (B, n,
        rotors) [rad/s], 0 where it `terminated`, and its terms {name: (B,)}."""
        g = np.where(self.engine.memory.taut, np.abs(self.engine.memory.g), 0.0)
        terms = {
            'tracking': np.linalg.norm(seen['position_error'], axis=1),
            'swing': np.linalg.norm(seen['velocity_error'][:, :2], axis=1),
            'effort': np.mean(((speeds - self.speed_hover) / self.speed_max) ** 2,
                              axis=(1, 2)),
            'health': g.max(axis=1) / self.tolerance,
        }
        cost = sum(REWARD_WEIGHTS[name] * value for name, value in terms.items())
        reward = np.where(terminated | ~np.isfinite(cost), 0.0, np.exp(-cost))
        return reward, terms

    def ends(self, seen: dict) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """(terminated, truncated) (B,) bool each, and each formation's reason for
        terminating ('' where it did not: TERMINATIONS, a physical failure with Algorithm 1's
        words)."""
        measured = seen['measured']
        roll, pitch = measured[:, :, UAV_EULER], measured[:, :, UAV_EULER + 1]
        with np.errstate(invalid='ignore'):
            tilted = (np.cos(roll) * np.cos(pitch) < np.cos(self.options.tilt_limit)).any(axis=1)
            lowest = np.minimum(measured[:, :, UAV_POSITION + 2].min(axis=1),
                                seen['payload'][:, 2])
            grounded = lowest < self.ground
            away = np.linalg.norm(seen['position_error'], axis=1) > self.options.bound
        stopped = self.engine.stopped
        ended = stopped | tilted | grounded | away
        reasons = [''] * self.batch
        for b in np.flatnonzero(ended):
            if stopped[b]:
                reasons[b] = f'physical failure: {self.engine.stop_reason(b)}'
            elif tilted[b]:
                reasons[b] = f'tilt limit: a UAV tilted beyond {self.options.tilt_limit_deg} deg'
            elif grounded[b]:
                reasons[b] = f'ground contact: below z = {self.ground[b]:.2f} m'
            else:
                reasons[b] = f'bound: the payload beyond {self.options.bound} m of its target'
        terminated = ended
        truncated = self.engine.finished & ~terminated
        return terminated, truncated, reasons


def _reel_limits(scenarios: list[Scenario]) -> np.ndarray:
    """Each UAV's winch's rate_limit (B, n) [m/s], or a ValueError naming winch_actions when a
    UAV carries none."""
    for s in scenarios:
        bare = [i + 1 for i, u in enumerate(s.uavs) if u.winch is None]
        if bare:
            raise ValueError(f'winch_actions needs a winch on every UAV (uavs[i].winch): '
                             f'scenario {s.name!r} has none on uav{bare[0]}')
    return np.array([[u.winch.rate_limit for u in s.uavs] for s in scenarios])
