"""The deep agents by name, with the paper's hyper-parameters (``learning.agents.DEEP_AGENT_NAMES``)."""

from __future__ import annotations

from learning.baselines.dqn import DQNAgent, DQNConfig
from learning.baselines.graph_network import GraphNetworkConfig
from learning.baselines.model_based import ModelBasedAgent, ModelBasedConfig
from learning.errors import UnknownAgent

LEARNERS = {
    "dqn": lambda **kw: DQNAgent(DQNConfig(**kw)),
    "mt-dqn": lambda **kw: DQNAgent(DQNConfig.multitask(**kw)),
    "model-based": lambda **kw: ModelBasedAgent(ModelBasedConfig(**kw)),
    "mt-model-based": lambda **kw: ModelBasedAgent(ModelBasedConfig.multitask(**kw)),
}


def make_learner(name: str, seed: int = 0, network: GraphNetworkConfig | None = None) -> DQNAgent | ModelBasedAgent:
    """A fresh, untrained deep agent (``training=True``); ``seed`` sets its weights and replay sampling,
    ``network`` its graph network (default: the release's 5 x 64, relative poses on the edges)."""
    if name not in LEARNERS:
        raise UnknownAgent(f"unknown deep agent {name!r}. Available: {sorted(LEARNERS)}")
    return LEARNERS[name](seed=seed, network=network or GraphNetworkConfig())
