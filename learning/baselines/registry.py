"""The deep agents by name, with the paper's hyper-parameters (their names: ``learning.agent_names``)."""

from __future__ import annotations

from dataclasses import fields
from typing import Any

from puzzlebox.learning.baselines.dqn import DQNAgent, DQNConfig
from puzzlebox.learning.baselines.graph_network import GraphNetworkConfig
from puzzlebox.learning.baselines.model_based import ModelBasedAgent, ModelBasedConfig
from puzzlebox.learning.errors import ConfigError, UnknownAgent

LEARNERS = {
    "dqn": lambda **kw: DQNAgent(DQNConfig(**kw)),
    "mt-dqn": lambda **kw: DQNAgent(DQNConfig.multitask(**kw)),
    "model-based": lambda **kw: ModelBasedAgent(ModelBasedConfig(**kw)),
    "mt-model-based": lambda **kw: ModelBasedAgent(ModelBasedConfig.multitask(**kw)),
}


def make_learner(
    name: str, seed: int = 0, network: GraphNetworkConfig | None = None, **overrides: Any
) -> DQNAgent | ModelBasedAgent:
    """A fresh, untrained deep agent (``training=True``); ``seed`` sets its weights and replay sampling,
    ``network`` its graph network (default: the release's 5 x 64, relative poses on the edges, the
    puzzle-box family; ``GraphNetworkConfig.for_spec`` gives a scene's), ``overrides`` other fields of
    the agent's config (e.g. ``progress_reward`` of the DQN agents)."""
    if name not in LEARNERS:
        raise UnknownAgent(f"unknown deep agent {name!r}. Available: {sorted(LEARNERS)}")
    known = {f.name for f in fields(ModelBasedConfig if "model-based" in name else DQNConfig)}
    if unknown := sorted(set(overrides) - known):
        raise ConfigError(f"deep agent {name!r} has no setting(s) {unknown}; its settings: {sorted(known)}")
    return LEARNERS[name](seed=seed, network=network or GraphNetworkConfig(), **overrides)
