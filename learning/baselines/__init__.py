"""Deep-RL baselines of the paper (torch, the ``baselines`` extra): a graph network over components,
DQN on it, the model-based precondition planner, and their MT-OPT variants (``registry.make_learner``)."""

from puzzlebox.learning.baselines.checkpoint import CheckpointError, load_checkpoint, save_checkpoint
from puzzlebox.learning.baselines.dqn import DQNAgent, DQNConfig
from puzzlebox.learning.baselines.graph_network import (
    GraphNetwork,
    GraphNetworkConfig,
    SceneMismatch,
    observation_tensors,
)
from puzzlebox.learning.baselines.model_based import ModelBasedAgent, ModelBasedConfig
from puzzlebox.learning.baselines.registry import LEARNERS, make_learner

__all__ = [
    "CheckpointError",
    "DQNAgent",
    "DQNConfig",
    "GraphNetwork",
    "GraphNetworkConfig",
    "LEARNERS",
    "ModelBasedAgent",
    "ModelBasedConfig",
    "SceneMismatch",
    "load_checkpoint",
    "make_learner",
    "observation_tensors",
    "save_checkpoint",
]
