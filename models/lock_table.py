"""The lock semantics of a spec, vectorised over symbolic states.

A symbolic state is a bitmask: bit ``i`` is the state (0 closed, 1 open) of ``spec.components[i]``.
Component ``j`` can be toggled in state ``s`` iff no rule ``(i, si, j, sj)`` is active there, i.e.
there is no rule with ``bit(s, i) == si`` and ``bit(s, j) == sj``.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from puzzlebox.models.errors import ReachabilityUndecided
from puzzlebox.models.spec import PuzzleSpec

DENSE_SEARCH_MAX_COMPONENTS = 22
"""Up to this many components, reachability uses a dense parent array (8 * 2**N bytes)."""
SPARSE_SEARCH_MAX_STATES = 4_000_000
"""Beyond that, a hash-set search gives up after this many visited states."""


@dataclass(frozen=True)
class LockTable:
    """Lock rules as index arrays over ``spec.components`` (one entry per rule)."""

    num_components: int
    locker: np.ndarray
    locker_state: np.ndarray
    locked: np.ndarray
    locked_state: np.ndarray
    goal: int
    goal_state: int

    @classmethod
    def from_spec(cls, spec: PuzzleSpec) -> LockTable:
        index = {name: i for i, name in enumerate(spec.component_names)}
        rules = spec.locks
        return cls(
            num_components=len(spec.components),
            locker=np.array([index[r.locker] for r in rules], dtype=np.int64),
            locker_state=np.array([r.locker_state for r in rules], dtype=np.int64),
            locked=np.array([index[r.locked] for r in rules], dtype=np.int64),
            locked_state=np.array([r.locked_state for r in rules], dtype=np.int64),
            goal=index[spec.goal.component],
            goal_state=spec.goal.state,
        )

    def can_move(self, state: int, component: int) -> bool:
        """Whether ``component`` toggles in symbolic ``state`` (a bitmask)."""
        return bool(self.movable(np.array([state], dtype=np.int64), component)[0])

    def movable(self, states: np.ndarray, component: int) -> np.ndarray:
        """Boolean array: for each bitmask in ``states``, whether ``component`` can toggle."""
        states = np.asarray(states, dtype=np.int64)
        blocked = np.zeros(states.shape, dtype=bool)
        for r in np.flatnonzero(self.locked == component):
            locker_ok = ((states >> self.locker[r]) & 1) == self.locker_state[r]
            locked_ok = ((states >> component) & 1) == self.locked_state[r]
            blocked |= locker_ok & locked_ok
        return ~blocked

    def held(self, states: np.ndarray) -> np.ndarray:
        """``(N,)`` bool: which components an active rule holds in the joint state ``states`` (``(N,)`` 0/1,
        entry ``c`` the state of component ``c``): the complement of :meth:`movable`, for one state vector (the
        twin's latches act on it)."""
        states = np.asarray(states, dtype=np.int64)
        active = (states[self.locker] == self.locker_state) & (states[self.locked] == self.locked_state)
        held = np.zeros(self.num_components, dtype=bool)
        held[self.locked[active]] = True
        return held

    def is_goal(self, state: int) -> bool:
        return ((state >> self.goal) & 1) == self.goal_state

    def shortest_solution(self, start: int = 0) -> list[int] | None:
        """A shortest sequence of components to toggle from ``start`` to the goal, or ``None``.

        Breadth-first over states. Raises :class:`ReachabilityUndecided` when the search would
        exceed :data:`SPARSE_SEARCH_MAX_STATES` states (only possible above
        :data:`DENSE_SEARCH_MAX_COMPONENTS` components).
        """
        if self.is_goal(start):
            return []
        n = self.num_components
        if n <= DENSE_SEARCH_MAX_COMPONENTS:
            return self._dense_search(start)
        return self._sparse_search(start)

    def _dense_search(self, start: int) -> list[int] | None:
        n = self.num_components
        parent = np.full(1 << n, -1, dtype=np.int64)  # previous state, -1 = unvisited
        parent[start] = start
        frontier = np.array([start], dtype=np.int64)
        while frontier.size:
            next_states = []
            for j in range(n):
                src = frontier[self.movable(frontier, j)]
                dst = src ^ (1 << j)
                fresh = parent[dst] < 0
                src, dst = src[fresh], dst[fresh]
                dst, first = np.unique(dst, return_index=True)
                parent[dst] = src[first]
                next_states.append(dst)
                hits = dst[((dst >> self.goal) & 1) == self.goal_state]
                if hits.size:
                    return self._unwind(parent, int(hits[0]), start)
            frontier = np.concatenate(next_states) if next_states else frontier[:0]
        return None

    @staticmethod
    def _unwind(parent: np.ndarray | dict[int, int], state: int, start: int) -> list[int]:
        """The toggles from ``start`` to ``state`` along the search's parent links."""
        path = []
        while state != start:
            prev = int(parent[state])
            path.append((prev ^ state).bit_length() - 1)
            state = prev
        return path[::-1]

    def _sparse_search(self, start: int) -> list[int] | None:
        parent: dict[int, int] = {start: start}
        queue = deque([start])
        while queue:
            state = queue.popleft()
            for j in range(self.num_components):
                nxt = state ^ (1 << j)
                if nxt in parent or not self.can_move(state, j):
                    continue
                parent[nxt] = state
                if self.is_goal(nxt):
                    return self._unwind(parent, nxt, start)
                if len(parent) > SPARSE_SEARCH_MAX_STATES:
                    raise ReachabilityUndecided(
                        f"searched {SPARSE_SEARCH_MAX_STATES} states of a {self.num_components}-component "
                        "puzzle without deciding whether the goal is reachable"
                    )
                queue.append(nxt)
        return None
