"""Best-first (A*) search for the exploitation values over any belief, e.g. one over sets of lockers.

The search is :class:`learning.best_first.BestFirstPlanner`'s; only the heuristic differs. That one relies
on the one-locker belief's additive structure (each locker adds its own term to a component's held
probability). Over sets of lockers a component is held if *any* locker of its set holds it, which is not
additive, so the heuristic here asks of the belief only an upper bound ``B[m, s]`` on ``P(m free | y)``
over the joint states ``y`` with ``y_m = s`` (:meth:`learning.multi_belief.MultiBelief.free_upper_bounds`).

Admissible: a path from a non-goal ``y`` either toggles the goal at once (cost ``step - log P(goal free |
y)``, exact) or toggles some other component first (at least ``min_m [step - log B[m, y_m]]``) and the goal
later (at least ``step - log B[goal, 1 - goal_state]``); ``h(y)`` is the lesser of the two.
"""

from __future__ import annotations

import numpy as np

from puzzlebox.learning.best_first import HEURISTIC_SHAVE, BestFirstPlanner
from puzzlebox.learning.lock_belief import LockBelief


class SetBestFirstPlanner(BestFirstPlanner):
    """:class:`BestFirstPlanner` with the heuristic of the module docstring, for any :class:`LockBelief`
    (the base class's constructor calls :meth:`_prepare`; the searches are the base class's)."""

    belief: LockBelief

    def _prepare(self) -> None:
        """The bounds :meth:`expand` reads: the cheapest toggle of every component from each state."""
        n, goal = self.num_components, self.goal
        bounds = self.belief.free_upper_bounds()  # (N, 2)
        with np.errstate(divide="ignore"):
            toggle = self.step - np.log(bounds)  # (N, 2): the cheapest toggle of m from state s
        self._toggle_by_bit = np.ascontiguousarray(toggle.T)  # [s, m]
        self._toggle_by_bit[:, goal] = np.inf  # "some other component first"
        self._goal_last = toggle[goal, 1 - self.goal_state]  # the goal toggled after them
        self._columns = np.arange(n)
        self._shifts = np.arange(n, dtype=np.int64)
        self._goal_row = np.array([goal])

    def expand(self, x: int) -> tuple[list[float], list[float]]:
        """For a non-goal ``x``, per component ``c``: the cost of toggling ``c`` in ``x`` and the
        heuristic of ``x ^ c`` (0 for the goal toggle, whose successor is a goal state)."""
        cached = self._cache.get(x)
        if cached is not None:
            return cached
        n, columns, goal = self.num_components, self._columns, self.goal
        bits = (x >> self._shifts) & 1
        with np.errstate(divide="ignore"):
            costs = self.step - np.log(self.belief.free_vector(x))
            successors = np.repeat(bits[None, :], n, axis=0)
            successors[columns, columns] ^= 1
            goal_free = self.belief.free_rows(successors, self._goal_row)[0]  # P(goal free | x ^ c)
            now = -np.log(goal_free)
        # cheapest first toggle of a non-goal component in each successor: x's bits, c's flipped
        toggles = np.repeat(self._toggle_by_bit[bits, columns][None, :], n, axis=0)
        toggles[columns, columns] = self._toggle_by_bit[1 - bits, columns]
        later = toggles.min(axis=1) + self._goal_last - self.step  # h adds the goal toggle's step back
        heuristic = np.maximum(self.step + np.minimum(now, later) - HEURISTIC_SHAVE, 0.0)
        heuristic[goal] = 0.0
        cached = (costs.tolist(), heuristic.tolist())
        self._cache[x] = cached
        return cached
