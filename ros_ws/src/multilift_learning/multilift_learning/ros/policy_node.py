"""policy_node: a policy trained on the learning environments flies a ROS run.

    scripts/multilift run SCENARIO --external uav1,uav2[,...] [--bag DIR]
    scripts/multilift node multilift_learning policy_node --ros-args -p scenario:=SCENARIO \\
        [-p task:=mission] [-p policy:=baseline | -p policy:=my_package.my_module:act |
         -p policy:=npz:PATH]

Each `/formation/snapshot` (every UAV's state at t) becomes the environment's observation at t
(`FormationBatch.observation_of`: the same slots and target, and the tension the environment
shows at t, the tick's before t: the node waits for that tick's `/formation/state`); the
policy, a plain callable `act(observation) -> action` (a numpy array of
`FormationEnv.observation_space`'s shape in, one of its action space out), gives the action,
its rotor speeds published as each UAV's `/uav{i}/rotor_cmd` stamped t. `policy:=baseline` is
the seed's controllers (`expert_action`); `npz:PATH` a trained policy file
(`multilift_learning.policies.load`; its environment's action_mode and normalise are used). The
node commands every UAV of the formation, so the run names them all `--external`. Parameters:
scenario, task (hover's target is its rest place: the radius is 0), policy, record (wait for
the recorder's subscriptions, as our controllers).
"""
from __future__ import annotations

import importlib
from typing import Callable, NoReturn

import numpy as np
from multilift_msgs.msg import FormationSnapshot, FormationState, RotorCommand
from rclpy.node import Node

from multilift_control.answer_messages import AnswerMessages
from multilift_learning import policies
from multilift_learning.env import formation_batch
from multilift_sim.wire import cdr
from multilift_sim.ros.common import (FIRST_ACK_TIMEOUT, PUBLISHER_QOS, SUBSCRIBER_QOS, Fatal,
                                      RawPublishers, controller_peers_missing, run_node,
                                      serve_controllers)
from multilift_sim.topics import FORMATION_SNAPSHOT, FORMATION_STATE, ROTOR_CMD, uav_topic

Policy = Callable[[np.ndarray], np.ndarray]


def load_policy(spec: str) -> Policy | None:
    """`module:callable` or `npz:PATH` -> the callable; 'baseline' -> None (the seed's
    controllers)."""
    if spec == 'baseline':
        return None
    module, _, name = spec.partition(':')
    if module == 'npz':
        try:
            return policies.load(name)
        except ValueError as error:
            raise Fatal(f'policy {spec!r}: {error}') from None
    if not module or not name:
        raise Fatal(f'policy {spec!r}: expected baseline, MODULE:CALLABLE or npz:PATH')
    try:
        policy = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as error:
        raise Fatal(f'policy {spec!r}: {error}') from None
    if not callable(policy):
        raise Fatal(f'policy {spec!r} is not callable')
    return policy


class PolicyNode(Node):
    def __init__(self) -> None:
        super().__init__('policy')
        name = self.declare_parameter('scenario', '').value
        task = self.declare_parameter('task', 'mission').value
        self.policy_spec = self.declare_parameter('policy', 'baseline').value
        self.policy = load_policy(self.policy_spec)
        self.record = bool(self.declare_parameter('record', False).value)
        self.summary_dir = ''
        if not name:
            raise Fatal('parameter "scenario" is required (a name in scenarios/ or a path)')
        options = {'target_radius': 0.0}
        if isinstance(self.policy, policies.MlpPolicy):
            trained = self.policy.environment.get('options', {})
            options.update({key: trained[key] for key in ('action_mode', 'normalise',
                                                           'start') if key in trained})
        try:
            self.batch = formation_batch([name], task, None, options)
        except ValueError as error:
            raise Fatal(str(error)) from None
        if isinstance(self.policy, policies.MlpPolicy):
            size = len(self.batch.observe()[0][0])
            if (self.policy.observation_size, self.policy.action_size) != (
                    size, self.batch.action_size):
                raise Fatal(f'policy {self.policy_spec!r} maps {self.policy.observation_size} '
                            f'observations to {self.policy.action_size} actions; {name} '
                            f'({task}) has {size} and {self.batch.action_size}')
        self.batch.reset()
        self.compile_answer(formation_batch([name], task, None, options))
        scenario = self.batch.scenarios[0]
        n = self.batch.n
        self.period_ns = int(self.batch.engine.arrays.period_ns[0])
        self.packer = AnswerMessages(scenario)
        self.snapshot = cdr.FormationSnapshot([u.vehicle.n_rotors for u in scenario.uavs])
        self.tension = np.zeros((1, n))
        self.cmd_pubs = [self.create_publisher(RotorCommand, uav_topic(i, ROTOR_CMD),
                                               PUBLISHER_QOS) for i in range(1, n + 1)]
        self.outputs = RawPublishers(*self.cmd_pubs,
                                     confirm_first=FIRST_ACK_TIMEOUT if self.record else 0.0)
        self.create_subscription(FormationState, FORMATION_STATE, self.on_formation_state,
                                 SUBSCRIBER_QOS)
        self.create_subscription(FormationSnapshot, FORMATION_SNAPSHOT, self.on_snapshot,
                                 SUBSCRIBER_QOS, raw=True)
        self.answered = 0
        self.pending: bytes | None = None   # a snapshot waiting for its tick's tension
        self.tension_ns = -1                # the stamp of the tension held [ns]

    def compile_answer(self, batch) -> None:
        """The compiled calls of `answer` made once, on `batch` (a throwaway batch of the same
        scenario), before the node joins the graph: the engine's and the learning calls'
        kernels, which scripts/setup leaves to their first use, compile here (tens of seconds
        on a cold cache, a fraction of one from the cache), not at the first snapshot, which
        the simulator waits for `command_timeout` (5 s) only. The policy itself is not called
        (a user's callable may note what it sees)."""
        batch.reset()
        measured = np.array(batch.engine.measured())
        if self.policy is None:
            batch.engine.answer(measured)
            return
        state = batch.engine.state
        batch.observation_of(measured, np.array(batch.layout.payload_position(state)),
                             np.array(batch.layout.payload_velocity(state)),
                             np.zeros((1, batch.n)), np.zeros(1))
        batch.speeds(np.zeros((1, batch.action_size)), measured)

    def missing_peers(self) -> str | None:
        for pub in self.cmd_pubs:
            what = controller_peers_missing(self, pub, self.record)
            if what is not None:
                return what
        return None

    def on_formation_state(self, msg: FormationState) -> None:
        """The tensions of the tick stamped (the integration that started there), the ones
        the environment shows at the next tick; a snapshot waiting for them is answered."""
        self.tension[0] = msg.cable_tension
        self.tension_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        if self.pending is not None:
            self.on_snapshot(self.pending)

    def on_snapshot(self, data: bytes) -> None:
        """Answer the snapshot at t once the tension of tick t - 1 is here (at once at 0)."""
        t_ns = self.snapshot.unpack(data)[0]
        if t_ns > 0 and self.tension_ns != t_ns - self.period_ns:
            self.pending = data
            return
        self.pending = None
        if t_ns == 0:
            self.tension[0] = 0.0
        self.answer(data)

    def answer(self, data: bytes) -> None:
        t_ns, position, velocity, euler, rates, payload, payload_velocity, _ = \
            self.snapshot.unpack(data)
        n = self.batch.n
        measured = np.concatenate([position.reshape(n, 3), velocity.reshape(n, 3),
                                   euler.reshape(n, 3), rates.reshape(n, 3)], axis=1)[None]
        engine = self.batch.engine
        engine.memory.tick[0] = t_ns // self.period_ns
        if self.policy is None:
            speeds, saturated = engine.answer(measured)
            speeds, saturated = speeds[0], saturated[0].tolist()
        else:
            observation, _ = self.batch.observation_of(
                measured, np.asarray(payload)[None], np.asarray(payload_velocity)[None],
                self.tension, np.array([t_ns * 1e-9]))
            action = np.asarray(self.policy(observation[0]), float)[None]
            speeds, saturated = self.batch.speeds(action, measured)
            speeds, saturated = speeds[0], saturated[0].tolist()
        messages = []
        for i in range(n):
            messages += self.packer.command_of(i, t_ns, speeds[i].tolist(), saturated[i])
        self.outputs.send(messages)
        self.answered += 1


def main(args: list[str] | None = None) -> NoReturn:
    run_node(PolicyNode, lambda node: serve_controllers(
        [node], lambda n: ('policy', {'answered': n.answered})), args)


if __name__ == '__main__':
    main()
