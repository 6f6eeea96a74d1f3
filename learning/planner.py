"""Exploitation values (the paper's Eq. 2): the probability of reaching the goal, discounted per step.

Nodes are joint states (bitmask ``x``, bit ``c`` = state of component ``c``); the edge that toggles
``c`` succeeds with ``P(c free | x)`` under the belief. ``V(x)`` is the best product of
``gamma * P`` along a path from ``x`` to a goal state (1 at goal states) and
``Q_exploit(c) = gamma * P(c free | x) * V(x ^ c)``.

The paper finds best paths with Dijkstra per successor state. Here, up to
:data:`EXACT_MAX_COMPONENTS` components, ``V`` is computed for all ``2^N`` states at once by
vectorised value iteration (exact: the Bellman fixed point of the same max-product problem).
Above, :class:`learning.best_first.BestFirstPlanner` runs A* on int bitmask states from each
successor, expanding states lazily, with an admissible heuristic and the exact values of earlier
searches' best paths. A search that ends within ``max_expansions`` is exact; one that reaches it
(as the authors' release caps its Dijkstra) gives a lower bound on ``V``: the best path found so far.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from learning.belief import Belief
from learning.best_first import BestFirstPlanner

SMALL_N = 10
"""Up to this N, the free table is one fancy-indexed gather; above, the doubling construction."""
EXACT_MAX_COMPONENTS = 18
"""Largest N planned by value iteration over all 2^N states (2^18 states x N floats: ~40 MB)."""


@dataclass(frozen=True)
class PlannerConfig:
    """Exploitation planner settings."""

    gamma: float = 0.9
    """Discount per action (the authors' release: 0.90), so shorter plans win at equal probability."""
    max_expansions: int = 300
    """Best-first search budget per searched state when N > EXACT_MAX_COMPONENTS (release: 300). A search
    that reaches it returns the best path found so far (a lower bound on V), else it is exact."""


def free_table(belief: Belief) -> np.ndarray:
    """``(N, 2^N)``: probability that component ``c`` is free in every joint state ``x``.

    ``P(c held | x) = sum_m P(Z[c, x_c] = (m, x_m))`` is a sum of one term per bit of ``x``, so it is
    built for all states by doubling — ``O(N * 2^N)`` work instead of ``O(N^2 * 2^N)``.
    """
    n = belief.num_components
    locker_probs = belief.probs[:, :, 1:].reshape(n, 2, n, 2)  # [c, x_c, m, x_m]
    size = 1 << n
    index = np.arange(size)
    if n <= SMALL_N:  # one gather over (state, c, m): cheapest when 2^N * N^2 is small
        bits = (index[:, None] >> np.arange(n)) & 1
        c_idx, m_idx = np.arange(n)[None, :, None], np.arange(n)[None, None, :]
        held = locker_probs[c_idx, bits[:, :, None], m_idx, bits[:, None, :]].sum(axis=2)
        return np.clip(1.0 - held.T, 0.0, 1.0)
    # held[c, own, x]: one doubling per locker m for every (c, own) at once, in place; the sums run
    # over m in the same order as one (c, own) at a time, so the table is bit for bit the same
    held = np.zeros((n, 2, size))
    for m in range(n):
        k = 1 << m
        held[:, :, k : 2 * k] = held[:, :, :k] + locker_probs[:, :, m, 1, None]
        held[:, :, :k] += locker_probs[:, :, m, 0, None]
    free = np.empty((n, size))
    for c in range(n):  # component c's own bit picks its block: halves of stride 2^c
        out, by_own = free[c].reshape(-1, 2, 1 << c), held[c].reshape(2, -1, 2, 1 << c)
        np.subtract(1.0, by_own[0, :, 0], out=out[:, 0])
        np.subtract(1.0, by_own[1, :, 1], out=out[:, 1])
    return np.clip(free, 0.0, 1.0, out=free)


def state_values(belief: Belief, goal: int, goal_state: int, gamma: float) -> np.ndarray:
    """``V(x)`` for all ``2^N`` states by value iteration to the exact fixed point."""
    return value_iteration(free_table(belief), goal, goal_state, gamma)


def bitmask(states: np.ndarray) -> int:
    """The joint state as a bitmask: bit ``c`` is the state (0/1) of component ``c``."""
    return int(sum(int(s) << c for c, s in enumerate(states)))


def value_iteration(free: np.ndarray, goal: int, goal_state: int, gamma: float) -> np.ndarray:
    """``V(x)`` for all ``2^N`` states from any table ``free`` (N, 2^N) of move probabilities (the
    belief's, or a learned precondition model's)."""
    n = free.shape[0]
    size = 1 << n
    index = np.arange(size)
    is_goal = ((index >> goal) & 1) == goal_state
    step = gamma * free  # (N, 2^N): gamma * P(c free | x)
    values = is_goal.astype(np.float64)  # goal states stay 1: every step * V is below gamma < 1
    for _ in range(size):  # converges far sooner: each sweep extends the best paths by one action or more
        changed = False
        for c in range(n):
            # in place (Gauss-Seidel): values only grow and never pass the least fixed point, so this
            # ends at the same fixed point, bit for bit, as updating all of them from the last sweep
            candidate = step[c] * values.reshape(-1, 2, 1 << c)[:, ::-1, :].reshape(-1)  # gamma P V(x ^ c)
            if not changed and np.any(candidate > values):
                changed = True
            np.maximum(values, candidate, out=values)
        if not changed:
            break
    return values


def exploit_values(
    belief: Belief, states: np.ndarray, goal: int, goal_state: int, config: PlannerConfig | None = None
) -> np.ndarray:
    """``Q_exploit`` for every action from joint state ``states`` (0/1 per component): value iteration
    up to :data:`EXACT_MAX_COMPONENTS`, A* per successor (:class:`BestFirstPlanner`) above."""
    config = config or PlannerConfig()
    x = bitmask(states)
    if belief.num_components <= EXACT_MAX_COMPONENTS:
        return _sweep_values(belief, states, x, goal, goal_state, config.gamma)
    return _best_first_values(belief, x, goal, goal_state, config)


def _sweep_values(belief: Belief, states: np.ndarray, x: int, goal: int, goal_state: int, gamma: float) -> np.ndarray:
    n = belief.num_components
    values = state_values(belief, goal, goal_state, gamma)
    free = np.array([belief.probability_free(states, c) for c in range(n)])
    return gamma * free * values[[x ^ (1 << c) for c in range(n)]]


def _best_first_values(belief: Belief, x: int, goal: int, goal_state: int, config: PlannerConfig) -> np.ndarray:
    """``Q_exploit`` by best-first search alone, ``config.max_expansions`` per search (a lower bound)."""
    return BestFirstPlanner(belief, goal, goal_state, config.gamma).exploit_values(x, config.max_expansions)
