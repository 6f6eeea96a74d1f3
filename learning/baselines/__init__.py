"""Deep-RL baselines of the paper (torch, the ``baselines`` extra): a graph network over components,
DQN on it, and (to come) the model-based precondition planner and MT-OPT variants."""

from learning.baselines.checkpoint import CheckpointError, load_checkpoint, save_checkpoint
from learning.baselines.dqn import DQNAgent, DQNConfig
from learning.baselines.graph_network import GraphNetwork, GraphNetworkConfig, observation_tensors
from learning.baselines.model_based import ModelBasedAgent, ModelBasedConfig

__all__ = [
    "CheckpointError",
    "DQNAgent",
    "DQNConfig",
    "GraphNetwork",
    "GraphNetworkConfig",
    "ModelBasedAgent",
    "ModelBasedConfig",
    "load_checkpoint",
    "observation_tensors",
    "save_checkpoint",
]
