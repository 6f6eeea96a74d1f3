"""A prior over sets of lockers built from a one-locker prior (the default one, or a memory's recall).

The one-locker prior gives each block ``Z[c, s]`` a categorical ``q``: ``q_0`` = "independent" and
``q_p`` = "held by pair ``p = (m, s')`` alone". The set prior keeps ``q_0`` on the empty set and spreads
the rest, ``1 - q_0``, over the non-empty sets of up to ``k`` lockers with weights

    w(L) = prod_{p in L} q_p,

normalised over the non-empty sets. This is the distribution of independently present pairs (each with
odds ``q_p``) conditioned on "at least one, at most ``k``, at most one state per locker". So

- at ``k = 1`` it is the one-locker prior itself (up to rounding);
- what the memory recalls about each pair carries over: a pair the memory rules out (``q_p ~ 0``) is in
  no likely set, a pair it is sure of (``q_p`` large) is in most of them;
- a second locker costs a factor ``q_p`` (small: under the uninformed prior of 8 components a pair has
  ``q_p = 0.3 / 14 = 0.021``, so all two-locker sets together get 3.4 % of the mass): the belief turns to
  two lockers when one no longer explains the tries. Weighing every extra locker up by a constant 3 or 10
  was worse on a validation set (150 two-locker boxes of 8 components, generator seeds 2000-2149, memory
  agent: 1.18, 1.19 and 1.26 times the optimum for 1, 3 and 10).
"""

from __future__ import annotations

import numpy as np

from learning.belief import hypothesis_count
from learning.errors import ConfigError
from learning.locker_sets import LockerSets


def set_prior(single_probs: np.ndarray, sets: LockerSets) -> np.ndarray:
    """``(N, 2, H)`` prior over ``sets`` from the one-locker prior ``single_probs`` ``(N, 2, 1 + 2N)``
    (rows summing to one; see the module docstring)."""
    single = np.asarray(single_probs, dtype=np.float64)
    n = sets.num_components
    if single.shape != (n, 2, hypothesis_count(n)):
        raise ConfigError(
            f"a one-locker prior for {n} components has shape {(n, 2, hypothesis_count(n))}, got {single.shape}"
        )
    # a pair's weight, with the padding pair 2N weighing 1 so that a gather + product reads every set
    pair_weight = np.concatenate([single[:, :, 1:], np.ones((n, 2, 1))], axis=2)
    weights = pair_weight[:, :, sets.members].prod(axis=3)  # (N, 2, H)
    weights = np.where(sets.possible[:, None, :], weights, 0.0)
    locked = weights[:, :, 1:].sum(axis=2, keepdims=True)
    independent = single[:, :, :1]
    # the non-empty sets share the one-locker prior's locker mass 1 - q_0 (all on "independent" if no
    # pair has weight)
    scale = np.divide(1.0 - independent, locked, out=np.zeros_like(locked), where=locked > 0.0)
    prior = np.concatenate([np.where(locked > 0.0, independent, 1.0), weights[:, :, 1:] * scale], axis=2)
    return prior / prior.sum(axis=2, keepdims=True)
