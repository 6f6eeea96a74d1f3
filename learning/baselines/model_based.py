"""Deep model-based baseline: the graph network as a precondition classifier — does component n move
in this state? — planned with the dual controller's exploitation search (the paper's Baselines,
after Sharma et al.'s relational precondition models).

Every try is a labelled example (the observation, the component, moved or not), kept in a replay set
and fitted with binary cross-entropy. To act, the network scores every component in every joint
state of the puzzle (2^N states, batched), which gives the table of move probabilities that value
iteration (``learning.planner.value_iteration``) turns into Q_exploit; epsilon-greedy exploration.
"""

from __future__ import annotations

import random
from collections import defaultdict, deque
from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from learning.baselines.graph_network import GraphNetwork, GraphNetworkConfig, observation_tensors
from learning.planner import value_iteration
from models import KIND_NAMES, SceneObservation

STATE_FEATURE = len(KIND_NAMES)
"""Index of the state flag in the node features."""


@dataclass(frozen=True)
class ModelBasedConfig:
    """Settings of the precondition learner and its planner."""

    network: GraphNetworkConfig = field(default_factory=GraphNetworkConfig)
    learning_rate: float = 3e-4
    batch_size: int = 16
    replay_size: int = 100_000
    gamma: float = 0.9
    """Planner discount per action (the agent's exploitation search)."""
    epsilon_start: float = 1.0
    epsilon_decay: float = 0.999
    epsilon_min: float = 0.2
    epsilon_eval: float = 0.1
    updates_per_action: int = 1
    seed: int = 0


@dataclass
class _Example:
    nodes: np.ndarray
    edges: np.ndarray
    action: int
    moved: bool


class ModelBasedAgent:
    """The agent (``Agent`` protocol); ``training=True`` explores and fits, else evaluates."""

    name = "model-based"

    def __init__(self, config: ModelBasedConfig | None = None) -> None:
        self.config = config or ModelBasedConfig()
        torch.manual_seed(self.config.seed)
        self.net = GraphNetwork(self.config.network)
        self.optimizer = torch.optim.Adam(self.net.parameters(), lr=self.config.learning_rate)
        self.examples: dict[int, deque[_Example]] = defaultdict(lambda: deque(maxlen=self.config.replay_size))
        self.epsilon = self.config.epsilon_start
        self.training = True
        self.episodes = 0
        self._sample_rng = random.Random(self.config.seed)
        self._rng = np.random.default_rng(0)
        self._last: tuple[np.ndarray, np.ndarray] | None = None

    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        self._rng = rng

    def move_probabilities(self, observation: SceneObservation) -> np.ndarray:
        """``(N, 2^N)``: the network's P(component moves) in every joint state of this scene."""
        nodes, edges = observation_tensors(observation, self.config.network.position_scale)
        n = len(nodes)
        bits = ((np.arange(1 << n)[:, None] >> np.arange(n)) & 1).astype(np.float32)
        batch = np.repeat(nodes[None], len(bits), axis=0)
        batch[:, :, STATE_FEATURE] = bits
        with torch.no_grad():
            logits = self.net(torch.from_numpy(batch), torch.from_numpy(edges)[None].expand(len(bits), -1, -1, -1))
        return torch.sigmoid(logits).numpy().T

    def choose(self, observation: SceneObservation) -> int:
        self._last = observation_tensors(observation, self.config.network.position_scale)
        epsilon = self.epsilon if self.training else self.config.epsilon_eval
        if self._rng.random() < epsilon:
            return int(self._rng.integers(len(observation)))
        free = self.move_probabilities(observation)
        values = value_iteration(free, observation.goal_index, observation.goal_state, self.config.gamma)
        x = int(sum(int(s) << c for c, s in enumerate(observation.states)))
        q = self.config.gamma * free[:, x] * values[[x ^ (1 << c) for c in range(len(observation))]]
        best = np.flatnonzero(q >= q.max() - 1e-12)
        return int(self._rng.choice(best))

    def record(self, index: int, moved: bool, observation: SceneObservation) -> None:
        if not self.training or self._last is None:
            return
        nodes, edges = self._last
        self.examples[len(nodes)].append(_Example(nodes, edges, index, moved))
        for _ in range(self.config.updates_per_action):
            self.update()

    def end_episode(self, solved: bool) -> None:
        if self.training:
            self.episodes += 1
            self.epsilon = max(self.config.epsilon_min, self.epsilon * self.config.epsilon_decay)

    def update(self) -> float | None:
        """One gradient step of binary cross-entropy on a batch of tries; the loss."""
        sizes = [n for n, examples in self.examples.items() if len(examples) >= self.config.batch_size]
        if not sizes:
            return None
        batch = self._sample_rng.sample(list(self.examples[self._sample_rng.choice(sizes)]), self.config.batch_size)
        nodes = torch.from_numpy(np.stack([b.nodes for b in batch]))
        edges = torch.from_numpy(np.stack([b.edges for b in batch]))
        actions = torch.tensor([b.action for b in batch])
        labels = torch.tensor([float(b.moved) for b in batch])
        logits = self.net(nodes, edges).gather(1, actions[:, None]).squeeze(1)
        loss = nn.functional.binary_cross_entropy_with_logits(logits, labels)
        self.optimizer.zero_grad()
        loss.backward()
        self.optimizer.step()
        return loss.item()
