"""Belief over sets of lockers: a component moves in a state only when none of its lockers holds it.

For every component ``n`` and each of its states ``s``, a categorical ``Z[n, s]`` over the sets ``L`` of up
to ``k`` lockers (pairs ``(m, s')``, ``m != n``, at most one ``s'`` per ``m``; the empty set is
"independent"), indexed as :mod:`learning.locker_sets` lays them out. ``n`` is held in joint state ``x`` iff
some ``(m, s')`` in ``L`` has ``x_m == s'``. The blocks stay independent, as in the one-locker belief
(:mod:`learning.belief`), whose hypothesis space is the special case ``k = 1``; the likelihood is the same
noise-aware one: ``P(no move | free) = jam_probability`` (epsilon), ``P(move | held) =
false_move_probability`` (delta).

The held/free probability of every component in many joint states at once is a gather ("which pairs are
active") and a product with the blocks: ``P(c free | x) = sum_h Z[c, x_c](h) [no member of set h active in
x]``. Per block there are ``sum_{j <= k} C(N, j) 2^j`` sets (those containing ``n`` itself have probability
zero): 129 for N = 8, k = 2; 2049 for N = 32.
"""

from __future__ import annotations

import numpy as np

from puzzlebox.learning.belief import (
    BeliefConfig,
    block_confidence,
    block_entropy,
    default_prior,
    normalised_blocks,
    state_bits,
)
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.locker_sets import LockerSets, locker_sets
from puzzlebox.learning.set_prior import membership_set_prior, set_prior

CHUNK_ENTRIES = 1 << 21
"""Joint states x hypotheses evaluated per chunk of a table (~17 MB of float64), so that tables over
``2^N`` states stay within memory for every N the exact planner takes."""


class MultiBelief:
    """The agent's belief over sets of up to ``max_lockers`` lockers (see the module docstring).

    Attributes:
        probs: ``(N, 2, H)`` probabilities; ``probs[n, s]`` sums to one over the sets of :attr:`sets`.
        sets: the hypothesis table (:class:`learning.locker_sets.LockerSets`).
    """

    def __init__(self, probs: np.ndarray, max_lockers: int, config: BeliefConfig | None = None) -> None:
        probs = np.array(probs, dtype=np.float64)
        n = probs.shape[0]
        self.sets: LockerSets = locker_sets(n, max_lockers)
        if probs.shape != (n, 2, self.sets.count):
            raise ConfigError(
                f"a belief over sets of up to {max_lockers} lockers of {n} components has shape "
                f"{(n, 2, self.sets.count)}, got {probs.shape}"
            )
        self.probs = normalised_blocks(np.where(self.sets.possible[:, None, :], probs, 0.0))  # nothing holds itself
        self.config = config or BeliefConfig()

    @classmethod
    def from_single_prior(
        cls, single_probs: np.ndarray, max_lockers: int, config: BeliefConfig | None = None
    ) -> MultiBelief:
        """The belief whose prior is :func:`learning.set_prior.set_prior` of a one-locker prior."""
        n = np.asarray(single_probs).shape[0]
        return cls(set_prior(single_probs, locker_sets(n, max_lockers)), max_lockers, config)

    @classmethod
    def from_memberships(
        cls,
        memberships: np.ndarray,
        max_lockers: int,
        config: BeliefConfig | None = None,
        floor: float = 0.01,
        holding: np.ndarray | None = None,
    ) -> MultiBelief:
        """The belief whose prior is :func:`learning.set_prior.membership_set_prior` of recalled memberships
        (:meth:`locker_memberships`' form, e.g. a memory's recall); ``holding``: the pairs that can hold."""
        n = np.asarray(memberships).shape[0]
        prior = membership_set_prior(memberships, locker_sets(n, max_lockers), floor, holding)
        return cls(prior, max_lockers, config)

    @classmethod
    def uninformed(cls, num_components: int, max_lockers: int, config: BeliefConfig | None = None) -> MultiBelief:
        config = config or BeliefConfig()
        return cls.from_single_prior(default_prior(num_components, config.prior_independent), max_lockers, config)

    @property
    def num_components(self) -> int:
        return self.probs.shape[0]

    @property
    def max_lockers(self) -> int:
        return self.sets.max_lockers

    def copy(self) -> MultiBelief:
        return MultiBelief(self.probs.copy(), self.max_lockers, self.config)

    # -- one joint state ----------------------------------------------------------------------------------

    def _held_sets(self, states: np.ndarray) -> np.ndarray:
        """``(H,)`` bool: which sets hold in joint state ``states`` (the same for every block)."""
        return self.sets.held(np.asarray(states, dtype=np.int64)[None, :])[0]

    def held_masks(self, states: np.ndarray) -> np.ndarray:
        """``(N, H)`` bool: row ``c`` marks the sets of ``Z[c, states[c]]`` that hold ``c`` in ``states``
        (the impossible sets, of zero probability, are marked as any other)."""
        return np.broadcast_to(self._held_sets(states), (self.num_components, self.sets.count))

    def probability_free(self, states: np.ndarray, component: int) -> float:
        """Marginal probability that ``component`` is not held in joint state ``states``."""
        block = self.probs[component, int(states[component])]
        return float(np.clip(1.0 - block[self._held_sets(states)].sum(), 0.0, 1.0))

    def probability_moves(self, states: np.ndarray, component: int) -> float:
        """Probability of *observing* a move when trying ``component`` (noise included)."""
        free = self.probability_free(states, component)
        return free * (1.0 - self.config.jam_probability) + (1.0 - free) * self.config.false_move_probability

    def posterior_block(self, states: np.ndarray, component: int, moved: bool) -> np.ndarray:
        """The updated block ``Z[component, states[component]]`` after observing ``moved``.

        An observation of zero probability under every set (possible only without noise, e.g. more
        lockers than ``k``) falls back to the uninformed prior's block instead of dividing by zero.
        """
        block = self.probs[component, int(states[component])]
        held = self._held_sets(states)
        eps, delta = self.config.jam_probability, self.config.false_move_probability
        likelihood = np.where(held, delta, 1.0 - eps) if moved else np.where(held, 1.0 - delta, eps)
        posterior = block * likelihood
        total = posterior.sum()
        if total <= 0.0:
            prior = MultiBelief.uninformed(self.num_components, self.max_lockers, self.config)
            return prior.probs[component, 0].copy()
        return posterior / total

    def update(self, states: np.ndarray, component: int, moved: bool) -> None:
        """Bayes update after trying ``component`` in joint state ``states`` (the state *before* the try)."""
        self.probs[component, int(states[component])] = self.posterior_block(states, component, moved)

    def entropy(self) -> float:
        """Total entropy of the belief [nats]: the sum over the 2N independent blocks."""
        return float(block_entropy(self.probs).sum())

    def free_vector(self, x: int) -> np.ndarray:
        """``(N,)``: probability that each component is free in the joint state of bitmask ``x``."""
        n = self.num_components
        bits = state_bits(x, n)
        free_sets = ~self._held_sets(bits)
        blocks = self.probs[np.arange(n), bits]  # (N, H): Z[c, x_c]
        return np.clip(blocks @ free_sets, 0.0, 1.0)

    # -- many joint states --------------------------------------------------------------------------------

    def free_probabilities(self, states_bits: np.ndarray) -> np.ndarray:
        """``(S, N)``: probability that each component is free in each of ``S`` joint states (0/1 rows)."""
        bits = np.asarray(states_bits, dtype=np.int64)
        return self.free_rows(bits, np.arange(self.num_components)).T

    def free_table(self) -> np.ndarray:
        """``(N, 2^N)``: probability that component ``c`` is free in every joint state ``x``."""
        n = self.num_components
        return self.free_rows(_bits_of(np.arange(1 << n), n), np.arange(n))

    def open_free_rows(self, rows: np.ndarray, goal: int, goal_state: int) -> np.ndarray:
        """Rows ``rows`` of :meth:`free_table` on the non-goal states, ``(len(rows), 2^(N-1))``, column ``j``
        = the non-goal state whose bits, the goal's removed, read ``j`` (``learning.planner.open_index``)."""
        n = self.num_components
        low = _bits_of(np.arange(1 << (n - 1)), n - 1)
        bits = np.insert(low, goal, 1 - goal_state, axis=1)  # the goal's bit back, fixed off the goal
        return self.free_rows(bits, np.asarray(rows, dtype=np.int64))

    def free_rows(self, states_bits: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """``(len(rows), S)``: ``P(c free | x)`` for the components ``rows`` in the joint states ``states_bits``
        (``(S, N)`` of 0/1): one gather of the sets that hold in each state, one matrix product with the blocks."""
        sets = self.sets
        free = np.empty((rows.size, states_bits.shape[0]))
        blocks = self.probs[rows].reshape(2 * rows.size, -1)  # [2r + own bit]: both of each row's blocks
        chunk = max(1, CHUNK_ENTRIES // sets.count)
        for start in range(0, states_bits.shape[0], chunk):
            part = states_bits[start : start + chunk]
            free_sets = (~sets.held(part)).astype(np.float64)  # (S', H)
            by_own = (free_sets @ blocks.T).reshape(-1, rows.size, 2)  # (S', R, own bit)
            own = part[:, rows]  # (S', R): the bit that picks each row's block
            free[:, start : start + chunk] = np.take_along_axis(by_own, own[:, :, None], axis=2)[:, :, 0].T
        return np.clip(free, 0.0, 1.0, out=free)

    # -- bounds and views ---------------------------------------------------------------------------------

    def free_upper_bounds(self) -> np.ndarray:
        """``(N, 2)``: an upper bound on ``P(c free | y)`` over every joint state ``y`` with ``y_c = s``.

        A set holds whenever its first member does, so ``P(held | y) >= sum_(m, s') A[m, s'] [y_m = s']``
        with ``A`` the mass of the sets whose first member is ``(m, s')``; its least value over ``y`` is
        ``sum_m min_s' A[m, s']``. (For the best-first planner's admissible heuristic.)
        """
        n = self.num_components
        by_first = np.zeros((n, 2, 2 * n + 1))
        # numpy's stubs type ufunc.at's indices as integers only, not the tuple of indices it takes
        np.add.at(by_first, (slice(None), slice(None), self.sets.first_member), self.probs)  # pyright: ignore[reportArgumentType]
        least_held = by_first[:, :, : 2 * n].reshape(n, 2, n, 2).min(axis=3).sum(axis=2)
        return np.clip(1.0 - least_held, 0.0, 1.0)

    def single_locker_probs(self) -> np.ndarray:
        """``(N, 2, 1 + 2N)``: the one-locker view (for displays) — "independent" keeps the empty set's
        mass, and each non-empty set's mass is shared equally by its lockers."""
        view = self.probs @ self.sets.member_shares()  # (N, 2, 2N)
        return np.concatenate([self.probs[:, :, :1], view], axis=2)

    def locker_memberships(self) -> np.ndarray:
        """``(N, 2, 1 + 2N)``: what a memory stores — "independent" keeps the empty set's mass, and pair ``(m, s')``
        gets the mass of every set it is a member of, P(``(m, s')`` is *among* the lockers). Unlike the one-locker
        view, it tells "held by both screws" (1 and 1) from "by one of them" (1/2 and 1/2)."""
        view = self.probs @ self.sets.member_indicator()  # (N, 2, 2N)
        return np.concatenate([self.probs[:, :, :1], np.clip(view, 0.0, 1.0)], axis=2)

    def block_confidence(self) -> np.ndarray:
        """``(N, 2)``: how resolved each block is over the sets a block can hold (those without its own component)."""
        possible = int(self.sets.possible[0].sum())  # the same for every component: the sets without it
        return block_confidence(self.probs, possible)


def _bits_of(index: np.ndarray, n: int) -> np.ndarray:
    """``(S, n)`` 0/1: the bits of each bitmask in ``index``."""
    return (index[:, None] >> np.arange(n)) & 1
