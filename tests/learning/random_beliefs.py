"""Random beliefs and planning problems for the planner tests (hypothesis draws the seed and size)."""

from __future__ import annotations

import numpy as np

from puzzlebox.learning.belief import Belief, BeliefConfig, hypothesis_count

EXACT = BeliefConfig(jam_probability=0.0, false_move_probability=0.0)
NOISY = BeliefConfig(jam_probability=0.05, false_move_probability=0.02)


def random_belief(rng: np.random.Generator, n: int, config: BeliefConfig = EXACT) -> Belief:
    """Sparse random blocks: some hypotheses impossible, so some moves are surely held."""
    shape = (n, 2, hypothesis_count(n))
    probs = rng.random(shape) ** 3 * (rng.random(shape) < 0.7)
    probs[:, :, 0] += rng.choice([0.0, 0.05, 0.5])
    probs[:, :, 0] += 1e-9
    return Belief(probs, config)


def random_problem(seed: int, n: int, config: BeliefConfig = EXACT) -> tuple[np.random.Generator, Belief, int, int]:
    """``(rng, belief, goal, goal_state)`` drawn from ``seed`` (the generator goes on for further draws)."""
    rng = np.random.default_rng(seed)
    belief = random_belief(rng, n, config)
    return rng, belief, int(rng.integers(n)), int(rng.integers(2))
