"""Belief over the lock dependency graph (the paper's Methods, "Exploration Policy").

For every component ``n`` and each of its states ``s``, a categorical ``Z[n, s]`` over hypotheses:
"independent" (index 0) or "held in ``s`` by component ``m`` while ``m`` is in state ``s'``"
(index ``1 + 2*m + s'``) — the paper's at-most-one-locker assumption. Hypotheses with ``m == n``
have probability zero. The blocks are independent, so the whole belief is the product of the
``2N`` categoricals.

A try of ``n`` in joint state ``x`` is informative about ``Z[n, x_n]`` only. Under hypothesis ``h``
the component is *held* iff ``h`` is a locker hypothesis ``(m, s')`` with ``x_m == s'``. The
likelihood is noise-aware: ``P(no move | free) = jam_probability`` (epsilon) and
``P(move | held) = false_move_probability`` (delta), so one false failure does not eliminate the
truth; both zero give the paper's exact elimination.

Bitset form: a joint state is also an int bitmask ``x`` (bit ``c`` = state of ``c``), and the lockers
are read as one ``(2N, 2N)`` matrix (:meth:`Belief.locker_matrix`), so the planner and the exploration
get every component's marginal in a state with one gather instead of a Python loop per component.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.locker_tables import locker_free_table, open_free_rows


@dataclass(frozen=True)
class BeliefConfig:
    """Prior and observation model of the belief."""

    prior_independent: float = 0.7
    """Prior probability that a component, in a state, is held by nothing (the authors' release: 0.7)."""
    jam_probability: float = 0.001
    """epsilon: probability that a free component fails to move when tried (a jam or a missed grasp).
    The small default is a floor, not a noise model: a structure the single-locker belief cannot
    represent (two lockers) or a rare misread then never eliminates every hypothesis, which with
    epsilon = delta = 0 (the paper's exact elimination) left 1.8% of runs on six-component two-locker
    puzzles cycling for 300 actions; with the floor 0.3% still do (a limit of the single-locker
    belief). On the paper's chains the floor changes nothing (5.08 mean actions either way)."""
    false_move_probability: float = 0.001
    """delta: probability that a held component is observed to move anyway (a misread outcome)."""
    family_holding_states: bool = True
    """Give no prior mass to lockers in a state their kind cannot hold in (:mod:`learning.holding_pairs`: a
    removed disassembly part holds nothing; every puzzle-box pair can hold, so boxes are unchanged). False:
    every pair may hold, the paper's hypothesis space."""

    def __post_init__(self) -> None:
        for name in ("prior_independent", "jam_probability", "false_move_probability"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise ConfigError(f"{name} must be in [0, 1], got {value}")
        if self.jam_probability + self.false_move_probability >= 1.0:
            raise ConfigError("jam_probability + false_move_probability must be < 1 (outcomes must inform)")


def hypothesis_count(num_components: int) -> int:
    """Hypotheses per block: independent + (locker m, locker state s') for every m (m == n masked)."""
    return 1 + 2 * num_components


def default_prior(num_components: int, prior_independent: float = 0.7) -> np.ndarray:
    """The no-memory prior, ``(N, 2, 1 + 2N)``: ``prior_independent`` on "independent", the rest
    spread evenly over the ``2(N-1)`` locker hypotheses."""
    n = num_components
    probs = np.zeros((n, 2, hypothesis_count(n)))
    probs[:, :, 0] = prior_independent if n > 1 else 1.0
    if n > 1:
        share = (1.0 - prior_independent) / (2 * (n - 1))
        probs[:, :, 1:] = share
        for c in range(n):
            probs[c, :, 1 + 2 * c : 3 + 2 * c] = 0.0
    return probs


def normalised_blocks(probs: np.ndarray) -> np.ndarray:
    """``probs`` with every block (last axis) scaled to sum to one; :class:`ConfigError` if a block has negative,
    non-finite or no mass."""
    totals = probs.sum(axis=-1, keepdims=True)
    if np.any(totals <= 0.0) or np.any(probs < 0.0) or not np.all(np.isfinite(probs)):
        raise ConfigError("every belief block needs non-negative, finite mass")
    return probs / totals


def state_bits(x: int, num_components: int) -> np.ndarray:
    """The 0/1 state vector ``(N,)`` of bitmask ``x`` (bit ``c`` = state of component ``c``)."""
    return (x >> np.arange(num_components, dtype=np.int64)) & 1


def block_entropy(p: np.ndarray) -> np.ndarray:
    """Shannon entropy [nats] over the last axis."""
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = np.where(p > 0.0, -p * np.log(p), 0.0)
    return terms.sum(axis=-1)


def block_confidence(probs: np.ndarray, hypotheses: int) -> np.ndarray:
    """How resolved each block is: ``1 - entropy / log(hypotheses)`` over the last axis (1 = one hypothesis
    left, 0 = uniform over ``hypotheses``), clipped to [0, 1]; ``hypotheses`` is the number a block could hold."""
    return np.clip(1.0 - block_entropy(probs) / np.log(max(hypotheses, 2)), 0.0, 1.0)


class Belief:
    """The agent's belief over who holds whom (see the module docstring).

    Attributes:
        probs: ``(N, 2, 1 + 2N)`` probabilities; ``probs[n, s]`` sums to one.
    """

    def __init__(self, probs: np.ndarray, config: BeliefConfig | None = None) -> None:
        probs = np.array(probs, dtype=np.float64)
        n = probs.shape[0]
        if probs.shape != (n, 2, hypothesis_count(n)):
            raise ConfigError(f"belief must have shape (N, 2, 1 + 2N), got {probs.shape}")
        for c in range(n):
            probs[c, :, 1 + 2 * c : 3 + 2 * c] = 0.0  # nothing holds itself
        self.probs = normalised_blocks(probs)
        self.config = config or BeliefConfig()

    @classmethod
    def uninformed(cls, num_components: int, config: BeliefConfig | None = None) -> Belief:
        config = config or BeliefConfig()
        return cls(default_prior(num_components, config.prior_independent), config)

    @property
    def num_components(self) -> int:
        return self.probs.shape[0]

    def copy(self) -> Belief:
        return Belief(self.probs.copy(), self.config)

    def held_mask(self, states: np.ndarray, component: int) -> np.ndarray:
        """Boolean ``(1 + 2N,)``: which hypotheses of ``Z[component, states[component]]`` hold it in
        joint state ``states``."""
        states = np.asarray(states)
        held = np.zeros(hypothesis_count(self.num_components), dtype=bool)
        held[1 + 2 * np.arange(self.num_components) + states] = True
        held[1 + 2 * component + states[component]] = False
        return held

    def held_masks(self, states: np.ndarray) -> np.ndarray:
        """``(N, 1 + 2N)`` bool: row ``c`` is :meth:`held_mask` of ``c`` (all components at once)."""
        n = self.num_components
        states = np.asarray(states, dtype=np.int64)
        components = np.arange(n)
        held = np.zeros((n, hypothesis_count(n)), dtype=bool)
        held[:, 1 + 2 * components + states] = True
        held[components, 1 + 2 * components + states] = False
        return held

    def probability_free(self, states: np.ndarray, component: int) -> float:
        """Marginal probability that ``component`` is not held in joint state ``states``."""
        block = self.probs[component, int(states[component])]
        return float(np.clip(1.0 - block[self.held_mask(states, component)].sum(), 0.0, 1.0))

    def probability_moves(self, states: np.ndarray, component: int) -> float:
        """Probability of *observing* a move when trying ``component`` (noise included)."""
        free = self.probability_free(states, component)
        return free * (1.0 - self.config.jam_probability) + (1.0 - free) * self.config.false_move_probability

    def posterior_block(self, states: np.ndarray, component: int, moved: bool) -> np.ndarray:
        """The updated block ``Z[component, states[component]]`` after observing ``moved``.

        If the observation has zero probability under every hypothesis (possible only without noise,
        e.g. a puzzle with two lockers), the block falls back to the prior of an uninformed agent
        rather than dividing by zero: the agent keeps acting instead of crashing.
        """
        block = self.probs[component, int(states[component])]
        held = self.held_mask(states, component)
        eps, delta = self.config.jam_probability, self.config.false_move_probability
        if moved:
            likelihood = np.where(held, delta, 1.0 - eps)
        else:
            likelihood = np.where(held, 1.0 - delta, eps)
        posterior = block * likelihood
        total = posterior.sum()
        if total <= 0.0:
            posterior = default_prior(self.num_components, self.config.prior_independent)[component, 0]
            return posterior / posterior.sum()
        return posterior / total

    def update(self, states: np.ndarray, component: int, moved: bool) -> None:
        """Bayes update after trying ``component`` in joint state ``states`` (the state *before* the try)."""
        self.probs[component, int(states[component])] = self.posterior_block(states, component, moved)

    def entropy(self) -> float:
        """Total entropy of the belief [nats]: the sum over the 2N independent blocks."""
        return float(block_entropy(self.probs).sum())

    def free_rows(self, states_bits: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """``(len(rows), S)``: :meth:`free_probabilities` of the components ``rows`` only, transposed."""
        return self.free_probabilities(states_bits)[:, rows].T

    def single_locker_probs(self) -> np.ndarray:
        """The belief itself (:attr:`probs`, not a copy): it already is the one-locker categoricals."""
        return self.probs

    def locker_memberships(self) -> np.ndarray:
        """The belief itself (:attr:`probs`, not a copy): with one locker, the probability that a pair is *among*
        the lockers is the probability that it *is* the locker."""
        return self.probs

    def block_confidence(self) -> np.ndarray:
        """``(N, 2)``: how resolved each block is (:func:`block_confidence` over the ``2N - 1`` hypotheses a block
        can hold)."""
        return block_confidence(self.probs, 2 * self.num_components - 1)

    def locker_probs(self) -> np.ndarray:
        """``(N, 2, N, 2)``: ``[c, s_c, m, s_m] = P(Z[c, s_c] = (m, s_m))``."""
        n = self.num_components
        return self.probs[:, :, 1:].reshape(n, 2, n, 2)

    def free_table(self) -> np.ndarray:
        """``(N, 2^N)``: probability that component ``c`` is free in every joint state ``x`` (by doubling:
        :func:`learning.locker_tables.locker_free_table`)."""
        return locker_free_table(self.locker_probs())

    def open_free_rows(self, rows: np.ndarray, goal: int, goal_state: int) -> np.ndarray:
        """Rows ``rows`` of :meth:`free_table` on the non-goal states
        (:func:`learning.locker_tables.open_free_rows`)."""
        return open_free_rows(self.locker_probs(), rows, goal, goal_state)

    def free_upper_bounds(self) -> np.ndarray:
        """``(N, 2)``: the largest ``P(c free | y)`` over the joint states ``y`` with ``y_c = s`` (every other
        component in the state that holds ``c`` least)."""
        return np.clip(1.0 - self.locker_probs().min(axis=3).sum(axis=2), 0.0, 1.0)

    def locker_matrix(self) -> np.ndarray:
        """``(2N, 2N)`` view: entry ``[2c + s_c, 2m + s_m] = P(Z[c, s_c] = (m, s_m))``.

        A view of :attr:`probs` (no copy), so it follows every :meth:`update` without being rebuilt.
        """
        n = self.num_components
        return self.probs.reshape(2 * n, 2 * n + 1)[:, 1:]

    def free_vector(self, x: int) -> np.ndarray:
        """``(N,)``: marginal probability that each component is free in the joint state of bitmask ``x``.

        Equals :meth:`probability_free` for every component (the self-locking entries are zero, so
        summing over every ``m`` adds only zeros to the reference's sum over ``m != c``).
        """
        n = self.num_components
        rows = 2 * np.arange(n) + state_bits(x, n)  # [2c + x_c]: the block each component is in
        held = self.locker_matrix()[rows[:, None], rows[None, :]].sum(axis=1)  # sum_m P(Z[c, x_c] = (m, x_m))
        return np.clip(1.0 - held, 0.0, 1.0)

    def free_probabilities(self, states_bits: np.ndarray) -> np.ndarray:
        """``(S, N)`` marginal probability that each component is free in each of ``S`` joint states.

        ``states_bits`` is ``(S, N)`` of 0/1. Vectorised: for planning over many states at once.
        """
        bits = np.asarray(states_bits, dtype=np.int64)
        n = self.num_components
        # locker_probs[c, s_c, m, s_m] = P(Z[c, s_c] = (m, s_m))
        locker_probs = self.probs[:, :, 1:].reshape(n, 2, n, 2)
        free = np.empty(bits.shape, dtype=np.float64)
        columns = np.arange(n)
        for c in range(n):
            # held probability = sum_m P(Z[c, x_c] = (m, x_m))
            table = locker_probs[c]  # (2, n, 2)
            held = table[bits[:, c][:, None], columns[None, :], bits].sum(axis=1)
            free[:, c] = 1.0 - held
        return np.clip(free, 0.0, 1.0)


CELL_BELIEF = BeliefConfig(jam_probability=0.05)
"""The belief's observation model in a physical cell: a free part fails to move on a try now and then
(it sticks, as the realistic cell's parts do on 2 % of tries; a grasp loses it unnoticed), so one
"blocked" is strong but not final evidence of a lock. With the symbolic default (0.001) a part that
jammed on the first try was written off, and the agent tried every other part before it again: +5
actions (10 instead of 5) on 2 of 60 realistic trials, +11 on one. With 0.05 those took 7, 10 and 6;
on the symbolic paper test boxes (300 runs) the mean stays 5.00 actions."""
