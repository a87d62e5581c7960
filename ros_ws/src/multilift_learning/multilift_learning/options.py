"""`TaskOptions`: what a learning environment's constructor takes beyond the scenario and the
task, validated once (a bad value is a ValueError naming the parameter and what it accepts).

    gymnasium.make('multilift/Hover-v0', action_mode='thrust_body_rates', normalise=True,
                   duration=20.0, start='rest', ground_height=None, bound=5.0)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from multilift_sim.registry import one_of

# the action modes (multilift_learning.batch): every rotor's speed, or per UAV a collective
# thrust and three body rates with the attitude-rate loop inside (laws.body_rates)
ACTION_MODES = ('rotor_speeds', 'thrust_body_rates')
# where an episode starts: the payload hanging still at its rest place under the UAVs
# ('rest'), or released as the scenario says (twin_lift: swinging 15 deg, 2.6 m off)
STARTS = ('rest', 'scenario')


@dataclass(frozen=True)
class TaskOptions:
    """The options of a learning task, SI units, world frame z up.

    action_mode: one of ACTION_MODES. normalise: observations divided by their scales
    (`batch.observation_scales`) and clipped to +-OBSERVATION_CLIP. duration [s]: the
    episode's length (None: the scenario's). target_radius [m]: hover's targets drawn in a
    disc of it about the payload's rest place. start: one of STARTS. ground_height [m]: world z
    of the ground (None: GROUND_BELOW_REST below the payload's rest place); a UAV or the payload
    below it ends the episode. bound [m]: the payload farther than this from its target ends
    the episode. tilt_limit_deg [deg]: a UAV tilted more (the angle between its thrust axis and
    the vertical) ends it. body_rate_limit [rad/s]: the body rate an action of 1 asks
    (thrust_body_rates). start_speed [m/s]: every body starts with one common velocity drawn
    uniformly in a ball of this radius (0: at rest). winch_actions: each UAV's action gains a
    last entry, its winch's reel rate (1: its rate_limit, paying out; -1 reeling in; physics.
    winch keeps the acceleration limit and the stops): for a scenario whose every UAV carries a
    winch (`uavs[i].winch`, e.g. winch_lower).
    """
    action_mode: str = 'rotor_speeds'
    normalise: bool = False
    duration: float | None = None
    target_radius: float = 0.5
    start: str = 'rest'
    ground_height: float | None = None
    bound: float = 5.0
    tilt_limit_deg: float = 60.0
    body_rate_limit: float = 1.0
    start_speed: float = 0.0
    winch_actions: bool = False

    def __post_init__(self) -> None:
        one_of('action_mode', self.action_mode, ACTION_MODES)
        one_of('start', self.start, STARTS)
        for name in ('normalise', 'winch_actions'):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f'{name} must be True or False, got {getattr(self, name)!r}')
        _positive('duration', self.duration, allow_none=True)
        _at_least_zero('target_radius', self.target_radius)
        _positive('bound', self.bound)
        _positive('body_rate_limit', self.body_rate_limit)
        _at_least_zero('start_speed', self.start_speed)
        if not (isinstance(self.tilt_limit_deg, (int, float))
                and 0 < self.tilt_limit_deg < 90):
            raise ValueError(f'tilt_limit_deg must be in (0, 90) [deg] (the seed\'s angles '
                             f'are singular at 90), got {self.tilt_limit_deg!r}')
        if self.ground_height is not None and not _finite(self.ground_height):
            raise ValueError(f'ground_height must be a finite height [m] or None, got '
                             f'{self.ground_height!r}')

    @property
    def tilt_limit(self) -> float:
        """tilt_limit_deg [rad]."""
        return math.radians(self.tilt_limit_deg)


# the ground's default height below the payload's rest place [m] (ground_height None)
GROUND_BELOW_REST = 2.0


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(
        value)


def _positive(name: str, value, allow_none: bool = False) -> None:
    if value is None and allow_none:
        return
    if not _finite(value) or value <= 0:
        raise ValueError(f'{name} must be a number > 0, got {value!r}')


def _at_least_zero(name: str, value) -> None:
    if not _finite(value) or value < 0:
        raise ValueError(f'{name} must be a number >= 0, got {value!r}')
