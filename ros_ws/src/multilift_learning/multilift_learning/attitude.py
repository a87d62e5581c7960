"""`AttitudeActions`: the other action choice of the issue, attitude set-points and thrust per
UAV instead of rotor speeds. Each UAV's own attitude loop and mixer (the cascade's inner half,
`multilift_control.laws.cascade.attitude_command`, the scenario's gains) turn them into rotor
speeds at every tick, as a flight controller under an offboard computer does.

Action, per formation: (n * 4,) in [-1, 1], UAV by UAV (roll, pitch, yaw, thrust): roll and
pitch a * control.max_tilt, yaw a * pi [rad], thrust (a + 1) / 2 of the vehicle's largest
(k_T rotors omega_max^2) [N].
"""
from __future__ import annotations

import gymnasium
import numpy as np


class AttitudeActions(gymnasium.ActionWrapper):
    """A `FormationEnv` commanded by attitude set-points and thrust (see the module)."""

    def __init__(self, env: gymnasium.Env):
        super().__init__(env)
        self.batch = batch = env.unwrapped.batch
        scenario = batch.scenarios[0]
        self.max_tilt = scenario.control.max_tilt                                # [rad]
        self.max_thrust = np.array([u.vehicle.max_thrust for u in scenario.uavs])  # [N]
        self.action_space = gymnasium.spaces.Box(-1.0, 1.0, (batch.n * 4,), np.float64)

    def action(self, action: np.ndarray) -> np.ndarray:
        """Attitude action -> the rotor-speed action the environment takes."""
        a = np.clip(np.asarray(action, dtype=float).reshape(self.batch.n, 4), -1.0, 1.0)
        setpoints = np.stack([a[:, 0] * self.max_tilt, a[:, 1] * self.max_tilt,
                              a[:, 2] * np.pi], axis=1)
        thrust = (a[:, 3] + 1.0) * 0.5 * self.max_thrust
        speeds, _ = self.batch.engine.attitude_speeds(setpoints[None], thrust[None])
        return self.batch.actions(speeds)[0]

    def attitude_action(self, setpoints: np.ndarray, thrust: np.ndarray) -> np.ndarray:
        """Set-points (n, 3: roll, pitch, yaw [rad]) and thrust (n,) [N] -> this action."""
        a = np.empty((self.batch.n, 4))
        a[:, 0] = setpoints[:, 0] / self.max_tilt
        a[:, 1] = setpoints[:, 1] / self.max_tilt
        a[:, 2] = setpoints[:, 2] / np.pi
        a[:, 3] = 2.0 * thrust / self.max_thrust - 1.0
        return a.reshape(-1)
