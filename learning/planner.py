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

The belief is any :class:`learning.lock_belief.LockBelief`: the planner asks it for free probabilities
(``free_table``, ``open_free_rows``, ``free_vector``, ``probability_free``) and never reads its
hypotheses. For the one-locker :class:`learning.belief.Belief` these are the doubling constructions of
:mod:`learning.locker_tables` and A* uses its additive heuristic; any other belief (sets of lockers,
:class:`learning.multi_belief.MultiBelief`) gets :class:`learning.set_best_first.SetBestFirstPlanner`.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from puzzlebox.learning.belief import Belief
from puzzlebox.learning.best_first import BestFirstPlanner
from puzzlebox.learning.lock_belief import LockBelief
from puzzlebox.learning.locker_tables import SMALL_N
from puzzlebox.learning.locker_tables import open_free_rows as open_free_rows  # re-exported: its home was here
from puzzlebox.learning.set_best_first import SetBestFirstPlanner

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


def free_table(belief: LockBelief) -> np.ndarray:
    """``(N, 2^N)``: probability that component ``c`` is free in every joint state ``x`` (the belief's own
    construction: by doubling for one locker per block, :mod:`learning.locker_tables`)."""
    return belief.free_table()


def open_index(x: int | np.ndarray, goal: int) -> int | np.ndarray:
    """Index of non-goal state ``x`` among the non-goal states: ``x`` with the goal's bit removed."""
    return (x & ((1 << goal) - 1)) | ((x >> (goal + 1)) << goal)


def state_values(belief: LockBelief, goal: int, goal_state: int, gamma: float) -> np.ndarray:
    """``V(x)`` for all ``2^N`` states by value iteration to the exact fixed point."""
    return value_iteration(free_table(belief), goal, goal_state, gamma)


def bitmask(states: np.ndarray) -> int:
    """The joint state as a bitmask: bit ``c`` is the state (0/1) of component ``c``."""
    return int(sum(int(s) << c for c, s in enumerate(states)))


def value_iteration(free: np.ndarray, goal: int, goal_state: int, gamma: float) -> np.ndarray:
    """``V(x)`` for all ``2^N`` states from any table ``free`` (N, 2^N) of move probabilities (the
    belief's, or a learned precondition model's)."""
    n = free.shape[0]
    index = np.arange(1 << n)
    is_goal = ((index >> goal) & 1) == goal_state
    values = np.ones(1 << n)  # goal states stay 1: every step * V is below gamma < 1
    values[~is_goal] = open_value_iteration(gamma * free[:, ~is_goal], goal)  # ascending x: the open index
    return values


_FLIP_INDEX: dict[tuple[int, int], np.ndarray] = {}
"""``arange(size) ^ (1 << j)`` per (size, j): the partner states of the low bits, gathered with ``take``."""
GATHER_BITS = 5
"""Bits below this are flipped by a gather (a strided view of runs of 1-16 floats is several times slower)."""


def open_value_iteration(step: np.ndarray, goal: int) -> np.ndarray:
    """``V`` on the non-goal states (open index) from ``step[c] = gamma * P(c free | x)`` on them.

    ``V(x) = max(step[goal, x], max_(c != goal) step[c, x] * V(x ^ c))``: the goal toggle ends at a value
    of 1, so it starts the iteration; the other toggles stay among non-goal states. Gauss-Seidel sweeps in
    place: values only grow and never pass the least fixed point, so they end at the same fixed point, bit
    for bit, as the Jacobi iteration over all ``2^N`` states (each value is the same product
    ``step * V(next)`` of the same best path).
    """
    n = step.shape[0]
    values = step[goal].copy()  # V >= the goal toggle's step * 1
    size = values.size
    candidate = np.empty(size)
    previous = np.empty(size)
    others = [c for c in range(n) if c != goal]
    gather = size >= 1 << 10
    for _ in range(size + 1):  # converges far sooner: each sweep extends the best paths by one action or more
        previous[...] = values
        for j, c in enumerate(others):
            k = 1 << j
            if gather and j < GATHER_BITS:
                flip = _FLIP_INDEX.get((size, j))
                if flip is None:
                    flip = _FLIP_INDEX[(size, j)] = np.arange(size) ^ k
                np.take(values, flip, out=candidate)
                np.multiply(step[c], candidate, out=candidate)  # gamma P V(x ^ c)
            else:
                now, pair, out = values.reshape(-1, 2, k), step[c].reshape(-1, 2, k), candidate.reshape(-1, 2, k)
                np.multiply(pair[:, 0], now[:, 1], out=out[:, 0])
                np.multiply(pair[:, 1], now[:, 0], out=out[:, 1])
            np.maximum(values, candidate, out=values)
        if np.array_equal(previous, values):
            break
    return values


class _StepCache:
    """One belief's ``gamma * P(c free | x)`` on the non-goal states, kept across decisions: a decision
    changes one block of the belief, so only the changed components' rows are rebuilt (bit for bit what
    a full rebuild gives: each row depends on its own component's blocks only)."""

    def __init__(self) -> None:
        self.key: tuple[int, int, float] | None = None
        self.probs = np.empty(0)
        self.step = np.empty(0)

    def get(self, belief: LockBelief, goal: int, goal_state: int, gamma: float) -> np.ndarray:
        n = belief.num_components
        probs = belief.probs
        if self.key != (goal, goal_state, gamma) or self.probs.shape != probs.shape:
            rows = np.arange(n)
            self.step = np.empty((n, 1 << (n - 1)))
        else:
            rows = np.flatnonzero(np.any((self.probs != probs).reshape(n, -1), axis=1))
        if rows.size:
            self.step[rows] = gamma * belief.open_free_rows(rows, goal, goal_state)
        self.key, self.probs = (goal, goal_state, gamma), probs.copy()
        return self.step


_STEP_CACHES: weakref.WeakKeyDictionary[LockBelief, _StepCache] = weakref.WeakKeyDictionary()


def exploit_values(
    belief: LockBelief, states: np.ndarray, goal: int, goal_state: int, config: PlannerConfig | None = None
) -> np.ndarray:
    """``Q_exploit`` for every action from joint state ``states`` (0/1 per component): value iteration
    up to :data:`EXACT_MAX_COMPONENTS`, A* per successor (:class:`BestFirstPlanner`) above."""
    config = config or PlannerConfig()
    x = bitmask(states)
    if belief.num_components <= EXACT_MAX_COMPONENTS:
        return _sweep_values(belief, states, x, goal, goal_state, config.gamma)
    return _best_first_values(belief, x, goal, goal_state, config)


def _sweep_values(
    belief: LockBelief, states: np.ndarray, x: int, goal: int, goal_state: int, gamma: float
) -> np.ndarray:
    n = belief.num_components
    if n <= SMALL_N:
        table = free_table(belief)
        is_goal = ((np.arange(1 << n) >> goal) & 1) == goal_state
        step = gamma * table[:, ~is_goal]
    else:
        cache = _STEP_CACHES.get(belief)
        if cache is None:
            cache = _STEP_CACHES[belief] = _StepCache()
        step = cache.get(belief, goal, goal_state, gamma)
    values = open_value_iteration(step, goal)
    free = np.array([belief.probability_free(states, c) for c in range(n)])
    successors = [x ^ (1 << c) for c in range(n)]
    after = np.array([1.0 if ((y >> goal) & 1) == goal_state else values[open_index(y, goal)] for y in successors])
    return gamma * free * after


def _best_first_values(belief: LockBelief, x: int, goal: int, goal_state: int, config: PlannerConfig) -> np.ndarray:
    """``Q_exploit`` by best-first search alone, ``config.max_expansions`` per search (a lower bound). The
    one-locker belief's additive structure gives a sharper heuristic; any other belief gets the generic one."""
    if isinstance(belief, Belief):
        return BestFirstPlanner(belief, goal, goal_state, config.gamma).exploit_values(x, config.max_expansions)
    return SetBestFirstPlanner(belief, goal, goal_state, config.gamma).exploit_values(x, config.max_expansions)
