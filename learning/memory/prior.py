"""A belief prior recalled from memory: k nearest neighbours per pair, averaged, with uniform mass.

For a new task, every block ``Z[j, s_j]`` gets weight ``w_indep`` = the mean stored independence of
``kind_j`` in ``s_j`` and, for every other component i and state s_i, ``w[i, s_i]`` = the mean of the
stored blocks of the k nearest pairs in bucket ``(kind_i, kind_j)`` around j's pose in i's frame (kernel-weighted,
with the uninformed prior as a pseudo-neighbour: see :class:`MemoryConfig`); a pair of a box met in several
episodes is one of the k, its meetings averaged into one neighbour (:func:`nearest_pairs`). The weights are
normalised, then ``uniform_mass`` is added to every possible hypothesis and the block renormalised, so
a bad prior can still be unlearned. A bucket the memory has never filled falls back to the
uninformed prior's value, or — with ``back_off`` — is recalled from all pairs at a similar pose.

What a memory stores of a pair is the probability that it is *among* the lockers
(:meth:`learning.lock_belief.LockBelief.locker_memberships`): for the paper's one-locker belief the locker's
own probability; for a belief over sets of lockers, the mass of every set the pair is in, so "held by both
screws" is remembered as such. A set belief's prior is built from the unnormalised recall
(:func:`recall_memberships`, :func:`learning.set_prior.membership_set_prior`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from puzzlebox.learning.belief import block_confidence, default_prior, hypothesis_count
from puzzlebox.learning.memory.keys import se3_pose_keys
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.models.disassembly_kinds import kind_family

KEY_DECIMALS = 9
"""Distances in key space are ranked at this resolution (key units ~ 2 cm / 1 rad)."""


@dataclass(frozen=True)
class MemoryConfig:
    """How memories become priors."""

    k: int = 5
    """Nearest neighbours averaged per pair (the authors' release: 5)."""
    bandwidth: float | None = 1.0
    """Gaussian kernel width in key units (``position_scale`` metres, or ~1 rad): neighbours are
    weighted by ``exp(-d^2 / 2 bandwidth^2)`` and the uninformed prior counts as ``prior_weight``
    of a neighbour, so a pose the memory has never seen near recalls the uninformed prior rather
    than unrelated memories. None: the paper's plain average of the k nearest."""
    prior_weight: float = 0.2
    """Pseudo-count of the uninformed prior in the weighted average (with a bandwidth or confidence)."""
    weight_by_confidence: bool = True
    """Weigh each recalled block by how resolved it was when stored (1 - entropy / max entropy), so
    blocks an episode actually pinned down outweigh blocks it left vague. False: the paper's equal
    weights."""
    back_off: bool = True
    """For a kind pair the memory has never seen, recall from every stored pair at a similar relative
    pose (kernel-weighted, so a pose unlike any memory still recalls the uninformed prior) — a
    back-off to the coarser bucket, as n-gram models do. Measured with one training variant (no
    wheels): 100% / 5.93 actions on the unseen variants against 95.3% / 8.33 without; unchanged at
    9 episodes (5.07) and on the validation split (6.96)."""
    uniform_mass: float = 0.01
    """Added to every hypothesis before renormalising (the authors' release: 0.01). For a belief over sets
    of lockers, the floor (and one minus it the ceiling) of every recalled membership and independence
    (:func:`learning.set_prior.membership_set_prior`)."""
    position_scale: float = 0.02
    """Length that weighs like one key unit [m] (used when creating a memory)."""
    rotation_weight: float = 1.0
    """Key units per unit of chord ``2 sin(theta/2)`` of a relative rotation, about per radian (used when
    creating a memory; :mod:`learning.memory.keys`): 1.0 weighs a planar yaw as the paper's sin/cos did."""
    training_entropy_scale: float | None = 0.5
    """The controller's ``entropy_scale`` while learning (training episodes); None keeps the controller's.
    A smaller h_max explores more, and only failed tries confirm a lock, so training episodes that
    explore store sharper graphs; trials in the symbolic simulator are cheap. Chosen on the
    validation split (memory of 6 training variants, the other 3 evaluated): 0.5 gave 7.04 mean
    actions against 7.55 with the evaluation setting (4.0)."""


def recall_prior(
    store: MemoryStore,
    kinds: tuple[str, ...],
    poses: np.ndarray,
    config: MemoryConfig,
    prior_independent: float = 0.7,
) -> np.ndarray:
    """The one-locker ``(N, 2, 1 + 2N)`` prior for a task with these kinds and poses (any common frame):
    :func:`recall_memberships` with every block normalised, then ``uniform_mass`` added to every possible
    hypothesis."""
    fallback = default_prior(len(kinds), prior_independent)
    if not _recalls(store, kinds):
        return fallback
    weights = _recalled_weights(store, kinds, poses, config, fallback)
    possible = fallback > 0.0
    totals = weights.sum(axis=-1, keepdims=True)
    probs = np.where(totals > 0.0, weights / np.where(totals > 0.0, totals, 1.0), fallback)
    probs = np.where(possible, probs + config.uniform_mass, 0.0)
    return probs / probs.sum(axis=-1, keepdims=True)


def recall_memberships(
    store: MemoryStore,
    kinds: tuple[str, ...],
    poses: np.ndarray,
    config: MemoryConfig,
    prior_independent: float = 0.7,
) -> np.ndarray:
    """``(N, 2, 1 + 2N)``: what the memory recalls for each block, before any normalising (see the module
    docstring): ``[j, s_j, 0]`` the mean stored independence of ``kind_j``, ``[j, s_j, 1 + 2i + s_i]`` the
    kernel-weighted mean of the k nearest stored values of the pair — P(``(i, s_i)`` is among ``j``'s lockers
    in ``s_j``), a memory's :meth:`learning.lock_belief.LockBelief.locker_memberships` (with one locker,
    P(it *is* the locker)). Pairs and kinds the memory has never seen hold the uninformed prior's values.
    A belief over sets of lockers is built from it by :func:`learning.set_prior.membership_set_prior`."""
    fallback = default_prior(len(kinds), prior_independent)
    return _recalled_weights(store, kinds, poses, config, fallback) if _recalls(store, kinds) else fallback


def _recalled_weights(
    store: MemoryStore, kinds: tuple[str, ...], poses: np.ndarray, config: MemoryConfig, fallback: np.ndarray
) -> np.ndarray:
    """:func:`recall_memberships` for a task the memory can recall (:func:`_recalls`); ``fallback`` is the
    uninformed prior of the task."""
    n = len(kinds)
    family = kind_family(kinds[0])
    keys = se3_pose_keys(poses, store.position_scale, store.rotation_weight)
    weights = np.zeros((n, 2, hypothesis_count(n)))
    for j in range(n):
        independence = store.independence_values(kinds[j])
        weights[j, :, 0] = independence.mean(axis=0) if independence is not None else fallback[j, :, 0]
        for i in range(n):
            if i == j:
                continue
            bucket = store.pair_bucket(kinds[i], kinds[j])
            if bucket is None and config.back_off:
                bucket = store.all_pairs_bucket(family)
            if bucket is None:
                weights[j, :, 1 + 2 * i : 3 + 2 * i] = fallback[j, :, 1 + 2 * i : 3 + 2 * i]
                continue
            distances = np.linalg.norm(bucket.keys - keys[i, j], axis=1)
            nearest = nearest_pairs(distances, bucket.pairs, config.k, bucket.distinct)
            values = bucket.values[nearest, :4].reshape(-1, 2, 2)  # (k, s_j, s_i)
            # per neighbour and row s_j: kernel x confidence (ones for the paper's plain average)
            neighbour_weights = np.ones((len(nearest), 2))
            if config.bandwidth is not None:
                neighbour_weights *= np.exp(-0.5 * (distances[nearest] / config.bandwidth) ** 2)[:, None]
            if config.weight_by_confidence:
                neighbour_weights *= bucket.values[nearest, 4:6]
            # a pair met in several episodes is one neighbour: its meetings share one neighbour's weight (their
            # mean), so meeting a box again sharpens what is recalled of it but does not make it count more
            if not bucket.distinct:
                _, group, meetings = np.unique(bucket.pairs[nearest], return_inverse=True, return_counts=True)
                neighbour_weights /= meetings[group][:, None]
            uninformed = fallback[j, :, 1 + 2 * i : 3 + 2 * i]  # (s_j, s_i)
            prior_weight = config.prior_weight if config.bandwidth is not None or config.weight_by_confidence else 0.0
            total = neighbour_weights.sum(axis=0)[:, None] + prior_weight  # (s_j, 1)
            block = (np.einsum("kr,krs->rs", neighbour_weights, values) + prior_weight * uninformed) / total
            weights[j, :, 1 + 2 * i : 3 + 2 * i] = block
    return weights


def nearest_pairs(distances: np.ndarray, pairs: np.ndarray, k: int, distinct: bool | None = None) -> np.ndarray:
    """Indices of the entries of the ``k`` nearest distinct pairs: the ``k`` pair ids (``pairs``, one per pair of a
    box: :func:`learning.memory.store.pair_ids`) whose nearest entry is nearest, then every entry of those pairs. A
    box met again thus adds its new meeting to what is recalled of it, and never pushes another
    box's pair out of the ``k`` (a robot's episode on a box the simulator also met, perceived a millimetre off,
    would otherwise rank just before the simulator's, and push out whichever box ranked ``k``-th). With no box met
    twice, these are the ``k`` nearest entries, in rank order.

    Distances are rounded to :data:`KEY_DECIMALS` before ranking: equidistant memories (layouts on a grid make
    many) rank in storage order, not by 1e-15 of rounding noise that depends on where the box stands.

    ``distinct``: whether no pair was met twice (:attr:`learning.memory.store.Bucket.distinct`; None: checked here)."""
    order = np.argsort(np.round(distances, KEY_DECIMALS), kind="stable")
    if distinct if distinct is not None else (pairs == np.arange(len(pairs))).all():
        return order[:k]
    ranked = pairs[order]
    chosen: list[int] = []
    for pair in ranked:  # a pair's rank is that of its nearest entry
        if pair not in chosen:
            chosen.append(int(pair))
            if len(chosen) == k:
                break
    members = ranked == chosen[0]
    for pair in chosen[1:]:
        members |= ranked == pair
    return order[members]  # in rank order


def _recalls(store: MemoryStore, kinds: tuple[str, ...]) -> bool:
    """Whether the memory has anything to say about a task of these kinds (a memory of puzzle boxes knows
    nothing of computers)."""
    return len(kinds) >= 2 and store.holds_family(kind_family(kinds[0]))


def episode_record(view: np.ndarray, confidence: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """What an episode's learned belief contributes to memory.

    Args:
        view: ``(N, 2, 1 + 2N)``, the belief's :meth:`~learning.lock_belief.LockBelief.locker_memberships`
            (with one locker, the belief itself).
        confidence: ``(N, 2)``, how resolved each block is (:meth:`~learning.lock_belief.LockBelief.block_confidence`);
            None: that of ``view`` read as one-locker categoricals, ``1 - entropy / log(2N - 1)``.

    Returns:
        pair_values: ``(N, N, 6)``, ``[i, j]`` = ``P((i, s_i) among the lockers of j in s_j)`` for ``(s_j, s_i)``
            in (0,0), (0,1), (1,0), (1,1), then the confidence of blocks ``Z[j, 0]`` and ``Z[j, 1]``
            (1 = resolved, 0 = uniform).
        independence: ``(N, 2)``, ``P(Z[j, s] = independent)``.
    """
    n = view.shape[0]
    lockers = view[:, :, 1:].reshape(n, 2, n, 2)  # [j, s_j, i, s_i]
    pair_values = lockers.transpose(2, 0, 1, 3).reshape(n, n, 4)  # [i, j, (s_j, s_i)]
    if confidence is None:
        confidence = block_confidence(view, 2 * n - 1)  # (j, s_j): hypotheses per block, independent + 2(N-1)
    confidence_ij = np.broadcast_to(np.asarray(confidence)[None, :, :], (n, n, 2))
    return np.concatenate([pair_values, confidence_ij], axis=-1), view[:, :, 0].copy()
