"""Deep model-free baseline: DQN on the graph network (the paper's Baselines; PAPER_NOTES.md).

Q(s, n) is the network's output at component n. Replay memory, a target network updated softly
(tau), epsilon-greedy exploration decaying per episode to a floor, Huber loss, Adam. The authors'
release: replay 1e5, batch 16, gamma 0.99, lr 3e-4, tau = lr, epsilon x0.999 per episode down to 0.2,
evaluation with epsilon 0.1. Rewards: +1 on reaching the goal, ``step_reward`` per other action,
plus the optional dense ``progress_reward`` for removing a component (the paper's deep agents needed
dense rewards on computer disassembly; 0, the default, is the sparse reward of the puzzle boxes).

``mt-dqn`` (MT-OPT, Kalashnikov et al. 2021) adds cross-task data sharing — each finished episode is
relabelled for the task "bring component g to its goal" for every g (``multitask.py``) — and
success/failure balancing: half of every batch comes from episodes that reached their task's goal.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import torch
from torch import nn

from puzzlebox.learning.baselines.graph_network import GraphNetwork
from puzzlebox.learning.baselines.learner import EpsilonGreedyLearner, LearnerConfig
from puzzlebox.learning.baselines.multitask import RelabelledStep, Step, progress, relabel_episode
from puzzlebox.models import SceneObservation


@dataclass(frozen=True)
class DQNConfig(LearnerConfig):
    """DQN settings (defaults: the authors' release). ``share_across_tasks`` relabels every episode for
    every component as the goal; ``balance`` draws half of each batch from success episodes."""

    gamma: float = 0.99
    tau: float = 3e-4
    """Soft target update rate per gradient step (the release: tau = learning rate)."""
    goal_reward: float = 1.0
    step_reward: float = -0.05
    progress_reward: float = 0.0
    """Dense reward added to a non-final action that removes (opens) a component, state 0 -> 1, and
    taken back for one that puts a component back, 1 -> 0 (so a cycle earns nothing). 0: sparse."""


class DQNAgent(EpsilonGreedyLearner[DQNConfig]):
    """The agent (``Agent`` protocol). ``training=True``: epsilon-greedy with learning; else evaluation."""

    base_name = "dqn"

    def __init__(self, config: DQNConfig | None = None) -> None:
        super().__init__(config or DQNConfig())
        self._episode: list[Step] = []
        self._goal = (0, 1)
        self.q = GraphNetwork(self.config.network)
        self.target = copy.deepcopy(self.q)
        self.optimizer = torch.optim.Adam(self.q.parameters(), lr=self.config.learning_rate, fused=True)

    def greedy_values(self, observation: SceneObservation) -> np.ndarray:
        assert self._last is not None  # choose() set it
        nodes, edges = self._last
        with torch.no_grad():
            return self.q(torch.from_numpy(nodes)[None], torch.from_numpy(edges)[None])[0].numpy()

    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        super().begin_episode(observation, rng)
        self._episode = []
        self._goal = (observation.goal_index, observation.goal_state)

    def observe_outcome(self, index: int, moved: bool, observation: SceneObservation) -> None:
        assert self._last is not None  # record() checked
        nodes, edges = self._last
        next_nodes, next_edges = self.tensors(observation)
        if self.config.is_multitask:  # stored once the episode's outcome is known
            self._episode.append(Step(nodes, edges, index, next_nodes, next_edges))
            return
        done = observation.solved
        c, column = self.config, self.config.network.state_column
        reward = (
            c.goal_reward if done else c.step_reward + c.progress_reward * progress(nodes, next_nodes, index, column)
        )
        self.store(RelabelledStep(nodes, edges, index, reward, next_nodes, next_edges, done), len(nodes), done)

    def finish_episode(self, solved: bool) -> None:
        """MT-OPT: relabel the episode for every task and file it as a success or a failure of each."""
        c = self.config
        columns = (c.network.state_column, c.network.goal_column)
        for _, steps, success in relabel_episode(
            self._episode, *self._goal, c.goal_reward, c.step_reward, c.share_across_tasks, c.progress_reward, columns
        ):
            for step in steps:
                self.store(step, len(step.nodes), success)
        self._episode = []

    def learn(self, batch: list[RelabelledStep]) -> float:
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
        with torch.no_grad():  # target <- (1 - tau) target + tau q, in one fused call
            # (torch leaves its fused foreach ops out of its public names)
            torch._foreach_lerp_(  # pyright: ignore[reportPrivateImportUsage]
                list(self.target.parameters()), list(self.q.parameters()), self.config.tau
            )
        return loss.item()
