"""A prior over sets of lockers, built from a one-locker prior (the default one: :func:`set_prior`) or from a
memory's recalled memberships (:func:`membership_set_prior`).

The one-locker prior (:func:`set_prior`) gives each block ``Z[c, s]`` a categorical ``q``: ``q_0`` = "independent" and
``q_p`` = "held by pair ``p = (m, s')`` alone". The set prior keeps ``q_0`` on the empty set and spreads
the rest, ``1 - q_0``, over the non-empty sets of up to ``k`` lockers with weights

    w(L) = prod_{p in L} q_p,

normalised over the non-empty sets. This is the distribution of independently present pairs (each with
odds ``q_p``) conditioned on "at least one, at most ``k``, at most one state per locker". So

- at ``k = 1`` it is the one-locker prior itself (up to rounding);
- what the prior says about each pair carries over: a pair it rules out (``q_p ~ 0``) is in
  no likely set, a pair it is sure of (``q_p`` large) is in most of them;
- a second locker costs a factor ``q_p`` (small: under the uninformed prior of 8 components a pair has
  ``q_p = 0.3 / 14 = 0.021``, so all two-locker sets together get 3.4 % of the mass): the belief turns to
  two lockers when one no longer explains the tries. Weighing every extra locker up by a constant 3 or 10
  was worse on a validation set (150 two-locker boxes of 8 components, generator seeds 2000-2149, memory
  agent: 1.18, 1.19 and 1.26 times the optimum for 1, 3 and 10).
"""

from __future__ import annotations

import numpy as np

from puzzlebox.learning.belief import hypothesis_count
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.locker_sets import LockerSets


def set_prior(single_probs: np.ndarray, sets: LockerSets) -> np.ndarray:
    """``(N, 2, H)`` prior over ``sets`` from the one-locker prior ``single_probs`` ``(N, 2, 1 + 2N)``
    (rows summing to one; see the module docstring)."""
    single = np.asarray(single_probs, dtype=np.float64)
    n = sets.num_components
    if single.shape != (n, 2, hypothesis_count(n)):
        raise ConfigError(
            f"a one-locker prior for {n} components has shape {(n, 2, hypothesis_count(n))}, got {single.shape}"
        )
    return _weighted_sets(single[:, :, 1:], single[:, :, :1], sets)


def membership_set_prior(
    memberships: np.ndarray, sets: LockerSets, floor: float = 0.01, holding: np.ndarray | None = None
) -> np.ndarray:
    """``(N, 2, H)`` prior over ``sets`` from recalled *memberships* ``(N, 2, 1 + 2N)`` (a memory's recall of
    :meth:`learning.multi_belief.MultiBelief.locker_memberships`): ``[c, s, 0]`` = P(held by nothing),
    ``[c, s, 1 + p]`` = ``m_p`` = P(pair ``p`` is among the lockers), rows *not* summing to one.

    The empty set keeps the recalled independence; the non-empty sets share the rest with weights

        w(L) = prod_{p in L} m_p / (1 - m_p),

    the distribution of pairs present independently with probabilities ``m_p``, conditioned as
    :func:`set_prior` conditions (at least one, at most ``k``). So a memory of "held by both screws" (``m``
    near 1 for both) recalls the two-screw set, where the one-locker view (a half each) would recall either
    screw alone. Every probability is first clipped to ``[floor, 1 - floor]`` (the one-locker recall's uniform
    mass), so no set is ruled out and a wrong memory can still be unlearned — except the sets with a pair
    outside ``holding`` (``(2N,)`` bool, :mod:`learning.holding_pairs`; None: every pair can hold).
    """
    view = np.asarray(memberships, dtype=np.float64)
    n = sets.num_components
    if view.shape != (n, 2, hypothesis_count(n)):
        raise ConfigError(f"memberships for {n} components have shape {(n, 2, hypothesis_count(n))}, got {view.shape}")
    if not 0.0 < floor < 0.5:
        raise ConfigError(f"the membership floor must be in (0, 0.5), got {floor}")
    clipped = np.clip(view, floor, 1.0 - floor)
    odds = clipped[:, :, 1:] / (1.0 - clipped[:, :, 1:])
    if holding is not None:
        odds = np.where(np.asarray(holding, dtype=bool)[None, None, :], odds, 0.0)
    return _weighted_sets(odds, clipped[:, :, :1], sets)


def _weighted_sets(pair_weights: np.ndarray, independent: np.ndarray, sets: LockerSets) -> np.ndarray:
    """``(N, 2, H)``: the empty set gets ``independent`` ``(N, 2, 1)``; the non-empty sets share the rest in
    proportion to the product of their pairs' ``pair_weights`` ``(N, 2, 2N)`` (all on the empty set if no set
    has weight)."""
    n = sets.num_components
    # the padding pair 2N weighs 1, so that a gather + product reads every set
    pair_weight = np.concatenate([pair_weights, np.ones((n, 2, 1))], axis=2)
    weights = pair_weight[:, :, sets.members].prod(axis=3)  # (N, 2, H)
    weights = np.where(sets.possible[:, None, :], weights, 0.0)
    locked = weights[:, :, 1:].sum(axis=2, keepdims=True)
    scale = np.divide(1.0 - independent, locked, out=np.zeros_like(locked), where=locked > 0.0)
    prior = np.concatenate([np.where(locked > 0.0, independent, 1.0), weights[:, :, 1:] * scale], axis=2)
    return prior / prior.sum(axis=2, keepdims=True)
