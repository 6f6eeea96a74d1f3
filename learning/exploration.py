"""Exploration values (the paper's Eq. 1): the expected information an action gives about the graph.

``Q_info(n) = sum_o P(o | x, n) * KL(posterior_o || belief)`` over the two outcomes ``o`` (moved / did
not move). Only block ``Z[n, x_n]`` changes, so the KL of the whole belief is that block's KL; the
expectation is the mutual information between the outcome and the block, which is >= 0 and exactly
0 when both outcomes leave the belief unchanged.
"""

from __future__ import annotations

import numpy as np

from learning.belief import Belief


def kl_divergence(p: np.ndarray, q: np.ndarray) -> float:
    """KL(p || q) [nats] for categoricals; terms with p = 0 contribute 0."""
    mask = p > 0.0
    return float(np.sum(p[mask] * (np.log(p[mask]) - np.log(q[mask]))))


def expected_information_gain(belief: Belief, states: np.ndarray, component: int) -> float:
    """Expected KL divergence between posterior and current belief for trying ``component`` [nats]."""
    block = belief.probs[component, int(states[component])]
    p_move = belief.probability_moves(states, component)
    gain = 0.0
    for moved, p_outcome in ((True, p_move), (False, 1.0 - p_move)):
        if p_outcome <= 1e-15:
            continue
        gain += p_outcome * kl_divergence(belief.posterior_block(states, component, moved), block)
    return max(gain, 0.0)  # rounding can leave -1e-17


def information_values(belief: Belief, states: np.ndarray, threshold: float = 0.0) -> np.ndarray:
    """``Q_info`` for every action; gains below ``threshold`` [nats] are set to 0 (the authors' release
    drops gains below (1 - gamma) * 1.01 so that near-certain beliefs stop driving exploration)."""
    gains = np.array([expected_information_gain(belief, states, c) for c in range(belief.num_components)])
    gains[gains < threshold] = 0.0
    return gains
