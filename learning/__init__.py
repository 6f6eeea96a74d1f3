"""puzzlebox learning: symbolic environments, agents, the trial loop (and later memory and
baselines). Imports only ``models`` — never ``twin`` or ``skills`` (DESIGN.md, "Layers")."""

import gymnasium

from puzzlebox.learning.agents import (
    AGENT_NAMES,
    DEEP_AGENT_NAMES,
    Agent,
    DualAgent,
    MemoryAgent,
    OracleAgent,
    RandomAgent,
    make_agent,
)
from puzzlebox.learning.errors import AgentError, ConfigError, InvalidAction, LearningError, UnknownAgent
from puzzlebox.learning.puzzle_env import FaultConfig, PuzzleEnv, PuzzleEnvConfig
from puzzlebox.learning.symbolic_world import SymbolicWorld
from puzzlebox.learning.trial import ActionRecord, RunResult, run_episode, summarise

if "puzzlebox/Puzzle-v0" not in gymnasium.registry:  # (``import puzzlebox`` registers it first)
    gymnasium.register(id="puzzlebox/Puzzle-v0", entry_point="puzzlebox.learning.puzzle_env:PuzzleEnv")
"""``gymnasium.make("puzzlebox/Puzzle-v0", spec=..., config=...)`` builds a :class:`PuzzleEnv`."""

__all__ = [
    "AGENT_NAMES",
    "DEEP_AGENT_NAMES",
    "ActionRecord",
    "AgentError",
    "Agent",
    "ConfigError",
    "DualAgent",
    "FaultConfig",
    "InvalidAction",
    "LearningError",
    "MemoryAgent",
    "OracleAgent",
    "PuzzleEnv",
    "PuzzleEnvConfig",
    "RandomAgent",
    "RunResult",
    "SymbolicWorld",
    "UnknownAgent",
    "make_agent",
    "run_episode",
    "summarise",
]
