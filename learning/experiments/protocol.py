"""Shared pieces of the paper's symbolic protocols: layouts per trial, training, evaluation.

As in the paper, every trial draws a new layout of its variant ("randomized component locations"):
training episode ``e`` of training seed ``t`` uses layout seed ``TRAIN_LAYOUT_BASE + 1000 t + e``;
test run ``r`` uses layout seed ``r`` and world seed ``r`` for every agent and training seed, so all
agents meet exactly the same test boxes (paired comparisons).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from puzzlebox.learning.agent_names import SYMBOLIC_AGENT_NAMES
from puzzlebox.learning.agents.base import Agent
from puzzlebox.learning.agents.dual_agent import DualAgent, MemoryAgent
from puzzlebox.learning.agents.oracle_agent import OracleAgent
from puzzlebox.learning.agents.random_agent import RandomAgent
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.memory.prior import MemoryConfig
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.learning.puzzle_env import FaultConfig, PuzzleEnvConfig
from puzzlebox.learning.symbolic_world import SymbolicWorld
from puzzlebox.learning.trial import RunResult, run_episode
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.generator import TEST_INDICES, TRAIN_INDICES, paper_variant

TRAIN_LAYOUT_BASE = 100_000
SYMBOLIC_AGENTS = SYMBOLIC_AGENT_NAMES


@dataclass(frozen=True)
class ProtocolConfig:
    """Settings shared by the symbolic protocols."""

    runs_per_variant: int = 50
    """Test runs per unseen variant (the paper: 50)."""
    success_actions: int = 15
    """A run succeeds when the goal is reached in fewer than this many actions (the paper: 15)."""
    max_actions: int = 30
    """Action budget per run; an unsolved run counts this many actions in the means."""
    training_seeds: int = 3
    """Independent trainings per point (the spread over seeds is reported)."""
    controller: DualControllerConfig = field(default_factory=DualControllerConfig)
    memory: MemoryConfig = field(default_factory=MemoryConfig)

    def quick(self) -> ProtocolConfig:
        """A CI-sized version: few runs, one training seed."""
        return replace(self, runs_per_variant=2, training_seeds=1)


@functools.lru_cache(maxsize=4096)
def layout(index: int, seed: int) -> PuzzleSpec:
    """Paper variant ``index`` with layout ``seed`` (cached: layouts are reused across agents)."""
    return paper_variant(index, seed)


def train_memory(
    store: MemoryStore,
    variants: Sequence[int],
    episodes: range,
    training_seed: int,
    config: ProtocolConfig,
) -> list[RunResult]:
    """Train the memory agent for ``episodes`` (episode numbers), cycling through ``variants``."""
    results = []
    for e in episodes:
        spec, seed = training_layout(variants, e, training_seed)
        agent = MemoryAgent(store, config.controller, config.memory, learn=True)
        agent.episode_label = spec.name
        results.append(run_episode(agent, SymbolicWorld(spec, seed), spec.name, seed, config.max_actions))
    return results


def training_layout(variants: Sequence[int], episode: int, training_seed: int) -> tuple[PuzzleSpec, int]:
    """The box of training episode ``episode`` (cycling through ``variants``) and its world seed: the
    same for every agent trained with ``training_seed``."""
    seed = TRAIN_LAYOUT_BASE + 1000 * training_seed + episode
    return layout(variants[episode % len(variants)], seed), seed


def agent_factory(name: str, store: MemoryStore | None, config: ProtocolConfig) -> Callable[[PuzzleSpec], Agent]:
    """Fresh evaluation agents by name (the memory agent does not learn during evaluation)."""
    if name == "memory":
        if store is None:
            raise ConfigError("the memory agent needs a memory")
        return lambda spec: MemoryAgent(store, config.controller, config.memory)
    if name == "dual":
        return lambda spec: DualAgent(config.controller)
    if name == "random":
        return lambda spec: RandomAgent()
    if name == "oracle":
        return OracleAgent
    raise ConfigError(f"unknown agent {name!r} for the symbolic protocols. Available: {list(SYMBOLIC_AGENTS)}")


@dataclass(frozen=True)
class Score:
    """Outcome of one evaluation: success rate [0..1] and mean actions (unsolved runs count the budget)."""

    success_rate: float
    mean_actions: float
    runs: int


def evaluate(
    make_agent: Callable[[PuzzleSpec], Agent],
    config: ProtocolConfig,
    faults: FaultConfig | None = None,
    box_pose: tuple[float, float, float] | None = None,
    variants: Sequence[int] = TEST_INDICES,
) -> Score:
    """Run ``runs_per_variant`` seeded runs on each unseen variant; success = solved in fewer than
    ``success_actions`` actions. ``box_pose`` places every test box elsewhere on the table."""
    env_config = PuzzleEnvConfig(faults=faults or FaultConfig())
    solved, actions = [], []
    for index in variants:
        for run in range(config.runs_per_variant):
            spec = layout(index, run)
            if box_pose is not None and spec.box is not None:
                spec = replace(spec, box=replace(spec.box, pose=box_pose))
            result = run_episode(
                make_agent(spec), SymbolicWorld(spec, run, env_config), spec.name, run, config.max_actions
            )
            solved.append(result.solved and result.num_actions < config.success_actions)
            actions.append(result.num_actions if result.solved else config.max_actions)
    return Score(float(np.mean(solved)), float(np.mean(actions)), len(solved))


def summarise_scores(scores: Sequence[Score]) -> dict[str, float | int | list[float]]:
    """Mean and standard deviation over training seeds, and each seed's value."""
    success = np.array([s.success_rate for s in scores])
    actions = np.array([s.mean_actions for s in scores])
    return {
        "success_rate": float(success.mean()),
        "success_rate_std": float(success.std()),
        "mean_actions": float(actions.mean()),
        "mean_actions_std": float(actions.std()),
        "seeds": len(scores),
        "success_rate_per_seed": success.tolist(),
        "mean_actions_per_seed": actions.tolist(),
    }


__all__ = [
    "SYMBOLIC_AGENTS",
    "TEST_INDICES",
    "TRAIN_INDICES",
    "ProtocolConfig",
    "Score",
    "agent_factory",
    "evaluate",
    "layout",
    "summarise_scores",
    "train_memory",
    "training_layout",
]
