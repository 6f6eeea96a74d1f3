"""The deep agents by name, with the paper's hyper-parameters (``learning.agents.DEEP_AGENT_NAMES``)."""

from __future__ import annotations

from learning.baselines.dqn import DQNAgent, DQNConfig
from learning.baselines.model_based import ModelBasedAgent, ModelBasedConfig
from learning.errors import UnknownAgent

LEARNERS = {
    "dqn": lambda seed: DQNAgent(DQNConfig(seed=seed)),
    "mt-dqn": lambda seed: DQNAgent(DQNConfig.multitask(seed=seed)),
    "model-based": lambda seed: ModelBasedAgent(ModelBasedConfig(seed=seed)),
    "mt-model-based": lambda seed: ModelBasedAgent(ModelBasedConfig.multitask(seed=seed)),
}


def make_learner(name: str, seed: int = 0) -> DQNAgent | ModelBasedAgent:
    """A fresh, untrained deep agent (``training=True``); ``seed`` sets its weights and replay sampling."""
    if name not in LEARNERS:
        raise UnknownAgent(f"unknown deep agent {name!r}. Available: {sorted(LEARNERS)}")
    return LEARNERS[name](seed)
