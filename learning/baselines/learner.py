"""What the deep baselines share: epsilon-greedy acting, a replay of examples grouped by component
count (a batch must hold puzzles of one size), seeded sampling, and the ``Agent`` protocol plumbing.
Subclasses say how to act greedily, what an example is, and how to learn from a batch."""

from __future__ import annotations

import random
from collections import defaultdict, deque
from typing import Any

import numpy as np
import torch

from learning.baselines.graph_network import observation_tensors
from models import SceneObservation


class EpsilonGreedyLearner:
    """Base of the deep agents. ``config`` needs: network, batch_size, replay_size, epsilon_start,
    epsilon_decay, epsilon_min, epsilon_eval, updates_per_action, seed."""

    name = "learner"

    def __init__(self, config: Any) -> None:
        self.config = config
        torch.manual_seed(config.seed)
        self.replay: dict[int, deque] = defaultdict(lambda: deque(maxlen=config.replay_size))
        self.epsilon = config.epsilon_start
        self.training = True
        self.episodes = 0
        self._sample_rng = random.Random(config.seed)
        self._rng = np.random.default_rng(0)
        self._last: tuple[np.ndarray, np.ndarray] | None = None

    # -- to provide --------------------------------------------------------------------------------
    def greedy_values(self, observation: SceneObservation) -> np.ndarray:
        """Value of trying each component (higher is better)."""
        raise NotImplementedError

    def example(self, index: int, moved: bool, observation: SceneObservation) -> Any:
        """The replay entry for trying ``index`` from the last observation."""
        raise NotImplementedError

    def learn(self, batch: list) -> float:
        """One gradient step on a batch; the loss."""
        raise NotImplementedError

    # -- the Agent protocol ------------------------------------------------------------------------
    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        self._rng = rng

    def choose(self, observation: SceneObservation) -> int:
        self._last = observation_tensors(observation, self.config.network.position_scale)
        epsilon = self.epsilon if self.training else self.config.epsilon_eval
        if self._rng.random() < epsilon:
            return int(self._rng.integers(len(observation)))
        values = self.greedy_values(observation)
        return int(self._rng.choice(np.flatnonzero(values >= values.max() - 1e-9)))

    def record(self, index: int, moved: bool, observation: SceneObservation) -> None:
        if not self.training or self._last is None:
            return
        self.replay[len(self._last[0])].append(self.example(index, moved, observation))
        for _ in range(self.config.updates_per_action):
            self.update()

    def end_episode(self, solved: bool) -> None:
        if self.training:
            self.episodes += 1
            self.epsilon = max(self.config.epsilon_min, self.epsilon * self.config.epsilon_decay)

    def update(self) -> float | None:
        """One gradient step on a replay batch of one component count; None until a batch is available."""
        sizes = [n for n, buffer in self.replay.items() if len(buffer) >= self.config.batch_size]
        if not sizes:
            return None
        buffer = self.replay[self._sample_rng.choice(sizes)]
        return self.learn(self._sample_rng.sample(list(buffer), self.config.batch_size))
