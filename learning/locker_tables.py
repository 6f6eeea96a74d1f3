"""Free-probability tables of the one-locker belief over all joint states (:class:`learning.belief.Belief`).

``locker_probs`` is ``(N, 2, N, 2)``: ``[c, x_c, m, x_m] = P(Z[c, x_c] = (m, x_m))``, so
``P(c held | x) = sum_m locker_probs[c, x_c, m, x_m]``, one additive term per bit of ``x``. Joint states
are bitmasks (bit ``c`` = state of component ``c``).
"""

from __future__ import annotations

import numpy as np

SMALL_N = 10
"""Up to this N, the free table is one fancy-indexed gather; above, the doubling construction."""


def locker_free_table(locker_probs: np.ndarray) -> np.ndarray:
    """``(N, 2^N)``: probability that component ``c`` is free in every joint state ``x``.

    ``P(c held | x) = sum_m P(Z[c, x_c] = (m, x_m))`` is a sum of one term per bit of ``x``, so it is
    built for all states by doubling — ``O(N * 2^N)`` work instead of ``O(N^2 * 2^N)``.
    """
    n = locker_probs.shape[0]
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


def open_free_rows(locker_probs: np.ndarray, rows: np.ndarray, goal: int, goal_state: int) -> np.ndarray:
    """Rows ``rows`` of :func:`locker_free_table` on the non-goal states only, ``(len(rows), 2^(N-1))``,
    indexed by ``learning.planner.open_index`` (the goal's bit removed): all the value iteration needs, as
    the goal states' values are 1.

    The same doubling as :func:`locker_free_table` with the goal's bit fixed (its term is added in its
    turn), so every sum runs over ``m`` in the same order: the entries equal the full table's bit for bit.
    """
    n = locker_probs.shape[0]
    lockers = locker_probs[rows]
    size = 1 << (n - 1)
    held = np.zeros((len(rows), 2, size))
    k = 1
    for m in range(n):
        if m == goal:  # fixed at 1 - goal_state in every non-goal state
            held += lockers[:, :, m, 1 - goal_state, None]
            continue
        held[:, :, k : 2 * k] = held[:, :, :k] + lockers[:, :, m, 1, None]
        held[:, :, :k] += lockers[:, :, m, 0, None]
        k *= 2
    free = np.empty((len(rows), size))
    for i, c in enumerate(rows.tolist()):
        if c == goal:
            np.subtract(1.0, held[i, 1 - goal_state], out=free[i])
            continue
        j = c if c < goal else c - 1  # c's bit in the open index
        out, by_own = free[i].reshape(-1, 2, 1 << j), held[i].reshape(2, -1, 2, 1 << j)
        np.subtract(1.0, by_own[0, :, 0], out=out[:, 0])
        np.subtract(1.0, by_own[1, :, 1], out=out[:, 1])
    return np.clip(free, 0.0, 1.0, out=free)
