"""The dual controller (the paper's Eq. 3): explore while the belief is uncertain, exploit once it is not.

``Q = w * Q_info + (1 - w) * Q_exploit`` with ``w = clip(h / h_max, 0, 1)``, ``h`` the belief entropy.
The action with the highest ``Q`` is taken; ties are broken at random (seeded), so symmetric beliefs
do not always favour the first component.

The belief is the paper's one-locker :class:`learning.belief.Belief` (``max_lockers = 1``, every
published protocol) or, with ``max_lockers = k >= 2``, :class:`learning.multi_belief.MultiBelief` over sets
of up to ``k`` lockers, its prior built from the same one-locker prior (:func:`new_belief`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from puzzlebox.learning.belief import Belief, BeliefConfig
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.exploration import information_values
from puzzlebox.learning.lock_belief import LockBelief
from puzzlebox.learning.multi_belief import MultiBelief
from puzzlebox.learning.planner import PlannerConfig, exploit_values

TIE_TOLERANCE = 1e-12
MAX_LOCKERS = 3
"""Largest ``max_lockers``: a block holds ``sum_(j <= k) C(N, j) 2^j`` sets (N = 32: 2049 at k = 2, 41729 at
k = 3), every decision reads them all; the random generator holds a closed component with at most two lockers."""


@dataclass(frozen=True)
class DualControllerConfig:
    """Settings of the dual controller and of the belief it maintains."""

    belief: BeliefConfig = field(default_factory=BeliefConfig)
    planner: PlannerConfig = field(default_factory=PlannerConfig)
    info_threshold: float = (1.0 - 0.99) * 1.01
    """Information gains below this are ignored [nats] (the authors' release: (1 - 0.99) * 1.01)."""
    max_entropy: float | None = None
    """h_max [nats]; None: ``entropy_scale`` times the entropy of a uniform belief for the task's N."""
    entropy_scale: float = 4.0
    """h_max as a multiple of the uniform belief's entropy ``2N log(2N - 1)``. The paper leaves h_max
    to tuning; 4 was chosen on a validation split (memory trained on 6 training variants, evaluated
    on the other 3; the test variants unused): 2 explored too much, larger values barely differ."""
    max_lockers: int = 1
    """k: the most lockers the belief lets one component have in one state (1..:data:`MAX_LOCKERS`). 1 is the
    paper's hypothesis space (:class:`learning.belief.Belief`, its numbers to the bit); k >= 2 believes over
    sets of up to k lockers (:class:`learning.multi_belief.MultiBelief`): a component moves only when none
    of its lockers holds it. ``h_max`` keeps the one-locker formula either way (the set prior's entropy is a
    little higher: 25.1 against 22.4 nats for the uninformed prior of 8 components, so w starts at 0.145, not
    0.129)."""

    def __post_init__(self) -> None:
        k = self.max_lockers
        if isinstance(k, bool) or not isinstance(k, int) or not 1 <= k <= MAX_LOCKERS:
            raise ConfigError(f"max_lockers must be an integer in 1..{MAX_LOCKERS}, got {k!r}")


@dataclass(frozen=True)
class Decision:
    """One decision and the values behind it (for logs and plots)."""

    action: int
    q_info: np.ndarray
    q_exploit: np.ndarray
    weight_info: float


def max_entropy_for(num_components: int, config: DualControllerConfig) -> float:
    """h_max [nats] for a task of ``num_components``."""
    if config.max_entropy is not None:
        return config.max_entropy
    n = num_components
    return config.entropy_scale * 2 * n * math.log(max(2 * n - 1, 2))


def new_belief(single_prior: np.ndarray, config: DualControllerConfig) -> LockBelief:
    """The controller's belief from a one-locker prior ``(N, 2, 1 + 2N)`` (the default or a memory's):
    itself at ``max_lockers = 1``, else the set prior built from it (:mod:`learning.set_prior`)."""
    if config.max_lockers == 1:
        return Belief(single_prior, config.belief)
    return MultiBelief.from_single_prior(single_prior, config.max_lockers, config.belief)


def decide(
    belief: LockBelief,
    states: np.ndarray,
    goal: int,
    goal_state: int,
    rng: np.random.Generator,
    config: DualControllerConfig,
    h_max: float,
    avoid: np.ndarray | None = None,
) -> Decision:
    """The dual controller's choice in joint state ``states``; ``avoid`` (bool per component) marks components not
    to choose while any other may be chosen (the robot could not try them in this state: a failed try)."""
    q_info = information_values(belief, states, config.info_threshold)
    q_exploit = exploit_values(belief, states, goal, goal_state, config.planner)
    weight = float(np.clip(belief.entropy() / h_max, 0.0, 1.0)) if h_max > 0.0 else 0.0
    q = weight * q_info + (1.0 - weight) * q_exploit
    if avoid is not None and avoid.any() and not avoid.all():
        q = np.where(avoid, -np.inf, q)
    best = np.flatnonzero(q >= q.max() - TIE_TOLERANCE)
    return Decision(int(rng.choice(best)), q_info, q_exploit, weight)
