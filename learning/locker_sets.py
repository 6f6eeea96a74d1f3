"""The hypotheses of a belief over sets of lockers, as index arrays (one table per N and k, cached).

A *pair* ``p = 2m + s'`` is "component ``m`` in state ``s'``" (``0 <= p < 2N``). A hypothesis is a set ``L``
of at most ``k`` pairs with distinct components (a locker holds in one of its states): component ``c`` in
state ``s`` is held in joint state ``x`` iff some ``(m, s')`` in ``L`` has ``x_m == s'``. The same table
serves every block ``Z[c, s]``; the sets that contain ``c`` itself are impossible in ``c``'s blocks
(:attr:`LockerSets.possible`), as the one-locker belief masks ``m == c``.

Order of the hypotheses: the empty set ("independent") first, then by size; within a size, by the
components in lexicographic order, then their states. The singletons therefore sit at ``1 + 2m + s'``,
the one-locker belief's own layout (:mod:`learning.belief`).
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np

from puzzlebox.learning.errors import ConfigError


@dataclass(frozen=True, eq=False)
class LockerSets:
    """Every set of up to ``max_lockers`` lockers for ``num_components`` components (see the module docstring)."""

    num_components: int
    """N."""
    max_lockers: int
    """k: the largest set."""
    members: np.ndarray
    """``(H, k)`` int: the pairs ``2m + s'`` of each set, padded with ``2N``, a pair that never holds (so a
    gather from an ``(2N + 1,)`` "pair is active" vector with a False last entry reads every set at once)."""
    sizes: np.ndarray
    """``(H,)`` int: ``|L|``."""
    possible: np.ndarray
    """``(N, H)`` bool: set ``h`` is a hypothesis of component ``c``'s blocks (it does not contain ``c``)."""
    first_member: np.ndarray
    """``(H,)`` int: the first pair of each set, ``2N`` for the empty one (for bounds: a set holds
    whenever its first member does)."""

    @property
    def count(self) -> int:
        """H, the hypotheses per block (the impossible ones included)."""
        return int(self.sizes.size)

    def active_pairs(self, states_bits: np.ndarray) -> np.ndarray:
        """``(S, 2N + 1)`` bool: pair ``2m + s'`` is active (``x_m == s'``) in each of ``S`` joint states
        (``(S, N)`` of 0/1); the padding pair ``2N`` never is."""
        bits = np.asarray(states_bits, dtype=np.int64)
        n = self.num_components
        active = np.zeros((bits.shape[0], 2 * n + 1), dtype=bool)
        active[np.arange(bits.shape[0])[:, None], 2 * np.arange(n) + bits] = True
        return active

    def held(self, states_bits: np.ndarray) -> np.ndarray:
        """``(S, H)`` bool: set ``h`` holds (some member is active) in each of ``S`` joint states."""
        # (numpy types any(axis=...) as a scalar or an array: it cannot tell the array is 3-D)
        return self.active_pairs(states_bits)[:, self.members].any(axis=2)  # pyright: ignore[reportReturnType]

    def member_indicator(self) -> np.ndarray:
        """``(H, 2N)`` float: 1 where pair ``p`` is a member of set ``h``, else 0 (the empty set's row is 0)."""
        n = self.num_components
        indicator = np.zeros((self.count, 2 * n + 1))
        indicator[np.repeat(np.arange(self.count), self.max_lockers), self.members.ravel()] = 1.0
        return indicator[:, : 2 * n]

    def member_shares(self) -> np.ndarray:
        """``(H, 2N)``: ``1 / |L|`` for each pair in set ``L``, else 0 (the empty set's row is 0)."""
        return self.member_indicator() / np.maximum(self.sizes, 1)[:, None]


def locker_set_count(num_components: int, max_lockers: int) -> int:
    """H = sum over sizes j <= k of C(N, j) 2^j (the sets containing the block's own component included)."""
    return sum(math.comb(num_components, j) * 2**j for j in range(min(max_lockers, num_components) + 1))


MAX_BELIEF_ENTRIES = 500_000
"""Most probabilities a belief over locker sets may hold, ``N x 2 x H`` (every decision reads them all): at 20
parts and k = 3 (397 000) a decision takes ~5 s on one core; 62 parts at k = 3 would hold 38 million (~8 min a
decision, 300 MB) and ran on without a word."""


def set_count(num_components: int, max_lockers: int) -> int:
    """H, the number of sets of up to ``max_lockers`` lockers of N components: ``sum_(j <= k) C(N, j) 2^j``."""
    n = num_components
    return sum(math.comb(n, j) * 2**j for j in range(min(max_lockers, n) + 1))


def check_belief_size(num_components: int, max_lockers: int) -> None:
    """Refuse a belief over sets of up to ``max_lockers`` lockers of N components larger than
    :data:`MAX_BELIEF_ENTRIES` (``ConfigError`` naming the largest k that fits), before anything is built."""
    n, k = num_components, max_lockers
    entries = n * 2 * set_count(n, k)
    if entries <= MAX_BELIEF_ENTRIES:
        return
    fits = max((j for j in range(1, k) if n * 2 * set_count(n, j) <= MAX_BELIEF_ENTRIES), default=None)
    advice = f"use max_lockers {fits} or fewer" if fits else "even one locker a part is too many hypotheses"
    raise ConfigError(
        f"a belief over sets of up to {k} lockers of {n} parts holds {entries:,} probabilities (at most "
        f"{MAX_BELIEF_ENTRIES:,}: every decision reads them all; 397,000 take ~5 s): {advice}"
    )


@functools.lru_cache(maxsize=32)
def locker_sets(num_components: int, max_lockers: int) -> LockerSets:
    """The hypothesis table for N components and sets of up to ``max_lockers`` (cached per (N, k)); refused past
    :data:`MAX_BELIEF_ENTRIES` (:func:`check_belief_size`)."""
    n, k = num_components, max_lockers
    if n < 1:
        raise ConfigError(f"a belief needs at least one component, got {n}")
    if k < 1:
        raise ConfigError(f"max_lockers must be >= 1, got {k}")
    if k > 1:
        check_belief_size(n, k)
    padding = 2 * n
    members = [[padding] * k]
    for size in range(1, min(k, n) + 1):
        for components in itertools.combinations(range(n), size):
            for states in itertools.product((0, 1), repeat=size):
                pairs = [2 * m + s for m, s in zip(components, states, strict=True)]
                members.append(pairs + [padding] * (k - size))
    table = np.array(members, dtype=np.int64)
    sizes = (table < padding).sum(axis=1)
    owner = np.where(table < padding, table // 2, n)  # the component of each member, N for padding
    possible = ~(owner[None, :, :] == np.arange(n)[:, None, None]).any(axis=2)
    for array in (table, sizes, possible):
        array.setflags(write=False)  # shared by every belief of this size: nobody may change it
    first = table[:, 0].copy()
    first.setflags(write=False)
    return LockerSets(n, k, table, sizes, possible, first)
