"""The trial loop: any agent against any ``World``, with a result per run in the contract's form."""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from learning.agents.base import Agent
from models import World


@dataclass(frozen=True)
class ActionRecord:
    """One try: which component (its ground-truth name when the world gives one), and its outcome."""

    component: str
    moved: bool


@dataclass(frozen=True)
class RunResult:
    """One run of one agent on one puzzle (the ``runs[]`` entries of ``results.json``)."""

    spec: str
    seed: int
    solved: bool
    num_actions: int
    wall_time_s: float
    actions: list[ActionRecord] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def run_episode(agent: Agent, world: World, spec_name: str, seed: int, max_actions: int) -> RunResult:
    """Let ``agent`` act on ``world`` until the goal is reached or ``max_actions`` tries are spent.

    The agent's random generator is ``default_rng(seed)``, so a run is reproducible from its seed.
    """
    start = time.perf_counter()
    observation = world.observe()
    agent.begin_episode(observation, np.random.default_rng(seed))
    name_of = getattr(world, "ground_truth_name", None)
    actions: list[ActionRecord] = []
    while not observation.solved and len(actions) < max_actions:
        index = agent.choose(observation)
        moved = world.try_toggle(index)
        observation = world.observe()
        agent.record(index, moved, observation)
        actions.append(ActionRecord(name_of(index) if name_of else str(index), moved))
    agent.end_episode(observation.solved)
    return RunResult(
        spec=spec_name,
        seed=seed,
        solved=observation.solved,
        num_actions=len(actions),
        wall_time_s=time.perf_counter() - start,
        actions=actions,
    )


def summarise(runs: list[RunResult | dict[str, Any]], max_actions: int) -> dict[str, Any]:
    """The ``results.json`` object: success rate, mean actions (an unsolved run counts ``max_actions``)
    and every run (``RunResult`` or its dict with extra keys, as twin trials give)."""
    rows = [r.to_dict() if isinstance(r, RunResult) else r for r in runs]
    if not rows:
        return {"success_rate": 0.0, "mean_actions": float(max_actions), "runs": []}
    counted = [r["num_actions"] if r["solved"] else max_actions for r in rows]
    return {
        "success_rate": float(np.mean([r["solved"] for r in rows])),
        "mean_actions": float(np.mean(counted)),
        "max_actions": max_actions,
        "runs": rows,
    }
