"""Which pairs can hold anything at all: a kind family's rule, as a mask over the beliefs' lockers.

A pair ``p = 2m + s'`` is "component ``m`` in state ``s'``". In the disassembly family state 1 is *removed*,
and a part out of the case holds nothing (:func:`models.disassembly_kinds.holding_states`); the puzzle-box
kinds hold in both states. A belief whose prior gives a pair no mass never gives it any (Bayes multiplies),
so masking the prior is all it takes: the agents do it when ``BeliefConfig.family_holding_states`` is set.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from puzzlebox.learning.errors import ConfigError
from puzzlebox.models.disassembly_kinds import holding_states


def holding_pairs(kinds: Sequence[str]) -> np.ndarray:
    """``(2N,)`` bool: pair ``2m + s'`` can hold, i.e. ``s'`` is one of ``kinds[m]``'s holding states."""
    pairs = np.zeros(2 * len(kinds), dtype=bool)
    for m, kind in enumerate(kinds):
        for state in holding_states(kind):
            pairs[2 * m + state] = True
    return pairs


def restrict_single_prior(prior: np.ndarray, holding: np.ndarray) -> np.ndarray:
    """A one-locker prior ``(N, 2, 1 + 2N)`` with the pairs that cannot hold given no mass, renormalised."""
    prior = np.asarray(prior, dtype=np.float64)
    holding = np.asarray(holding, dtype=bool)
    if prior.ndim != 3 or holding.shape != (prior.shape[2] - 1,):
        raise ConfigError(
            f"a mask of {prior.shape[2] - 1} pairs for a prior of shape {prior.shape}, got {holding.shape}"
        )
    if holding.all():
        return prior
    restricted = np.where(np.concatenate([[True], holding])[None, None, :], prior, 0.0)
    return restricted / restricted.sum(axis=2, keepdims=True)
