"""What a memory stores of a belief over sets of lockers: each pair's probability of being *among* the lockers,
so "held by both screws" is remembered (and recalled) as such, not as "by one of them"."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.learning.agents.dual_agent import MemoryAgent
from puzzlebox.learning.belief import Belief, block_confidence, hypothesis_count
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.locker_sets import locker_sets
from puzzlebox.learning.memory.keys import se3_pose_keys
from puzzlebox.learning.memory.prior import episode_record
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.learning.multi_belief import MultiBelief
from puzzlebox.learning.set_prior import membership_set_prior
from puzzlebox.models.observation import ComponentObservation, SceneObservation

N = 3  # screw-1 (0), screw-2 (1), panel (2)
KINDS = ("screw", "screw", "panel")
POSES = np.array([[0.0, 0.0, 0.0, 0, 0, 0], [0.0, 0.0, -0.37, 0, 0, 0], [-0.24, 0.0, -0.185, 0, 0, np.pi / 2]])


def set_index(sets, *pairs: int) -> int:
    """Index of the set of ``pairs`` (``2m + s'``) in ``sets``."""
    padded = sorted(pairs) + [2 * sets.num_components] * (sets.max_lockers - len(pairs))
    return int(np.flatnonzero((sets.members == padded).all(axis=1))[0])


def panel_belief(mass: dict[tuple[int, ...], float]) -> MultiBelief:
    """A two-locker belief whose panel block (state 0) puts ``mass`` on sets of pairs; the rest uninformed."""
    belief = MultiBelief.uninformed(N, 2)
    sets = belief.sets
    block = np.zeros(sets.count)
    for pairs, p in mass.items():
        block[set_index(sets, *pairs)] = p
    belief.probs[2, 0] = block
    return belief


def test_memberships_tell_both_lockers_from_either_where_the_one_locker_view_cannot():
    both, either = panel_belief({(0, 2): 1.0}), panel_belief({(0,): 0.5, (2,): 0.5})
    np.testing.assert_allclose(both.single_locker_probs()[2, 0], either.single_locker_probs()[2, 0])
    np.testing.assert_allclose(both.locker_memberships()[2, 0, [1, 3]], [1.0, 1.0])
    np.testing.assert_allclose(either.locker_memberships()[2, 0, [1, 3]], [0.5, 0.5])
    assert both.block_confidence()[2, 0] == pytest.approx(1.0)
    assert either.block_confidence()[2, 0] < 1.0


def test_a_one_locker_belief_is_its_own_memberships_and_keeps_its_confidence():
    rng = np.random.default_rng(0)
    belief = Belief(rng.random((4, 2, hypothesis_count(4))))
    np.testing.assert_array_equal(belief.locker_memberships(), belief.probs)
    stored, _ = episode_record(belief.locker_memberships(), belief.block_confidence())
    default, _ = episode_record(belief.probs)
    np.testing.assert_array_equal(stored, default)
    np.testing.assert_array_equal(belief.block_confidence(), block_confidence(belief.probs, 7))


def test_the_set_prior_of_memberships_recalls_the_pair_of_lockers():
    sets = locker_sets(N, 2)
    view = np.zeros((N, 2, hypothesis_count(N)))
    view[:, :, 0] = 0.7
    view[2, 0, 0], view[2, 0, [1, 3]] = 0.0, 0.99  # held by nothing: 0; both screws among its lockers
    prior = membership_set_prior(view, sets)
    np.testing.assert_allclose(prior.sum(axis=2), 1.0)
    assert prior[2, 0, set_index(sets, 0, 2)] > 0.95
    view[2, 0, [1, 3]] = 0.5  # either screw
    prior = membership_set_prior(view, sets)
    singles = prior[2, 0, [set_index(sets, 0), set_index(sets, 2)]]
    np.testing.assert_allclose(singles, prior[2, 0, set_index(sets, 0, 2)], rtol=0.1)  # a third each, about
    assert prior[2, 0, 0] == pytest.approx(0.01)  # the floor: "independent" is never ruled out


def test_the_set_prior_of_memberships_rules_out_the_pairs_that_cannot_hold_and_refuses_bad_input():
    sets = locker_sets(N, 2)
    view = np.full((N, 2, hypothesis_count(N)), 0.3)
    holding = np.array([True, False, True, False, True, False])
    prior = membership_set_prior(view, sets, holding=holding)
    with_removed = ((sets.members % 2 == 1) & (sets.members < 2 * N)).any(axis=1)
    assert np.all(prior[:, :, with_removed] == 0.0) and np.allclose(prior.sum(axis=2), 1.0)
    with pytest.raises(ConfigError, match="shape"):
        membership_set_prior(view[:, :, :-1], sets)
    with pytest.raises(ConfigError, match="floor"):
        membership_set_prior(view, sets, floor=0.0)


def test_a_memory_of_both_screws_starts_the_next_belief_on_both():
    """Stored, recalled at the same pose, and built into a set prior: the two-screw set outweighs each screw."""
    store = MemoryStore(position_scale=0.05)
    learned = panel_belief({(0, 2): 1.0})
    pair_values, independence = episode_record(learned.locker_memberships(), learned.block_confidence())
    store.add_episode(KINDS, se3_pose_keys(POSES, 0.05), pair_values, independence, spec="case", solved=True,
                      num_actions=4)  # fmt: skip
    components = tuple(ComponentObservation(kind, pose, 0) for kind, pose in zip(KINDS, POSES, strict=True))
    observation = SceneObservation(components, goal_index=2, goal_state=1)
    belief = MemoryAgent(store, config=DualControllerConfig(max_lockers=2)).initial_belief(observation)
    block = belief.probs[2, 0]
    both, one, other = (block[set_index(belief.sets, *pairs)] for pairs in ((0, 2), (0,), (2,)))
    assert both > 2 * (one + other)
