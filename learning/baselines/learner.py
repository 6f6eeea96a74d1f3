"""What the deep baselines share: epsilon-greedy acting, a replay of examples grouped by component
count (a batch must hold puzzles of one size), optional success/failure balancing of the batches
(MT-OPT), seeded sampling, and the ``Agent`` protocol plumbing. Subclasses say how to act greedily,
what an example is, and how to learn from a batch."""

from __future__ import annotations

import math
import random
from collections import defaultdict, deque
from dataclasses import dataclass, field, fields
from typing import Any, Generic, Self, TypeVar

import numpy as np
import torch

from puzzlebox.learning.baselines.graph_network import GraphNetworkConfig, observation_tensors
from puzzlebox.learning.errors import ConfigError
from puzzlebox.models import SceneObservation, TryResult

MAX_SIZE = 2**32 - 1
"""Largest batch, replay buffer, update count or seed of a config."""


@dataclass(frozen=True)
class LearnerConfig:
    """What every deep agent is configured with (defaults: the authors' release)."""

    network: GraphNetworkConfig = field(default_factory=GraphNetworkConfig)
    learning_rate: float = 3e-4
    batch_size: int = 16
    replay_size: int = 100_000
    epsilon_start: float = 1.0
    epsilon_decay: float = 0.999
    """Multiplier of epsilon after every training episode."""
    epsilon_min: float = 0.2
    epsilon_eval: float = 0.1
    updates_per_action: int = 1
    share_across_tasks: bool = False
    """MT-OPT data sharing (what is shared is the agent's call: see ``multitask.py``)."""
    balance: bool = False
    """MT-OPT balancing: half of each batch successes, half failures (the agent says which is which)."""
    seed: int = 0

    def __post_init__(self) -> None:
        """Every number in its range, finite: a checkpoint's metadata is read back into this config, and a value
        out of range would fail late (a negative width in torch) or silently (``epsilon_eval`` NaN acts greedily
        at random, every run)."""
        for name, value in ((f.name, getattr(self, f.name)) for f in fields(self)):
            if isinstance(value, bool) or name == "network":
                continue
            if isinstance(value, float | int) and not math.isfinite(value):
                raise ConfigError(f"{name} must be finite, got {value!r}")
        for name in ("epsilon_start", "epsilon_min", "epsilon_eval", "gamma", "tau"):
            value = getattr(self, name, 0.0)
            if not 0.0 <= value <= 1.0:
                raise ConfigError(f"{name} must be in [0, 1], got {value!r}")
        if not 0.0 < self.epsilon_decay <= 1.0 or not self.learning_rate > 0:
            raise ConfigError(f"epsilon_decay must be in (0, 1] and learning_rate > 0, got {self.epsilon_decay!r} "
                              f"and {self.learning_rate!r}")  # fmt: skip
        for name, low in (("batch_size", 1), ("replay_size", 1), ("updates_per_action", 0), ("seed", 0)):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= MAX_SIZE:
                raise ConfigError(f"{name} must be an integer in [{low}, {MAX_SIZE}], got {value!r}")

    @classmethod
    def multitask(cls, **overrides: Any) -> Self:
        """The MT-OPT variant: data sharing and balancing on."""
        return cls(**{"share_across_tasks": True, "balance": True, **overrides})

    @property
    def is_multitask(self) -> bool:
        return self.share_across_tasks or self.balance


ConfigT = TypeVar("ConfigT", bound=LearnerConfig)
"""A deep agent's config class."""


class EpsilonGreedyLearner(Generic[ConfigT]):
    """Base of the deep agents, configured by a :class:`LearnerConfig` (or a subclass of it, ``ConfigT``); named
    ``base_name``, with an ``mt-`` prefix when the config turns MT-OPT on.

    The replay holds, per component count, two buffers: ``success`` and ``failure`` examples (what
    counts as a success is the subclass's call). Without ``balance`` a batch is drawn from both
    together, i.e. in the proportion they were collected; with it (MT-OPT's success/failure
    balancing) half of every batch comes from each as soon as both can fill their half.
    """

    base_name = "learner"

    def __init__(self, config: ConfigT) -> None:
        self.config = config
        self.name = f"mt-{self.base_name}" if config.is_multitask else self.base_name
        torch.manual_seed(config.seed)
        self.replay: dict[tuple[int, bool], deque] = defaultdict(lambda: deque(maxlen=config.replay_size))
        self.epsilon = config.epsilon_start
        self.training = True
        self.episodes = 0
        self._sample_rng = random.Random(config.seed)
        self._rng = np.random.default_rng(0)
        self._last: tuple[np.ndarray, np.ndarray] | None = None
        self._cached: tuple[SceneObservation, tuple[np.ndarray, np.ndarray]] | None = None

    # -- to provide --------------------------------------------------------------------------------
    def greedy_values(self, observation: SceneObservation) -> np.ndarray:
        """Value of trying each component (higher is better)."""
        raise NotImplementedError

    def observe_outcome(self, index: int, moved: bool, observation: SceneObservation) -> None:
        """Store what trying ``index`` from the last observation taught (call :meth:`store`)."""
        raise NotImplementedError

    def learn(self, batch: list) -> float:
        """One gradient step on a batch; the loss."""
        raise NotImplementedError

    def finish_episode(self, solved: bool) -> None:
        """Hook at the end of a training episode (e.g. relabel and store the episode's data)."""

    # -- the Agent protocol ------------------------------------------------------------------------
    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        self._rng = rng

    def tensors(self, observation: SceneObservation) -> tuple[np.ndarray, np.ndarray]:
        """The network's features of ``observation``, computed once: the scene after a try is both
        learned from (``record``) and acted on (``choose``)."""
        if self._cached is None or self._cached[0] is not observation:
            self._cached = (observation, observation_tensors(observation, self.config.network))
        return self._cached[1]

    def choose(self, observation: SceneObservation) -> int:
        self._last = self.tensors(observation)
        epsilon = self.epsilon if self.training else self.config.epsilon_eval
        if self._rng.random() < epsilon:
            return int(self._rng.integers(len(observation)))
        values = self.greedy_values(observation)
        return int(self._rng.choice(np.flatnonzero(values >= values.max() - 1e-9)))

    def record(self, index: int, result: TryResult, observation: SceneObservation) -> None:
        if not self.training or self._last is None or not result.informative:
            return  # a failed try (the robot could not try) is not an example of the task's dynamics
        self.observe_outcome(index, result.moved, observation)
        for _ in range(self.config.updates_per_action):
            self.update()

    def end_episode(self, solved: bool) -> None:
        if self.training:
            self.finish_episode(solved)
            self.episodes += 1
            self.epsilon = max(self.config.epsilon_min, self.epsilon * self.config.epsilon_decay)

    # -- replay ------------------------------------------------------------------------------------
    def store(self, example: Any, components: int, success: bool) -> None:
        """Add one example of a ``components``-component puzzle to the success or failure buffer."""
        self.replay[(components, success)].append(example)

    def replay_size(self) -> int:
        """Examples held, over every buffer."""
        return sum(len(buffer) for buffer in self.replay.values())

    def update(self) -> float | None:
        """One gradient step on a replay batch of one component count; None until a batch is available."""
        batch = self.sample_batch()
        return None if batch is None else self.learn(batch)

    def sample_batch(self) -> list | None:
        """A batch of one component count (drawn uniformly among the counts that can fill one)."""
        size = self.config.batch_size
        counts = sorted({n for n, _ in self.replay})
        ready = [n for n in counts if len(self.replay[(n, True)]) + len(self.replay[(n, False)]) >= size]
        if not ready:
            return None
        n = self._sample_rng.choice(ready)
        success, failure = self.replay[(n, True)], self.replay[(n, False)]
        half = size // 2
        if self.config.balance and len(success) >= half and len(failure) >= size - half:
            return self._draw(success, half) + self._draw(failure, size - half)
        picks = self._sample_rng.sample(range(len(success) + len(failure)), size)
        return [success[i] if i < len(success) else failure[i - len(success)] for i in picks]

    def _draw(self, buffer: deque, k: int) -> list:
        """``k`` distinct examples (indices, not a copy of the buffer: replays hold up to 1e5)."""
        return [buffer[i] for i in self._sample_rng.sample(range(len(buffer)), k)]
