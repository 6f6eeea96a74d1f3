"""Agents by name, as the command line asks for them."""

from __future__ import annotations

from collections.abc import Callable

from learning.agents.base import Agent
from learning.agents.oracle_agent import OracleAgent
from learning.agents.random_agent import RandomAgent
from learning.errors import UnknownAgent
from models import PuzzleSpec

AGENT_FACTORIES: dict[str, Callable[[PuzzleSpec], Agent]] = {
    "random": lambda spec: RandomAgent(),
    "oracle": OracleAgent,  # knows the spec's locks: the optimal floor on actions
}
"""Factories taking the spec to solve (only the oracle reads it)."""


def make_agent(name: str, spec: PuzzleSpec) -> Agent:
    """A fresh agent for one puzzle; :class:`UnknownAgent` lists the names that exist."""
    try:
        factory = AGENT_FACTORIES[name]
    except KeyError:
        raise UnknownAgent(f"unknown agent {name!r}. Available agents: {sorted(AGENT_FACTORIES)}") from None
    return factory(spec)
