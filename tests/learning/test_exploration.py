"""Exploration values (Eq. 1): expected KL between posterior and belief, i.e. the mutual information."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from puzzlebox.learning.belief import Belief, BeliefConfig, default_prior, hypothesis_count
from puzzlebox.learning.exploration import expected_information_gain, information_values, kl_divergence

EXACT = BeliefConfig(jam_probability=0.0, false_move_probability=0.0)
"""The paper's exact elimination (the library default adds a 0.001 noise floor)."""


def binary_entropy(p: float) -> float:
    return float(-sum(q * np.log(q) for q in (p, 1.0 - p) if q > 0.0))


def mutual_information(belief: Belief, states: np.ndarray, component: int) -> float:
    """I(outcome; Z[component, x_c]) = H(outcome) - E_h H(outcome | h), computed independently of KL."""
    block = belief.probs[component, int(states[component])]
    held = belief.held_mask(states, component)
    eps, delta = belief.config.jam_probability, belief.config.false_move_probability
    p_move_given_h = np.where(held, delta, 1.0 - eps)
    p_move = float((block * p_move_given_h).sum())
    conditional = sum(b * binary_entropy(float(q)) for b, q in zip(block, p_move_given_h, strict=True))
    return binary_entropy(p_move) - conditional


@st.composite
def belief_and_states(draw, noisy: bool | None = None):
    n = draw(st.integers(2, 6))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    probs = rng.random((n, 2, hypothesis_count(n))) ** draw(st.sampled_from([1.0, 4.0, 12.0]))
    zero_out = rng.random(probs.shape) < draw(st.sampled_from([0.0, 0.3, 0.7]))
    probs[zero_out] = 0.0
    probs[:, :, 0] += 1e-6  # no block without mass
    if noisy is None:
        noisy = draw(st.booleans())
    config = (
        BeliefConfig(jam_probability=draw(st.floats(0.0, 0.3)), false_move_probability=draw(st.floats(0.0, 0.3)))
        if noisy
        else EXACT
    )
    states = rng.integers(0, 2, size=n)
    return Belief(probs, config), states


@settings(max_examples=150, deadline=None)
@given(belief_and_states())
def test_information_gain_is_non_negative_and_equals_the_mutual_information(case):
    belief, states = case
    for c in range(belief.num_components):
        gain = expected_information_gain(belief, states, c)
        assert gain >= 0.0
        assert gain == pytest.approx(mutual_information(belief, states, c), abs=1e-9)
        # never more than the block's entropy nor one bit of a binary outcome
        assert gain <= np.log(2) + 1e-12


@settings(max_examples=100, deadline=None)
@given(belief_and_states())
def test_information_gain_is_the_expected_drop_in_block_entropy(case):
    belief, states = case
    for c in range(belief.num_components):
        before = belief.entropy()
        p_move = belief.probability_moves(states, c)
        expected_after = 0.0
        for moved, p in ((True, p_move), (False, 1.0 - p_move)):
            if p <= 1e-15:
                continue
            after = belief.copy()
            after.update(states, c, moved)
            expected_after += p * after.entropy()
        assert before - expected_after == pytest.approx(expected_information_gain(belief, states, c), abs=1e-9)


@settings(max_examples=100, deadline=None)
@given(st.integers(1, 12), st.integers(0, 2**32 - 1))
def test_kl_divergence_is_non_negative_and_zero_only_for_equal_distributions(size, seed):
    rng = np.random.default_rng(seed)
    q = rng.random(size) + 1e-3
    q /= q.sum()
    p = rng.random(size) * (rng.random(size) < 0.7)
    if p.sum() == 0.0:
        p[0] = 1.0
    p /= p.sum()
    assert kl_divergence(p, q) >= -1e-15
    assert kl_divergence(q, q) == 0.0
    expected = sum(a * np.log(a / b) for a, b in zip(p, q, strict=True) if a > 0)
    assert kl_divergence(p, q) == pytest.approx(expected, abs=1e-12)


def test_kl_divergence_of_known_distributions():
    p = np.array([0.5, 0.5, 0.0])
    q = np.array([0.25, 0.25, 0.5])
    assert kl_divergence(p, q) == pytest.approx(np.log(2.0))


@pytest.mark.parametrize("noisy", [False, True])
def test_resolved_block_gives_exactly_zero_information(noisy):
    config = BeliefConfig(jam_probability=0.1, false_move_probability=0.05) if noisy else EXACT
    n = 4
    probs = default_prior(n)
    states = np.array([0, 1, 1, 0])
    probs[2, 1] = 0.0
    probs[2, 1, 1 + 2 * 0 + 0] = 1.0  # Z[2, 1] resolved: held by component 0 in state 0
    probs[3, 0] = 0.0
    probs[3, 0, 0] = 1.0  # Z[3, 0] resolved: independent
    belief = Belief(probs, config)
    assert expected_information_gain(belief, states, 2) == 0.0
    assert expected_information_gain(belief, states, 3) == 0.0
    values = information_values(belief, states)
    assert values[2] == 0.0 and values[3] == 0.0
    assert values[0] > 0.0 and values[1] > 0.0  # the other blocks are still uncertain


@pytest.mark.parametrize("noisy", [False, True])
def test_block_whose_hypotheses_all_predict_the_same_outcome_gives_no_information(noisy):
    config = BeliefConfig(jam_probability=0.2, false_move_probability=0.1) if noisy else EXACT
    n = 3
    states = np.array([1, 0, 0])
    probs = default_prior(n)
    # Z[2, 0] spread over "independent" and lockers inactive in `states` (0 open, 1 open): all say free
    probs[2, 0] = 0.0
    probs[2, 0, [0, 1 + 2 * 0 + 0, 1 + 2 * 1 + 1]] = [0.5, 0.3, 0.2]
    # Z[1, 0] spread over lockers active in `states` (0 in 1, 2 in 0): all say held
    probs[1, 0] = 0.0
    probs[1, 0, [1 + 2 * 0 + 1, 1 + 2 * 2 + 0]] = [0.6, 0.4]
    belief = Belief(probs, config)
    assert expected_information_gain(belief, states, 2) == pytest.approx(0.0, abs=1e-12)
    assert expected_information_gain(belief, states, 1) == pytest.approx(0.0, abs=1e-12)
    # the same blocks are informative in a state that separates their hypotheses
    assert expected_information_gain(belief, np.array([0, 0, 0]), 2) > 0.01
    assert expected_information_gain(belief, np.array([1, 1, 0]), 1) > 0.01


def test_information_values_drop_gains_below_the_threshold():
    belief = Belief.uninformed(4, EXACT)
    states = np.zeros(4, dtype=np.int64)
    raw = information_values(belief, states)
    assert np.all(raw > 0.0)
    np.testing.assert_allclose(raw, [expected_information_gain(belief, states, c) for c in range(4)])
    assert np.all(information_values(belief, states, threshold=raw.max() + 1e-9) == 0.0)


def test_more_uncertain_block_is_worth_more_to_try():
    states = np.zeros(3, dtype=np.int64)
    certain = Belief.uninformed(3, BeliefConfig(prior_independent=0.99))
    uncertain = Belief.uninformed(3, BeliefConfig(prior_independent=0.5))
    assert expected_information_gain(uncertain, states, 0) > expected_information_gain(certain, states, 0)
