"""Deep model-free baseline: DQN on the graph network (the paper's Baselines; PAPER_NOTES.md).

Q(s, n) is the network's output at component n. Replay memory, a target network updated softly
(tau), epsilon-greedy exploration decaying per episode to a floor, Huber loss, Adam. The authors'
release: replay 1e5, batch 16, gamma 0.99, lr 3e-4, tau = lr, epsilon x0.999 per episode down to 0.2,
evaluation with epsilon 0.1. Rewards: +1 on reaching the goal, ``step_reward`` per other action.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from learning.baselines.graph_network import GraphNetwork, GraphNetworkConfig, observation_tensors
from learning.baselines.learner import EpsilonGreedyLearner
from models import SceneObservation


@dataclass(frozen=True)
class DQNConfig:
    """DQN settings (defaults: the authors' release)."""

    network: GraphNetworkConfig = field(default_factory=GraphNetworkConfig)
    gamma: float = 0.99
    learning_rate: float = 3e-4
    batch_size: int = 16
    replay_size: int = 100_000
    tau: float = 3e-4
    """Soft target update rate per gradient step (the release: tau = learning rate)."""
    epsilon_start: float = 1.0
    epsilon_decay: float = 0.999
    """Multiplier of epsilon after every training episode."""
    epsilon_min: float = 0.2
    epsilon_eval: float = 0.1
    goal_reward: float = 1.0
    step_reward: float = -0.05
    updates_per_action: int = 1
    seed: int = 0


@dataclass
class _Transition:
    nodes: np.ndarray
    edges: np.ndarray
    action: int
    reward: float
    next_nodes: np.ndarray
    next_edges: np.ndarray
    done: bool


class DQNAgent(EpsilonGreedyLearner):
    """The agent (``Agent`` protocol). ``training=True``: epsilon-greedy with learning; else evaluation."""

    name = "dqn"

    def __init__(self, config: DQNConfig | None = None) -> None:
        super().__init__(config or DQNConfig())
        self.q = GraphNetwork(self.config.network)
        self.target = copy.deepcopy(self.q)
        self.optimizer = torch.optim.Adam(self.q.parameters(), lr=self.config.learning_rate)

    def greedy_values(self, observation: SceneObservation) -> np.ndarray:
        nodes, edges = self._last
        with torch.no_grad():
            return self.q(torch.from_numpy(nodes)[None], torch.from_numpy(edges)[None])[0].numpy()

    def example(self, index: int, moved: bool, observation: SceneObservation) -> _Transition:
        done = observation.solved
        reward = self.config.goal_reward if done else self.config.step_reward
        next_nodes, next_edges = observation_tensors(observation, self.config.network.position_scale)
        nodes, edges = self._last
        return _Transition(nodes, edges, index, reward, next_nodes, next_edges, done)

    def learn(self, batch: list[_Transition]) -> float:
        """TD step with the Huber loss, then a soft update of the target network."""
        nodes = torch.from_numpy(np.stack([t.nodes for t in batch]))
        edges = torch.from_numpy(np.stack([t.edges for t in batch]))
        next_nodes = torch.from_numpy(np.stack([t.next_nodes for t in batch]))
        next_edges = torch.from_numpy(np.stack([t.next_edges for t in batch]))
        actions = torch.tensor([t.action for t in batch])
        rewards = torch.tensor([t.reward for t in batch], dtype=torch.float32)
        done = torch.tensor([t.done for t in batch], dtype=torch.float32)
        q = self.q(nodes, edges).gather(1, actions[:, None]).squeeze(1)
        with torch.no_grad():
            target = rewards + self.config.gamma * (1 - done) * self.target(next_nodes, next_edges).max(dim=1).values
        loss = nn.functional.smooth_l1_loss(q, target)
        self.optimizer.zero_grad()
        loss.backward()
        self.optimizer.step()
        with torch.no_grad():
            for p, tp in zip(self.q.parameters(), self.target.parameters(), strict=True):
                tp.mul_(1 - self.config.tau).add_(self.config.tau * p)
        return loss.item()
