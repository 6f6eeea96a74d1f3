"""Deep model-based baseline: the graph network as a precondition classifier — does component n move
in this state? — planned with the dual controller's exploitation search (the paper's Baselines,
after Sharma et al.'s relational precondition models).

Every try is a labelled example (the observation, the component, moved or not), kept in a replay set
and fitted with binary cross-entropy. To act, the network scores every component in every joint
state of the puzzle (2^N states, batched), which gives the table of move probabilities that value
iteration (``learning.planner.value_iteration``) turns into Q_exploit; epsilon-greedy exploration.

``mt-model-based`` (MT-OPT) adds cross-task data sharing — a precondition does not depend on the task,
so every try is also stored with the goal flag on each other component (``multitask.py``), teaching
the network that invariance from data — and success/failure balancing: half of every batch are tries
that moved the component, half tries that did not (the classifier's two outcomes; most tries in a
locked box fail).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from puzzlebox.learning.baselines.graph_network import GraphNetwork
from puzzlebox.learning.baselines.learner import EpsilonGreedyLearner, LearnerConfig
from puzzlebox.learning.baselines.multitask import with_goal
from puzzlebox.learning.planner import bitmask, value_iteration
from puzzlebox.models import SceneObservation


@dataclass(frozen=True)
class ModelBasedConfig(LearnerConfig):
    """Settings of the precondition learner and its planner. ``share_across_tasks`` stores every try
    with the goal flag on each component; ``balance`` draws half of each batch from tries that moved."""

    gamma: float = 0.9
    """Planner discount per action (the agent's exploitation search)."""


@dataclass
class _Example:
    nodes: np.ndarray
    edges: np.ndarray
    action: int
    moved: bool


class ModelBasedAgent(EpsilonGreedyLearner[ModelBasedConfig]):
    """The agent (``Agent`` protocol); ``training=True`` explores and fits, else evaluates."""

    base_name = "model-based"

    def __init__(self, config: ModelBasedConfig | None = None) -> None:
        super().__init__(config or ModelBasedConfig())
        self.net = GraphNetwork(self.config.network)
        self.optimizer = torch.optim.Adam(self.net.parameters(), lr=self.config.learning_rate, fused=True)

    def move_probabilities(self, observation: SceneObservation) -> np.ndarray:
        """``(N, 2^N)``: the network's P(component moves) in every joint state of this scene."""
        nodes, edges = self.tensors(observation)
        n = len(nodes)
        bits = ((np.arange(1 << n)[:, None] >> np.arange(n)) & 1).astype(np.float32)
        batch = np.repeat(nodes[None], len(bits), axis=0)
        batch[:, :, self.config.network.state_column] = bits
        with torch.no_grad():
            logits = self.net(torch.from_numpy(batch), torch.from_numpy(edges)[None].expand(len(bits), -1, -1, -1))
        return torch.sigmoid(logits).numpy().T

    def greedy_values(self, observation: SceneObservation) -> np.ndarray:
        """Q_exploit from the learned move probabilities (the agent's exploitation search)."""
        free = self.move_probabilities(observation)
        values = value_iteration(free, observation.goal_index, observation.goal_state, self.config.gamma)
        x = bitmask(observation.states)
        return self.config.gamma * free[:, x] * values[[x ^ (1 << c) for c in range(len(observation))]]

    def observe_outcome(self, index: int, moved: bool, observation: SceneObservation) -> None:
        assert self._last is not None  # record() checked
        nodes, edges = self._last
        goals = range(len(nodes)) if self.config.share_across_tasks else [None]
        for goal in goals:
            example_nodes = nodes if goal is None else with_goal(nodes, goal, self.config.network.goal_column)
            self.store(_Example(example_nodes, edges, index, moved), len(nodes), moved)

    def learn(self, batch: list[_Example]) -> float:
        """One gradient step of binary cross-entropy on a batch of tries; the loss."""
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
