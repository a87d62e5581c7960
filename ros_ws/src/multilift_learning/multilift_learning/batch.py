"""B formations of one task on the batched engine, as the environments see them: actions in,
observations, rewards and episode ends out, every array with the batch axis first. The one
place that defines them (`FormationEnv` is B = 1, `FormationVectorEnv` B = num_envs).

Action, per formation: every rotor's speed, normalised, flat (n * rotors,) in [-1, 1]:
omega = omega_min + (a + 1) / 2 (omega_max - omega_min) with each vehicle's rotor_speed_min
and rotor_speed_max [rad/s], UAV by UAV (uav1's rotors first); held over one control period.

Observation, per formation, flat (OBSERVATION_PER_UAV n + OBSERVATION_PAYLOAD,), world frame z
up, SI units; for each UAV i (uav1 first, `observation_names` names every slot):
- position error [m]: its position less the payload's target plus its start offset from the
  payload's rest place (where it would be, the formation kept, with the payload on target);
- velocity less the target's [m/s];
- roll, pitch, yaw [rad]; body rates [rad/s] (FLU);
- cable direction, the unit vector from the payload to the UAV;
- cable tension of the last tick over its static share m_p g / n (0 before the first tick);
then the payload's position error [m] and velocity error [m/s].

Reward, per tick: ALIVE - sum of weight * term (REWARD_WEIGHTS):
- tracking: |payload position error| [m];
- swing: |horizontal payload velocity error| [m/s];
- effort: mean over rotors of ((omega - omega_hover) / omega_max)^2, omega_hover the speed at
  which a UAV's rotors carry its weight and its share of the payload's;
- health: max over cables of |g_i| / constraint_tolerance (the seed's Eq. 2.59 residual).

An episode terminates when Algorithm 1 stops the formation (non-finite state, |g| or |g_dot|
beyond tolerance) or a UAV rolls or pitches past 90 deg (a crash: the world has no ground, its
origin is the leader's start, docs/conventions.md); it is truncated at the scenario's
duration.
"""
from __future__ import annotations

import numpy as np

from multilift_control import laws
from multilift_control.engine import Engine
from multilift_control.laws.layout import (UAV_BODY_RATES, UAV_EULER, UAV_POSITION,
                                           UAV_VELOCITY)
from multilift_learning.tasks import Targets, task, task_scenario
from multilift_sim.formation_params import StateLayout
from multilift_sim.scenario import Scenario
from multilift_sim.start import cable_reach
from multilift_sim.statistics.swing import equilibrium_point

OBSERVATION_PER_UAV = 16
OBSERVATION_PAYLOAD = 6
ALIVE = 1.0
REWARD_WEIGHTS = {'tracking': 1.0, 'swing': 0.5, 'effort': 0.1, 'health': 1.0}


def observation_names(n: int) -> list[str]:
    """The name of every observation slot of a formation of n UAVs."""
    names = []
    for i in range(1, n + 1):
        names += [f'uav{i}.position_error.{a}' for a in 'xyz']
        names += [f'uav{i}.velocity_error.{a}' for a in 'xyz']
        names += [f'uav{i}.{a}' for a in ('roll', 'pitch', 'yaw')]
        names += [f'uav{i}.body_rate.{a}' for a in 'xyz']
        names += [f'uav{i}.cable_direction.{a}' for a in 'xyz']
        names += [f'uav{i}.tension_ratio']
    names += [f'payload.position_error.{a}' for a in 'xyz']
    names += [f'payload.velocity_error.{a}' for a in 'xyz']
    return names


class FormationBatch:
    """B formations (`scenarios`, of the same shape) of task `task_name` on one Engine."""

    def __init__(self, scenarios: list[Scenario], task_name: str, target_radius: float = 0.5):
        kind = task(task_name)
        if kind.needs_mission and any(s.control.mode != 'cascade' for s in scenarios):
            raise ValueError(f'task {task_name!r} needs a scenario whose leader flies its '
                             'mission (control.mode: cascade)')
        scenarios = [task_scenario(s, task_name) for s in scenarios]
        self.scenarios = scenarios
        self.engine = Engine(scenarios)
        self.batch = self.engine.batch
        self.n = self.engine.n_uavs
        self.rotors = self.engine.arrays.allocation.shape[-1]
        n = self.n
        limits = np.array([[(u.vehicle.rotor_speed_min, u.vehicle.rotor_speed_max)
                            for u in s.uavs] for s in scenarios])        # (B, n, 2)
        self.speed_min = limits[:, :, :1]                                # (B, n, 1)
        self.speed_span = limits[:, :, 1:] - limits[:, :, :1]
        self.speed_max = limits[:, :, 1:]
        weight_share = np.array([[(u.vehicle.mass + s.payload.mass / n) * s.simulation.gravity
                                  for u in s.uavs] for s in scenarios])  # (B, n) [N]
        k_t = np.array([[u.vehicle.thrust_coefficient for u in s.uavs] for s in scenarios])
        self.speed_hover = np.sqrt(weight_share / (self.rotors * k_t))[:, :, None]
        self.tension_share = np.array([s.payload.mass * s.simulation.gravity / n
                                       for s in scenarios])[:, None]     # (B, 1) [N]
        self.tolerance = np.array([s.simulation.constraint_tolerance for s in scenarios])
        # the payload's rest place under the UAVs' start (not its start: a scenario may
        # release it swinging), and each UAV's offset from it (B, n, 3) [m]
        rest_place = laws.runnable(equilibrium_point)
        rest = np.array([rest_place(self.engine.positions[b], cable_reach(s))
                         for b, s in enumerate(scenarios)])
        self.start_offsets = self.engine.positions.copy() - rest[:, None, :]
        self.targets = Targets(task_name, self.engine, rest, self.start_offsets,
                               target_radius)
        self.tension = np.zeros((self.batch, n))
        self.rngs = [np.random.default_rng() for _ in range(self.batch)]
        self._expert_at: np.ndarray | None = None
        self._expert = np.zeros((self.batch, n * self.rotors))

    # -------------------------------------------------------------------------- episodes
    def seed(self, seeds: list[int | None]) -> None:
        self.rngs = [np.random.default_rng(s) for s in seeds]

    def reset(self, which: np.ndarray | None = None) -> None:
        """The formations in `which` (all by default) back to their start, new targets."""
        which = np.ones(self.batch, dtype=bool) if which is None else which
        self.engine.reset(which)
        self.targets.reset(which, self.rngs)
        self.tension[which] = 0.0
        self._expert_at = None

    def speeds(self, actions: np.ndarray) -> np.ndarray:
        """Normalised actions (B, n * rotors) in [-1, 1] (clipped) -> rotor speeds (B, n,
        rotors) [rad/s]."""
        a = np.clip(np.asarray(actions, dtype=float).reshape(self.batch, self.n, self.rotors),
                    -1.0, 1.0)
        return self.speed_min + (a + 1.0) * 0.5 * self.speed_span

    def at_limits(self, speeds: np.ndarray) -> np.ndarray:
        """Which rotor speeds (B, n, rotors) [rad/s] sit at a vehicle limit (saturated)."""
        return (speeds <= self.speed_min) | (speeds >= self.speed_max)

    def actions(self, speeds: np.ndarray) -> np.ndarray:
        """Rotor speeds (B, n, rotors) [rad/s] -> normalised actions (B, n * rotors)."""
        a = 2.0 * (speeds - self.speed_min) / self.speed_span - 1.0
        return a.reshape(self.batch, self.n * self.rotors)

    def expert_actions(self) -> np.ndarray:
        """The scenario's own controllers' answer (seed Ch. 3: the leader's cascade, the
        followers' virtual-constraint law) at each formation's current tick, as actions. The
        controllers' memories advance once per tick: asked again before the next step, the
        same actions come back."""
        tick = self.engine.memory.tick
        if self._expert_at is None or not np.array_equal(self._expert_at, tick):
            speeds, _ = self.engine.answer()
            self._expert[:] = self.actions(speeds)
            self._expert_at = tick.copy()
        return self._expert.copy()

    def step(self, actions: np.ndarray, which: np.ndarray | None = None) -> None:
        """One control tick of every running formation (those in `which`) under `actions`."""
        speeds = self.speeds(actions)
        tension = self.engine.step_commanded(speeds, self.at_limits(speeds), which)
        if which is None:
            self.tension[:] = tension
        else:
            self.tension[which] = tension[which]

    # ----------------------------------------------------------------------- what they see
    def observe(self) -> tuple[np.ndarray, dict]:
        """Observations (B, OBSERVATION_PER_UAV n + OBSERVATION_PAYLOAD) of the engine's
        formations, and the pieces the reward uses."""
        state, layout = self.engine.state, StateLayout(self.n)
        return self.observation_of(self.engine.measured(), layout.payload_position(state),
                                   layout.payload_velocity(state), self.tension, self.engine.t)

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
        observation = np.concatenate([per_uav.reshape(self.batch, -1), position_error,
                                      velocity_error], axis=1)
        return observation, {'position_error': position_error, 'velocity_error': velocity_error,
                             'measured': measured, 'payload': payload}

    def reward(self, seen: dict, actions: np.ndarray) -> tuple[np.ndarray, dict]:
        """Each formation's reward (B,) and its terms {name: (B,)} (REWARD_WEIGHTS)."""
        speeds = self.speeds(actions)
        terms = {
            'tracking': np.linalg.norm(seen['position_error'], axis=1),
            'swing': np.linalg.norm(seen['velocity_error'][:, :2], axis=1),
            'effort': np.mean(((speeds - self.speed_hover) / self.speed_max) ** 2,
                              axis=(1, 2)),
            'health': np.abs(self.engine.memory.g).max(axis=1) / self.tolerance,
        }
        reward = ALIVE - sum(REWARD_WEIGHTS[name] * value for name, value in terms.items())
        return reward, terms

    def ends(self, seen: dict) -> tuple[np.ndarray, np.ndarray]:
        """(terminated, truncated) (B,) bool each."""
        tilt = seen['measured'][:, :, UAV_EULER:UAV_EULER + 2]
        crashed = (np.abs(tilt) > np.pi / 2).any(axis=(1, 2))
        terminated = self.engine.stopped | crashed
        truncated = self.engine.finished & ~terminated
        return terminated, truncated
