"""Agents by name, as the command line asks for them."""

from __future__ import annotations

from puzzlebox.learning.agent_names import AGENT_NAMES, BELIEF_AGENT_NAMES, DEEP_AGENT_NAMES, POSE_ENCODINGS
from puzzlebox.learning.agents.base import Agent
from puzzlebox.learning.agents.dual_agent import DualAgent, MemoryAgent
from puzzlebox.learning.agents.oracle_agent import OracleAgent
from puzzlebox.learning.agents.random_agent import RandomAgent
from puzzlebox.learning.belief import BeliefConfig
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import ConfigError, UnknownAgent
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.learning.scene_lockers import scene_max_lockers
from puzzlebox.models import PuzzleSpec

__all__ = ["AGENT_NAMES", "BELIEF_AGENT_NAMES", "DEEP_AGENT_NAMES", "POSE_ENCODINGS", "make_agent"]


def make_agent(
    name: str,
    spec: PuzzleSpec,
    memory: MemoryStore | None = None,
    checkpoint: str | None = None,
    belief: BeliefConfig | None = None,
    max_lockers: int | None = None,
) -> Agent:
    """A fresh agent for one puzzle; :class:`UnknownAgent` lists the names that exist. ``belief`` is the
    observation model of the belief-based agents (``memory``, ``dual``; default :class:`BeliefConfig`),
    ``max_lockers`` the most lockers their belief allows one component (1: the paper's; see
    :class:`DualControllerConfig`; None: what fits the scene and the memory, :func:`scene_max_lockers`); the
    other agents take neither."""
    if max_lockers is None:
        max_lockers = scene_max_lockers(spec, memory, name)
    controller = DualControllerConfig(belief=belief) if belief is not None else None
    if max_lockers != 1:  # k = 1 keeps the agents' own default config, as before k existed
        if name not in BELIEF_AGENT_NAMES:
            raise ConfigError(f"agent {name!r} has no belief; max_lockers is for {list(BELIEF_AGENT_NAMES)}")
        controller = DualControllerConfig(belief=belief or BeliefConfig(), max_lockers=max_lockers)
    if name in DEEP_AGENT_NAMES:
        if checkpoint is None:
            raise ConfigError(f"agent {name!r} needs a checkpoint (train one with scripts/train.py --agent {name})")
        from puzzlebox.learning.baselines.checkpoint import load_checkpoint  # torch only when asked

        return load_checkpoint(checkpoint, expected_agent=name, scene=spec)
    if checkpoint is not None:
        raise ConfigError(
            f"agent {name!r} takes no checkpoint; --checkpoint is for the deep agents {list(DEEP_AGENT_NAMES)}"
        )
    if name == "memory":
        if memory is None:
            raise ConfigError("agent 'memory' needs a memory (train one with scripts/train.py, pass --memory)")
        return MemoryAgent(memory, config=controller)
    if memory is not None:
        raise ConfigError(f"agent {name!r} takes no memory; --memory is for the memory agent")
    if name == "dual":
        return DualAgent(controller)
    if name == "random":
        return RandomAgent()
    if name == "oracle":
        return OracleAgent(spec)
    raise UnknownAgent(f"unknown agent {name!r}. Available agents: {list(AGENT_NAMES)}")
