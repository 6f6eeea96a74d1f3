"""The belief over lock structures: Bayes updates checked against brute-force enumeration."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from puzzlebox.learning.belief import Belief, BeliefConfig, block_entropy, default_prior, hypothesis_count
from puzzlebox.learning.errors import ConfigError

EXACT = BeliefConfig(jam_probability=0.0, false_move_probability=0.0)
"""The paper's exact elimination (the library default adds a 0.001 noise floor)."""

# -- brute force over whole structures ---------------------------------------------------------------
# A structure assigns one hypothesis to every block (n, s): 0 = independent or 1 + 2m + s' (m != n).
# The prior over structures is the product of the blocks; Bayes runs over whole structures and the
# marginals per block are compared with the factored Belief.


def allowed_hypotheses(n: int, component: int) -> list[int]:
    return [0] + [1 + 2 * m + s for m in range(n) if m != component for s in (0, 1)]


def all_structures(n: int) -> np.ndarray:
    """``(S, 2N)`` hypothesis per block, block index ``2 * component + state``."""
    per_block = [allowed_hypotheses(n, c) for c in range(n) for _ in (0, 1)]
    return np.array(list(itertools.product(*per_block)), dtype=np.int64)


def structure_is_held(structures: np.ndarray, states: np.ndarray, component: int) -> np.ndarray:
    """Whether ``component`` is held in joint state ``states`` under every structure."""
    h = structures[:, 2 * component + int(states[component])]
    locker, locker_state = (h - 1) // 2, (h - 1) % 2
    return (h > 0) & (np.asarray(states)[np.clip(locker, 0, None)] == locker_state)


def outcome_likelihood(held: np.ndarray, moved: bool, eps: float, delta: float) -> np.ndarray:
    if moved:
        return np.where(held, delta, 1.0 - eps)
    return np.where(held, 1.0 - delta, eps)


class BruteForce:
    def __init__(self, prior: np.ndarray) -> None:
        n = prior.shape[0]
        self.n = n
        self.structures = all_structures(n)
        self.weights = np.ones(len(self.structures))
        for b in range(2 * n):
            self.weights *= prior[b // 2, b % 2][self.structures[:, b]]
        self.weights /= self.weights.sum()

    def probability_of(self, states, component, moved, eps, delta) -> float:
        held = structure_is_held(self.structures, states, component)
        return float((self.weights * outcome_likelihood(held, moved, eps, delta)).sum())

    def update(self, states, component, moved, eps, delta) -> None:
        held = structure_is_held(self.structures, states, component)
        self.weights = self.weights * outcome_likelihood(held, moved, eps, delta)
        self.weights /= self.weights.sum()

    def marginals(self) -> np.ndarray:
        out = np.zeros((self.n, 2, hypothesis_count(self.n)))
        for b in range(2 * self.n):
            out[b // 2, b % 2] = np.bincount(
                self.structures[:, b], weights=self.weights, minlength=hypothesis_count(self.n)
            )
        return out


# -- strategies ---------------------------------------------------------------------------------------
# exact zeros exercise elimination; no tiny masses, whose products would underflow in the brute force
PROBABILITY = st.one_of(st.just(0.0), st.floats(1e-3, 1.0), st.sampled_from([0.05, 0.3, 0.7]))


@st.composite
def priors(draw, n: int) -> np.ndarray:
    probs = np.array(draw(st.lists(PROBABILITY, min_size=2 * n * (1 + 2 * n), max_size=2 * n * (1 + 2 * n))))
    probs = probs.reshape(n, 2, 1 + 2 * n)
    for c in range(n):
        probs[c, :, 1 + 2 * c : 3 + 2 * c] = 0.0
    probs[probs.sum(axis=-1) <= 1e-9] = default_prior(n)[0, 0]  # every block needs some mass
    return probs / probs.sum(axis=-1, keepdims=True)


@st.composite
def observations(draw, n: int, max_size: int = 8) -> list[tuple[np.ndarray, int, bool]]:
    count = draw(st.integers(0, max_size))
    return [
        (
            np.array(draw(st.lists(st.integers(0, 1), min_size=n, max_size=n)), dtype=np.int64),
            draw(st.integers(0, n - 1)),
            draw(st.booleans()),
        )
        for _ in range(count)
    ]


@st.composite
def belief_cases(draw, noisy: bool):
    n = draw(st.integers(2, 3))
    if noisy:
        eps = draw(st.floats(0.01, 0.4))
        delta = draw(st.floats(0.01, 0.4))
    else:
        eps = delta = 0.0
    return n, eps, delta, draw(priors(n)), draw(observations(n))


def check_against_brute_force(n, eps, delta, prior, obs) -> None:
    config = BeliefConfig(jam_probability=eps, false_move_probability=delta)
    belief = Belief(prior, config)
    brute = BruteForce(prior)
    np.testing.assert_allclose(belief.probs, brute.marginals(), atol=1e-12)
    for states, component, moved in obs:
        if brute.probability_of(states, component, moved, eps, delta) <= 0.0:
            moved = not moved  # this outcome is impossible: the other one then has probability 1
        assert brute.probability_of(states, component, moved, eps, delta) > 0.0
        np.testing.assert_allclose(
            belief.probability_moves(states, component),
            brute.probability_of(states, component, True, eps, delta),
            atol=1e-12,
        )
        belief.update(states, component, moved)
        brute.update(states, component, moved, eps, delta)
        np.testing.assert_allclose(belief.probs, brute.marginals(), atol=1e-9)
        np.testing.assert_allclose(belief.probs.sum(axis=-1), 1.0, atol=1e-12)


@settings(max_examples=60, deadline=None)
@given(belief_cases(noisy=False))
def test_exact_update_equals_brute_force_bayes_over_whole_structures(case):
    check_against_brute_force(*case)


@settings(max_examples=60, deadline=None)
@given(belief_cases(noisy=True))
def test_noisy_update_equals_brute_force_bayes_over_whole_structures(case):
    check_against_brute_force(*case)


@pytest.mark.parametrize("n", [2, 3, 5])
def test_default_prior_keeps_independence_and_spreads_the_rest_over_other_components(n):
    prior = default_prior(n, 0.6)
    np.testing.assert_allclose(prior.sum(axis=-1), 1.0)
    np.testing.assert_allclose(prior[:, :, 0], 0.6)
    for c in range(n):
        assert np.all(prior[c, :, 1 + 2 * c : 3 + 2 * c] == 0.0)
        others = np.delete(prior[c, :, 1:].reshape(2, n, 2), c, axis=1)
        np.testing.assert_allclose(others, 0.4 / (2 * (n - 1)))


# -- elimination ----------------------------------------------------------------------------------------


def random_states(rng, n):
    return rng.integers(0, 2, size=n)


def active_lockers(states: np.ndarray, component: int) -> list[int]:
    """Hypothesis indices of lockers that hold ``component`` in ``states``."""
    n = len(states)
    return [1 + 2 * m + int(states[m]) for m in range(n) if m != component]


@pytest.mark.parametrize("seed", range(20))
def test_exact_failed_try_leaves_only_the_active_lockers(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    belief = Belief.uninformed(n, EXACT)
    states, component = random_states(rng, n), int(rng.integers(n))
    before = belief.probs.copy()
    belief.update(states, component, moved=False)
    block = belief.probs[component, states[component]]
    active = active_lockers(states, component)
    assert block[0] == 0.0  # "independent" is eliminated
    assert np.all(np.delete(block, active) == 0.0)  # so is every locker not active in this state
    assert np.all(block[active] > 0.0)
    np.testing.assert_allclose(block[active], 1.0 / len(active))  # uniform prior over lockers stays uniform
    # every other block is untouched
    untouched = np.ones((n, 2), dtype=bool)
    untouched[component, states[component]] = False
    np.testing.assert_array_equal(belief.probs[untouched], before[untouched])


@pytest.mark.parametrize("seed", range(20))
def test_exact_successful_try_eliminates_every_active_locker(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    belief = Belief.uninformed(n, EXACT)
    states, component = random_states(rng, n), int(rng.integers(n))
    belief.update(states, component, moved=True)
    block = belief.probs[component, states[component]]
    active = active_lockers(states, component)
    assert np.all(block[active] == 0.0)
    inactive = [1 + 2 * m + 1 - int(states[m]) for m in range(n) if m != component]
    assert block[0] > 0.0 and np.all(block[inactive] > 0.0)
    assert belief.probability_free(states, component) == pytest.approx(1.0)
    assert belief.probability_moves(states, component) == pytest.approx(1.0)


def test_exact_tries_in_two_states_pin_down_the_locker():
    # 3 components; component 2 is held closed by component 0 in state 1.
    belief = Belief.uninformed(3, EXACT)
    belief.update(np.array([1, 0, 0]), 2, moved=False)  # held: (0, 1) or (1, 0)
    belief.update(np.array([1, 1, 0]), 2, moved=False)  # held: (0, 1) or (1, 1) -> only (0, 1) remains
    expected = np.zeros(hypothesis_count(3))
    expected[1 + 2 * 0 + 1] = 1.0
    np.testing.assert_array_equal(belief.probs[2, 0], expected)
    assert belief.probability_free(np.array([1, 0, 0]), 2) == 0.0
    assert belief.probability_free(np.array([0, 1, 0]), 2) == 1.0


def test_noisy_single_false_failure_does_not_eliminate_the_truth():
    config = BeliefConfig(prior_independent=0.7, jam_probability=0.1, false_move_probability=0.05)
    belief = Belief.uninformed(4, config)
    states = np.array([0, 1, 0, 0])
    belief.update(states, 2, moved=False)  # the truth: component 2 is independent, the try jammed
    block = belief.probs[2, 0]
    assert 0.0 < block[0] < 0.7  # less likely, not impossible
    assert np.all(block[[1 + 2 * m + s for m in (0, 1, 3) for s in (0, 1)]] > 0.0)
    # a few successful tries recover the truth
    for _ in range(4):
        belief.update(states, 2, moved=True)
    assert belief.probs[2, 0, 0] > 0.7


def test_noisy_false_move_does_not_eliminate_an_active_locker():
    config = BeliefConfig(jam_probability=0.05, false_move_probability=0.1)
    belief = Belief.uninformed(3, config)
    states = np.array([0, 0, 0])
    belief.update(states, 1, moved=False)
    held_by_0 = belief.probs[1, 0, 1 + 2 * 0 + 0]
    belief.update(states, 1, moved=True)  # misread: the locker is still possible
    assert 0.0 < belief.probs[1, 0, 1 + 2 * 0 + 0] < held_by_0


def test_impossible_observation_without_noise_falls_back_to_the_uninformed_block():
    belief = Belief.uninformed(3, EXACT)
    states = np.array([0, 0, 0])
    belief.update(states, 1, moved=True)
    belief.update(np.array([1, 0, 1]), 1, moved=True)  # block Z[1, 0] now: independent only
    belief.update(states, 1, moved=False)  # impossible under the belief (e.g. two lockers)
    np.testing.assert_allclose(belief.probs[1, 0], default_prior(3)[1, 0])
    assert np.all(np.isfinite(belief.probs))


# -- marginals and entropy ---------------------------------------------------------------------------------


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 4).flatmap(lambda n: priors(n)))
def test_free_probabilities_match_probability_free_in_every_state(prior):
    belief = Belief(prior, EXACT)
    n = belief.num_components
    bits = np.array(list(itertools.product((0, 1), repeat=n)))
    table = belief.free_probabilities(bits)
    for row, states in enumerate(bits):
        for c in range(n):
            assert table[row, c] == pytest.approx(belief.probability_free(states, c), abs=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 3).flatmap(lambda n: priors(n)))
def test_probability_free_equals_the_brute_force_marginal(prior):
    belief = Belief(prior, EXACT)
    brute = BruteForce(belief.probs)
    n = belief.num_components
    for states in itertools.product((0, 1), repeat=n):
        states = np.array(states)
        for c in range(n):
            free = 1.0 - float(brute.weights[structure_is_held(brute.structures, states, c)].sum())
            assert belief.probability_free(states, c) == pytest.approx(free, abs=1e-12)


def test_entropy_is_the_sum_of_block_entropies_and_zero_when_resolved():
    belief = Belief.uninformed(4, EXACT)
    block = default_prior(4)[0, 0]
    nonzero = block[block > 0]
    assert belief.entropy() == pytest.approx(8 * float(-(nonzero * np.log(nonzero)).sum()))
    resolved = np.zeros((4, 2, hypothesis_count(4)))
    resolved[:, :, 0] = 1.0
    assert Belief(resolved).entropy() == 0.0
    assert block_entropy(np.array([0.5, 0.5, 0.0])) == pytest.approx(np.log(2))


def test_entropy_falls_after_an_exact_failed_try():
    belief = Belief.uninformed(3, EXACT)
    before = belief.entropy()
    belief.update(np.array([0, 0, 0]), 2, moved=False)
    assert belief.entropy() < before


def test_self_locking_hypotheses_are_masked_and_blocks_renormalised():
    probs = np.ones((3, 2, hypothesis_count(3)))
    belief = Belief(probs, EXACT)
    for c in range(3):
        assert np.all(belief.probs[c, :, 1 + 2 * c : 3 + 2 * c] == 0.0)
    np.testing.assert_allclose(belief.probs.sum(axis=-1), 1.0)
    np.testing.assert_allclose(belief.probs[0, 0, [0, 3, 4, 5, 6]], 0.2)


def test_invalid_beliefs_and_configs_are_config_errors():
    with pytest.raises(ConfigError):
        Belief(np.ones((3, 2, 5)))  # wrong hypothesis count
    with pytest.raises(ConfigError):
        Belief(np.zeros((2, 2, 5)))  # no mass
    bad = default_prior(2)
    bad[0, 0, 0] = -1.0
    with pytest.raises(ConfigError):
        Belief(bad)
    with pytest.raises(ConfigError):
        BeliefConfig(jam_probability=0.6, false_move_probability=0.4)
    with pytest.raises(ConfigError):
        BeliefConfig(prior_independent=1.5)
