"""Trained policies as plain numpy: a multilayer perceptron in one `.npz` file, flown without the
library that trained it (`examples/learning/train_ppo.py` writes one; `policy_node -p
policy:=npz:PATH` flies it through ROS).

    act = multilift_learning.policies.load('runs/ppo/policy.npz')
    action = act(observation)            # (size,) -> (action_size,), or (B, size) -> (B, ...)

The file's arrays: `weights_k` (inputs, outputs) and `biases_k` (outputs,) for layers k = 0..L-1;
`activation` (of every hidden layer: tanh or relu; the last layer is linear, its output
clipped to the action space [-1, 1]); `observation_mean`, `observation_std` and
`observation_clip` (the observation normalisation the learner applied: (o - mean) / std,
clipped to +-clip; mean 0, std 1, clip inf for none); `environment` (JSON: the environment's id
and the arguments it was trained with, `action_mode` and `normalise` among them, which a node
flying it needs).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from multilift_learning.observations import agent_observation_slots

ACTIVATIONS = {'tanh': np.tanh, 'relu': lambda x: np.maximum(x, 0.0)}


@dataclass(frozen=True)
class MlpPolicy:
    """A policy `act(observations) -> actions`: normalise, the layers, clip to [-1, 1]."""
    weights: tuple[np.ndarray, ...]
    biases: tuple[np.ndarray, ...]
    activation: str
    observation_mean: np.ndarray
    observation_std: np.ndarray
    observation_clip: float
    environment: dict = field(default_factory=dict)

    @property
    def observation_size(self) -> int:
        return self.weights[0].shape[0]

    @property
    def action_size(self) -> int:
        return self.weights[-1].shape[1]

    def __call__(self, observations: np.ndarray) -> np.ndarray:
        o = np.asarray(observations, dtype=np.float64)
        if o.shape[-1:] != (self.observation_size,):
            raise ValueError(f'observations of shape {o.shape}: this policy takes '
                             f'({self.observation_size},) or (B, {self.observation_size})')
        x = np.clip((o - self.observation_mean) / self.observation_std,
                    -self.observation_clip, self.observation_clip)
        hidden = ACTIVATIONS[self.activation]
        for k, (w, b) in enumerate(zip(self.weights, self.biases)):
            x = x @ w + b
            if k < len(self.weights) - 1:
                x = hidden(x)
        return np.clip(x, -1.0, 1.0)


def shared_by_agents(policy, n: int):
    """A policy of one agent (the PettingZoo env's: its UAV's observation slots and the
    payload's -> its UAV's actions) flown by every UAV of a formation of n, its parameters
    shared: `act(observations (B, size)) -> actions (B, n * agent actions)`."""
    slots = agent_observation_slots(n)

    def act(observations: np.ndarray) -> np.ndarray:
        o = np.asarray(observations)
        batch = o.reshape(-1, o.shape[-1])
        actions = policy(batch[:, slots].reshape(batch.shape[0] * n, -1))
        return actions.reshape(o.shape[:-1] + (-1,))
    return act


def save(path: str | Path, policy: MlpPolicy) -> Path:
    """`policy` to the .npz file `path` (load's format)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {f'weights_{k}': w for k, w in enumerate(policy.weights)}
    arrays.update({f'biases_{k}': b for k, b in enumerate(policy.biases)})
    np.savez(path, activation=np.array(policy.activation),
             observation_mean=policy.observation_mean, observation_std=policy.observation_std,
             observation_clip=np.array(policy.observation_clip),
             environment=np.array(json.dumps(policy.environment)), **arrays)
    return path


def load(path: str | Path) -> MlpPolicy:
    """The policy of the .npz file `path`; a ValueError naming the file and the array that is
    missing or of the wrong shape."""
    path = Path(path)
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as error:
        raise ValueError(f'policy file {path}: {error}') from None
    with data:
        def array(name: str) -> np.ndarray:
            if name not in data.files:
                raise ValueError(f'policy file {path}: no array {name!r}')
            return data[name]
        layers = sum(1 for name in data.files if name.startswith('weights_'))
        if layers == 0:
            raise ValueError(f'policy file {path}: no layers (weights_0, biases_0, ...)')
        weights = tuple(array(f'weights_{k}').astype(np.float64) for k in range(layers))
        biases = tuple(array(f'biases_{k}').astype(np.float64) for k in range(layers))
        for k, (w, b) in enumerate(zip(weights, biases)):
            inputs = weights[k - 1].shape[1] if k else None
            if w.ndim != 2 or (inputs is not None and w.shape[0] != inputs):
                raise ValueError(f'policy file {path}: weights_{k} has shape {w.shape}, '
                                 f'expected ({inputs if k else "inputs"}, outputs)')
            if b.shape != (w.shape[1],):
                raise ValueError(f'policy file {path}: biases_{k} has shape {b.shape}, '
                                 f'expected ({w.shape[1]},)')
        size = weights[0].shape[0]
        mean = array('observation_mean').astype(np.float64)
        std = array('observation_std').astype(np.float64)
        for name, value in (('observation_mean', mean), ('observation_std', std)):
            if value.shape != (size,):
                raise ValueError(f'policy file {path}: {name} has shape {value.shape}, '
                                 f'expected ({size},)')
        if not (std > 0).all():
            raise ValueError(f'policy file {path}: observation_std must be > 0')
        activation = str(array('activation'))
        if activation not in ACTIVATIONS:
            raise ValueError(f'policy file {path}: activation {activation!r}: one of '
                             f'{", ".join(ACTIVATIONS)}')
        clip = float(array('observation_clip'))
        environment = json.loads(str(array('environment')))
    return MlpPolicy(weights, biases, activation, mean, std,
                     clip if clip > 0 else math.inf, environment)
