"""Agents that solve puzzles through a ``World``, and a factory by name."""

from puzzlebox.learning.agents.base import Agent
from puzzlebox.learning.agents.dual_agent import DualAgent, MemoryAgent
from puzzlebox.learning.agents.factory import AGENT_NAMES, DEEP_AGENT_NAMES, make_agent
from puzzlebox.learning.agents.oracle_agent import OracleAgent
from puzzlebox.learning.agents.random_agent import RandomAgent

__all__ = [
    "AGENT_NAMES",
    "DEEP_AGENT_NAMES",
    "Agent",
    "DualAgent",
    "MemoryAgent",
    "OracleAgent",
    "RandomAgent",
    "make_agent",
]
