"""Exploration values (the paper's Eq. 1): the expected information an action gives about the graph.

``Q_info(n) = sum_o P(o | x, n) * KL(posterior_o || belief)`` over the two outcomes ``o`` (moved / did
not move). Only block ``Z[n, x_n]`` changes, so the KL of the whole belief is that block's KL; the
expectation is the mutual information between the outcome and the block, which is >= 0 and exactly
0 when both outcomes leave the belief unchanged.

Any :class:`learning.lock_belief.LockBelief` (one locker per block, or sets of lockers): the blocks are read
as ``probs[c, s]`` and which of their hypotheses hold ``c`` from :meth:`~learning.lock_belief.LockBelief.held_masks`.
"""

from __future__ import annotations

import numpy as np

from puzzlebox.learning.lock_belief import LockBelief


def kl_divergence(p: np.ndarray, q: np.ndarray) -> float:
    """KL(p || q) [nats] for categoricals; terms with p = 0 contribute 0."""
    mask = p > 0.0
    return float(np.sum(p[mask] * (np.log(p[mask]) - np.log(q[mask]))))


def expected_information_gain(belief: LockBelief, states: np.ndarray, component: int) -> float:
    """Expected KL divergence between posterior and current belief for trying ``component`` [nats]."""
    block = belief.probs[component, int(states[component])]
    p_move = belief.probability_moves(states, component)
    gain = 0.0
    for moved, p_outcome in ((True, p_move), (False, 1.0 - p_move)):
        if p_outcome <= 1e-15:
            continue
        gain += p_outcome * kl_divergence(belief.posterior_block(states, component, moved), block)
    return max(gain, 0.0)  # rounding can leave -1e-17


def information_values(belief: LockBelief, states: np.ndarray, threshold: float = 0.0) -> np.ndarray:
    """``Q_info`` for every action; gains below ``threshold`` [nats] are set to 0 (the authors' release
    drops gains below (1 - gamma) * 1.01 so that near-certain beliefs stop driving exploration).

    All components at once (:func:`information_gains`): the same values as
    :func:`expected_information_gain` per component, without a Python loop over them.
    """
    gains = information_gains(belief, states)
    gains[gains < threshold] = 0.0
    return gains


def information_gains(belief: LockBelief, states: np.ndarray) -> np.ndarray:
    """``(N,)`` expected information gain of trying each component in ``states`` [nats]."""
    n = belief.num_components
    states = np.asarray(states, dtype=np.int64)
    components = np.arange(n)
    blocks = belief.probs[components, states]  # (N, H): Z[c, x_c] for every c
    held = belief.held_masks(states)  # held[c, h]: hypothesis h of Z[c, x_c] holds c in x
    eps, delta = belief.config.jam_probability, belief.config.false_move_probability
    free = np.clip(1.0 - np.where(held, blocks, 0.0).sum(axis=1), 0.0, 1.0)
    p_move = free * (1.0 - eps) + (1.0 - free) * delta
    gains = np.zeros(n)
    for p_outcome, likelihood in (
        (p_move, np.where(held, delta, 1.0 - eps)),
        (1.0 - p_move, np.where(held, 1.0 - delta, eps)),
    ):
        posterior = blocks * likelihood
        total = posterior.sum(axis=1, keepdims=True)
        informative = (p_outcome > 1e-15) & (total[:, 0] > 0.0)  # as the loop: skip impossible outcomes
        with np.errstate(divide="ignore", invalid="ignore"):
            posterior = posterior / total
            terms = np.where(posterior > 0.0, posterior * (np.log(posterior) - np.log(blocks)), 0.0)
        gains += np.where(informative, p_outcome * terms.sum(axis=1), 0.0)
    return np.maximum(gains, 0.0)  # rounding can leave -1e-17
