"""Deep-RL baselines of the paper (torch, the ``baselines`` extra): a graph network over components,
DQN on it, the model-based precondition planner, and their MT-OPT variants (``registry.make_learner``)."""

from learning.baselines.checkpoint import CheckpointError, load_checkpoint, save_checkpoint
from learning.baselines.dqn import DQNAgent, DQNConfig
from learning.baselines.graph_network import GraphNetwork, GraphNetworkConfig, SceneMismatch, observation_tensors
from learning.baselines.model_based import ModelBasedAgent, ModelBasedConfig
from learning.baselines.registry import LEARNERS, make_learner

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
