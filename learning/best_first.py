"""Best-first (A*) search for the exploitation values on int bitmask states, expanded lazily.

The graph is the planner's (:mod:`learning.planner`): nodes are joint states ``x`` (bit ``c`` = state
of component ``c``), toggling ``c`` costs ``-log(gamma * P(c free | x))`` [nats] (infinite when
surely held), so the cheapest path to a goal state is the most probable discounted one and
``V(x) = exp(-cost)``. Instead of the ``2^N`` states of value iteration, a search expands only the
states whose cost plus heuristic is below the best path's, so on 32 components it visits hundreds
of states, not four billion.

Heuristic (admissible, so the first path whose cost no open state can beat is optimal): the
relaxed problem in which toggling component ``m`` costs its cheapest possible toggle,
``step - log(max_y P(m free | y))``, whatever the other components do. A path from a non-goal
``y`` ends with the goal toggle in some ``y'``; every locker that differs between ``y`` and ``y'``
was toggled at least once. The goal is free in ``y'`` with ``F(y) + sum of the gains`` of those
lockers (gain = what switching the locker's state frees), so with ``k`` lockers switched the cost is
at least (the ``k`` cheapest toggles) + ``step - log(F + the k largest gains)``; ``h`` is the least
of these over ``k`` (``k = 0``: toggle the goal at once).
"""

from __future__ import annotations

import heapq
import math

import numpy as np

from puzzlebox.learning.belief import Belief
from puzzlebox.learning.lock_belief import LockBelief

COST_TOLERANCE = 1e-12
"""A path within this [nats] of the best one counts as equal to it: without it, the many paths of
equal cost (toggle the same lockers in another order), whose sums differ only by rounding, would
all be expanded. A relative error of 1e-12 in V, far below the differences between distinct plans."""
HEURISTIC_SHAVE = 1e-13
"""The heuristic is lowered by this [nats] so that rounding never lets it exceed a true cost."""


def _clip_unit(values: np.ndarray) -> np.ndarray:
    """``np.clip(values, 0, 1)`` in place, without its Python-level dispatch (same result: no NaN here)."""
    return np.minimum(np.maximum(values, 0.0, out=values), 1.0, out=values)


class BestFirstPlanner:
    """The searches of one decision: one belief (unchanged within a decision) and one goal.

    Each expanded state's edge costs and its successors' heuristic are cached, and every state on a
    best path already found keeps its exact cost-to-go (:attr:`known`): later searches end there as
    at a goal, so the successors' searches reuse the first one's work.
    """

    def __init__(self, belief: LockBelief, goal: int, goal_state: int, gamma: float) -> None:
        self.belief = belief
        self.num_components = n = belief.num_components
        self.goal, self.goal_state, self.gamma = goal, goal_state, gamma
        self.step = -math.log(gamma)
        """Discount cost of any action [nats]: the least an edge can cost."""
        self.known: dict[int, float] = {}
        """Exact cost-to-go [nats] of the states on best paths found so far (inf: no path)."""
        self.exact = True
        """False once a search stopped at its budget (its value is then a lower bound on V)."""
        self.expansions = 0
        """States expanded by all searches so far."""
        self._cache: dict[int, tuple[list[float], list[float]]] = {}
        self._flips = [1 << c for c in range(n)]
        self._prepare()

    def _prepare(self) -> None:
        """What :meth:`expand` reads, from the belief's additive one-locker structure."""
        belief, n, goal, goal_state = self.belief, self.num_components, self.goal, self.goal_state
        assert isinstance(belief, Belief)  # this heuristic is the one-locker belief's (any: SetBestFirstPlanner)
        lockers = belief.locker_matrix().reshape(n, 2, n, 2)  # [c, s_c, m, s_m]
        # the goal's block when it is toggled towards the goal: [m, s_m]
        self._goal_lockers = lockers[goal, 1 - goal_state]
        # cheapest toggle of m from state s: every other component in the state that holds m least
        best_free = 1.0 - lockers.min(axis=3).sum(axis=2)  # (N, 2)
        with np.errstate(divide="ignore"):
            self._cheapest_toggle = self.step - np.log(np.clip(best_free, 0.0, 1.0))
        # per (bit of c, c), precomputed for expand: a - b == -(b - a) exactly, so the gains equal the
        # per-state differences bit for bit
        difference = self._goal_lockers[:, 0] - self._goal_lockers[:, 1]
        self._gain_by_bit = np.stack([difference, -difference])
        self._toggle_by_bit = np.ascontiguousarray(self._cheapest_toggle.T)
        self._columns = np.arange(n)
        self._shifts = np.arange(n, dtype=np.int64)
        self._lockers_by_row = belief.locker_matrix()

    def is_goal(self, x: int) -> bool:
        return ((x >> self.goal) & 1) == self.goal_state

    def expand(self, x: int) -> tuple[list[float], list[float]]:
        """For a non-goal ``x``, per component ``c``: the cost of toggling ``c`` in ``x`` and the
        heuristic of ``x ^ c``."""
        cached = self._cache.get(x)
        if cached is not None:
            return cached
        n, columns = self.num_components, self._columns
        bits = (x >> self._shifts) & 1
        rows = 2 * columns + bits
        held = self._lockers_by_row[rows[:, None], rows].sum(axis=1)
        free = _clip_unit(1.0 - held)
        # the relaxed problem seen from each successor x ^ c, as (successor, locker) matrices
        gain = self._gain_by_bit[bits, columns]  # what switching c frees of the goal: lockers[c, x_c] - [c, 1 - x_c]
        goal_free = 1.0 - held[self.goal] + gain  # the goal's free probability in x ^ c
        gains = np.empty((n, n))
        gains[:] = gain
        gains[columns, columns] = -gain  # in x ^ c, switching c back undoes its gain
        toggles = np.empty((n, n))
        toggles[:] = self._toggle_by_bit[bits, columns]
        toggles[columns, columns] = self._toggle_by_bit[1 - bits, columns]
        useful = gains > 0.0
        # ndarray methods, in place: the numpy functions' dispatch cost as much as the sorts at N = 32
        best_gains = np.where(useful, gains, 0.0)
        best_gains.sort(axis=1)
        best_gains = best_gains[:, ::-1].cumsum(axis=1)  # largest first: the same sequence as -sort(-a)
        cheapest = np.where(useful, toggles, np.inf)
        cheapest.sort(axis=1)
        cheapest = cheapest.cumsum(axis=1)
        # log(0) = -inf is meant here: the caller (cost_to_go) silences the divide warning once per search
        costs = self.step - np.log(free)
        later = cheapest - np.log(_clip_unit(goal_free[:, None] + best_gains))
        now = -np.log(_clip_unit(goal_free))  # clipped in place: after its last use unclipped
        heuristic = np.maximum(self.step + np.minimum(now, later.min(axis=1)) - HEURISTIC_SHAVE, 0.0)
        cached = (costs.tolist(), heuristic.tolist())
        self._cache[x] = cached
        return cached

    def cost_to_go(self, source: int, budget: int) -> float:
        """Least path cost [nats] from ``source`` to a goal state (inf if there is none). If the search
        stops at ``budget`` expansions: the best path found so far (so V is never overestimated)."""
        if self.is_goal(source):
            return 0.0
        if source in self.known:
            return self.known[source]
        with np.errstate(divide="ignore"):  # once per search, not per expansion (log of a zero probability)
            return self._search(source, budget)

    def _search(self, source: int, budget: int) -> float:
        goal_bit, known = 1 << self.goal, self.known
        best, best_parent, best_end = math.inf, -1, -1
        cost = {source: 0.0}
        parent = {source: -1}
        frontier = [(0.0, -0.0, source)]  # (cost + heuristic, -cost: deepest first among equals, state)
        expanded = 0
        flips, expand, known_tail, cost_of = self._flips, self.expand, known.get, cost.get
        push, pop, inf = heapq.heappush, heapq.heappop, math.inf
        while frontier:
            bound, negative_cost, x = pop(frontier)
            if bound >= best - COST_TOLERANCE:  # no open state can beat the best path: it is optimal
                break
            g = -negative_cost
            if g > cost[x]:
                continue  # superseded by a cheaper path to x
            if expanded >= budget:
                self.exact = False
                self.expansions += expanded
                return best
            expanded += 1
            costs, heuristic = expand(x)
            for w, h, flip in zip(costs, heuristic, flips, strict=True):
                g_y = g + w
                if g_y >= best:  # also skips surely held components (w = inf)
                    continue
                y = x ^ flip
                tail = 0.0 if flip == goal_bit else known_tail(y)  # x is not a goal state: y is iff c is the goal
                if tail is not None:
                    if g_y + tail < best:
                        best, best_parent, best_end = g_y + tail, x, y
                    continue
                if g_y < cost_of(y, inf):
                    cost[y] = g_y
                    parent[y] = x
                    push(frontier, (g_y + h, -g_y, y))
        self.expansions += expanded
        if best_end < 0:
            known[source] = math.inf
            return math.inf
        # each state of the best path has the rest of that path as its own best path
        tail, y, x = (0.0 if self.is_goal(best_end) else known[best_end]), best_end, best_parent
        while x != -1:
            tail += self.expand(x)[0][(x ^ y).bit_length() - 1]
            known[x] = tail
            x, y = parent[x], x
        return best

    def exploit_values(self, x: int, budget: int, total: bool = False) -> np.ndarray:
        """``Q_exploit`` of every action in ``x``. ``budget``: expansions per search, or for all the
        searches together when ``total`` (then :attr:`exact` turns False once it is spent)."""
        free = self.belief.free_vector(x)
        q = np.zeros(self.num_components)
        if not self.is_goal(x):  # x's own best path first: its states' values end later searches early
            self.cost_to_go(x, budget - self.expansions if total else budget)
        for c in np.argsort(-free, kind="stable"):  # likeliest moves first: their paths seed the rest
            if total and not self.exact:
                break  # the caller falls back to value iteration
            if free[c] > 0.0:
                value = math.exp(-self.cost_to_go(x ^ (1 << int(c)), budget - self.expansions if total else budget))
                q[c] = self.gamma * free[c] * value
        return q
