"""Exploitation values (the paper's Eq. 2): the probability of reaching the goal, discounted per step.

Nodes are joint states (bitmask ``x``, bit ``c`` = state of component ``c``); the edge that toggles
``c`` succeeds with ``P(c free | x)`` under the belief. ``V(x)`` is the best product of
``gamma * P`` along a path from ``x`` to a goal state (1 at goal states) and
``Q_exploit(c) = gamma * P(c free | x) * V(x ^ c)``.

The paper finds best paths with Dijkstra per successor state. Here, up to
:data:`EXACT_MAX_COMPONENTS` components, ``V`` is computed for all ``2^N`` states at once by
vectorised value iteration (exact: the Bellman fixed point of the same max-product problem).
Beyond that, a best-first search from each successor with an expansion budget, as the authors'
release does, gives a lower bound on ``V``.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np

from learning.belief import Belief

SMALL_N = 10
"""Up to this N, the free table is one fancy-indexed gather; above, the doubling construction."""
EXACT_MAX_COMPONENTS = 18
"""Largest N planned exactly over all 2^N states (2^18 states x N floats: ~40 MB)."""


@dataclass(frozen=True)
class PlannerConfig:
    """Exploitation planner settings."""

    gamma: float = 0.9
    """Discount per action (the authors' release: 0.90), so shorter plans win at equal probability."""
    max_expansions: int = 300
    """Best-first search budget per successor state when N > EXACT_MAX_COMPONENTS (release: 300)."""


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
    free = np.empty((n, size))
    for c in range(n):
        held_by_own_state = []
        for own in (0, 1):
            held = np.zeros(1)
            for m in range(n):
                held = np.concatenate([held + locker_probs[c, own, m, 0], held + locker_probs[c, own, m, 1]])
            held_by_own_state.append(held)
        own_bit = (index >> c) & 1
        free[c] = 1.0 - np.where(own_bit == 1, held_by_own_state[1], held_by_own_state[0])
    return np.clip(free, 0.0, 1.0)


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
    values = is_goal.astype(np.float64)
    for _ in range(size):  # converges far sooner: each sweep extends the best paths by one action
        new = values.copy()
        for c in range(n):
            toggled = values.reshape(-1, 2, 1 << c)[:, ::-1, :].reshape(-1)  # V(x ^ (1 << c))
            np.maximum(new, step[c] * toggled, out=new)
        new[is_goal] = 1.0
        if np.array_equal(new, values):
            break
        values = new
    return values


def exploit_values(
    belief: Belief, states: np.ndarray, goal: int, goal_state: int, config: PlannerConfig | None = None
) -> np.ndarray:
    """``Q_exploit`` for every action from joint state ``states`` (0/1 per component)."""
    config = config or PlannerConfig()
    n = belief.num_components
    x = bitmask(states)
    if n <= EXACT_MAX_COMPONENTS:
        values = state_values(belief, goal, goal_state, config.gamma)
        free = np.array([belief.probability_free(states, c) for c in range(n)])
        return config.gamma * free * values[[x ^ (1 << c) for c in range(n)]]
    return _best_first_values(belief, x, goal, goal_state, config)


def _bits(x: int, n: int) -> np.ndarray:
    return (x >> np.arange(n)) & 1


def _best_first_values(belief: Belief, x: int, goal: int, goal_state: int, config: PlannerConfig) -> np.ndarray:
    n = belief.num_components
    q = np.zeros(n)
    for c in range(n):
        p = belief.probability_free(_bits(x, n), c)
        if p <= 0.0:
            continue
        q[c] = config.gamma * p * _best_path_value(belief, x ^ (1 << c), goal, goal_state, config)
    return q


def _best_path_value(belief: Belief, start: int, goal: int, goal_state: int, config: PlannerConfig) -> float:
    """Dijkstra on cost ``-log(gamma * P)`` from ``start``; 0 if no goal within the expansion budget."""
    n = belief.num_components
    step_cost = -math.log(config.gamma)
    best = {start: 0.0}
    frontier = [(0.0, start)]
    expansions = 0
    while frontier and expansions < config.max_expansions:
        cost, x = heapq.heappop(frontier)
        if cost > best.get(x, math.inf):
            continue
        if ((x >> goal) & 1) == goal_state:
            return math.exp(-cost)
        expansions += 1
        bits = _bits(x, n)
        for c in range(n):
            p = belief.probability_free(bits, c)
            if p <= 0.0:
                continue
            nxt, new_cost = x ^ (1 << c), cost + step_cost - math.log(p)
            if new_cost < best.get(nxt, math.inf):
                best[nxt] = new_cost
                heapq.heappush(frontier, (new_cost, nxt))
    return 0.0
