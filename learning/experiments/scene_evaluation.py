"""Evaluating an agent on a list of test scenes: the same seeded worlds for every agent, checkpoint and training
seed (the disassembly experiment's memory, dual and deep agents all meet these runs)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from puzzlebox.learning.agents.base import Agent
from puzzlebox.learning.symbolic_world import SymbolicWorld
from puzzlebox.learning.trial import run_episode
from puzzlebox.models import PuzzleSpec

TEST_SEED = 500
"""World seed of test run 0 (run r: ``TEST_SEED + r``) on every test scene."""


def evaluate_on_scenes(
    make: Callable[[], Agent], tests: Sequence[PuzzleSpec], runs: int, max_actions: int
) -> dict[str, Any]:
    """``runs`` runs on each of ``tests`` with agents from ``make()``: the fraction ``solved`` within
    ``max_actions``, the ``mean_actions`` (unsolved runs count ``max_actions``), both per test scene too."""
    per_test: dict[str, dict[str, float]] = {}
    solved_all, actions_all = [], []
    for spec in tests:
        solved, actions = [], []
        for r in range(runs):
            result = run_episode(make(), SymbolicWorld(spec, TEST_SEED + r), spec.name, TEST_SEED + r, max_actions)
            solved.append(bool(result.solved))
            actions.append(result.num_actions if result.solved else max_actions)
        per_test[spec.name] = {"solved": float(np.mean(solved)), "mean_actions": float(np.mean(actions))}
        solved_all += solved
        actions_all += actions
    return {"solved": float(np.mean(solved_all)), "mean_actions": float(np.mean(actions_all)), "per_test": per_test}
