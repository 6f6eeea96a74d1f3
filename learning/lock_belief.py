"""What the exploration, the planner and the dual controller need of a belief over the lock graph.

Two beliefs implement it: :class:`learning.belief.Belief` (the paper's: at most one locker per component
and state) and :class:`learning.multi_belief.MultiBelief` (sets of up to ``k`` lockers). Both factor into
independent blocks ``Z[c, s]``, one per component ``c`` and state ``s``, each a categorical over the
belief's own hypotheses (``H`` of them: the index layout is the belief's business). A joint state is a
0/1 vector ``states`` (``(N,)``, entry ``c`` = state of component ``c``) or a bitmask ``x`` (bit ``c``).

A try of ``c`` in joint state ``x`` informs block ``Z[c, x_c]`` only, through whether each of its
hypotheses *holds* ``c`` in ``x``; the observation model (jam epsilon, false move delta) is the belief's
:class:`learning.belief.BeliefConfig`.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from puzzlebox.learning.belief import BeliefConfig


class LockBelief(Protocol):
    """A factored belief over who holds whom (see the module docstring)."""

    config: BeliefConfig
    probs: np.ndarray
    """``(N, 2, H)``: block ``Z[c, s]`` at ``probs[c, s]``, a categorical over the belief's own ``H``
    hypotheses (their layout is the belief's business). The exploration reads blocks from it (with
    :meth:`held_masks`), the planner notices from it which components changed between decisions (row ``c``
    is everything ``c``'s free probabilities depend on)."""

    @property
    def num_components(self) -> int: ...

    def copy(self) -> LockBelief: ...

    def held_masks(self, states: np.ndarray) -> np.ndarray:
        """``(N, H)`` bool: row ``c`` marks the hypotheses of block ``Z[c, states[c]]`` that hold ``c`` in
        ``states``."""
        ...

    def probability_free(self, states: np.ndarray, component: int) -> float:
        """Marginal probability that ``component`` is not held in joint state ``states``."""
        ...

    def probability_moves(self, states: np.ndarray, component: int) -> float:
        """Probability of *observing* a move when trying ``component`` in ``states`` (noise included)."""
        ...

    def posterior_block(self, states: np.ndarray, component: int, moved: bool) -> np.ndarray:
        """Block ``Z[component, states[component]]`` (``(H,)``) after observing ``moved``."""
        ...

    def update(self, states: np.ndarray, component: int, moved: bool) -> None:
        """Bayes update after trying ``component`` in ``states`` (the state *before* the try)."""
        ...

    def entropy(self) -> float:
        """Total entropy [nats]: the sum over the ``2N`` independent blocks."""
        ...

    def free_vector(self, x: int) -> np.ndarray:
        """``(N,)``: probability that each component is free in the joint state of bitmask ``x``."""
        ...

    def free_probabilities(self, states_bits: np.ndarray) -> np.ndarray:
        """``(S, N)``: probability that each component is free in each of ``S`` joint states (0/1 rows)."""
        ...

    def free_rows(self, states_bits: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """``(len(rows), S)``: probability that each component of ``rows`` is free in each of ``S`` joint states."""
        ...

    def free_table(self) -> np.ndarray:
        """``(N, 2^N)``: probability that component ``c`` is free in every joint state ``x``."""
        ...

    def open_free_rows(self, rows: np.ndarray, goal: int, goal_state: int) -> np.ndarray:
        """Rows ``rows`` of :meth:`free_table` on the non-goal states only, ``(len(rows), 2^(N-1))``, column
        ``j`` = the non-goal state whose bits, the goal's removed, read ``j`` (``learning.planner.open_index``)."""
        ...

    def free_upper_bounds(self) -> np.ndarray:
        """``(N, 2)``: an upper bound on ``P(c free | y)`` over the joint states ``y`` with ``y_c = s`` (for the
        best-first planner's admissible heuristic)."""
        ...

    def single_locker_probs(self) -> np.ndarray:
        """``(N, 2, 1 + 2N)``: the belief as the paper's one-locker categoricals (for displays)."""
        ...

    def locker_memberships(self) -> np.ndarray:
        """``(N, 2, 1 + 2N)``: what a memory stores — ``[c, s, 0]`` = P(``c`` in ``s`` is held by nothing),
        ``[c, s, 1 + 2m + s']`` = P(``(m, s')`` is among the lockers of ``c`` in ``s``) (with one locker: the
        belief itself)."""
        ...

    def block_confidence(self) -> np.ndarray:
        """``(N, 2)``: how resolved each block is, ``1 - entropy / log(hypotheses a block can hold)``."""
        ...
