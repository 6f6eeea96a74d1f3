"""The belief over sets of lockers: exact Bayes checked against brute force, and what it plugs into."""

import itertools

import numpy as np
import pytest

import puzzlebox.learning.planner as planner
from puzzlebox.learning.belief import BeliefConfig, default_prior
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.exploration import expected_information_gain, information_values
from puzzlebox.learning.locker_sets import locker_set_count, locker_sets
from puzzlebox.learning.multi_belief import MultiBelief
from puzzlebox.learning.planner import exploit_values, free_table, value_iteration
from puzzlebox.learning.set_prior import set_prior

EXACT = BeliefConfig(jam_probability=0.0, false_move_probability=0.0)
NOISY = BeliefConfig(jam_probability=0.05, false_move_probability=0.02)

# -- brute force, written without the belief's index arrays ------------------------------------------------
# A hypothesis of block (c, s) is a frozenset of (m, s') with m != c, distinct m, at most k of them; it holds
# c in joint state x iff some (m, s') in it has x[m] == s'.


def hypotheses(n: int, component: int, k: int) -> list[frozenset]:
    others = [m for m in range(n) if m != component]
    out = [frozenset()]
    for size in range(1, k + 1):
        for lockers in itertools.combinations(others, size):
            for states in itertools.product((0, 1), repeat=size):
                out.append(frozenset(zip(lockers, states, strict=True)))
    return out


def holds(hypothesis: frozenset, states) -> bool:
    return any(states[m] == s for m, s in hypothesis)


def likelihood(held: bool, moved: bool, config: BeliefConfig) -> float:
    eps, delta = config.jam_probability, config.false_move_probability
    if moved:
        return delta if held else 1.0 - eps
    return 1.0 - delta if held else eps


def index_of_sets(n: int, k: int) -> dict[frozenset, int]:
    """Where each hypothesis sits in the belief's layout (read from its table only to compare)."""
    sets = locker_sets(n, k)
    return {frozenset((int(p) // 2, int(p) % 2) for p in row if p < 2 * n): h for h, row in enumerate(sets.members)}


def random_block_priors(rng, n: int, k: int) -> dict[tuple[int, int], dict[frozenset, float]]:
    priors = {}
    for c, s in itertools.product(range(n), (0, 1)):
        weights = rng.random(len(hypotheses(n, c, k))) ** 2 * (rng.random(len(hypotheses(n, c, k))) < 0.8) + 1e-3
        weights /= weights.sum()
        priors[c, s] = dict(zip(hypotheses(n, c, k), weights, strict=True))
    return priors


def as_belief(priors, n: int, k: int, config: BeliefConfig) -> MultiBelief:
    where = index_of_sets(n, k)
    probs = np.zeros((n, 2, locker_set_count(n, k)))
    for (c, s), block in priors.items():
        for hypothesis, p in block.items():
            probs[c, s, where[hypothesis]] = p
    return MultiBelief(probs, k, config)


def true_observations(rng, n: int, k: int, tries: int, config: BeliefConfig):
    """Tries of random components in random states of a random true structure (outcomes flipped with the
    noise's probabilities), so exact elimination never runs out of hypotheses."""
    truth = {(c, s): hypotheses(n, c, k)[rng.integers(len(hypotheses(n, c, k)))] for c in range(n) for s in (0, 1)}
    out = []
    for _ in range(tries):
        states, c = rng.integers(0, 2, n), int(rng.integers(n))
        held = holds(truth[c, int(states[c])], states)
        moved = rng.random() < (config.false_move_probability if held else 1.0 - config.jam_probability)
        out.append((states, c, bool(moved)))
    return out


@pytest.mark.parametrize("config", [EXACT, NOISY], ids=["exact", "noisy"])
@pytest.mark.parametrize("seed", range(3))
def test_three_components_equal_bayes_over_whole_lock_structures(config, seed):
    """N = 3, k = 2: every block has 9 hypotheses, a structure one per block: 9^6 structures. Bayes over the
    structures (prior = product of the blocks) gives the marginals and the predictive probabilities."""
    n, k = 3, 2
    rng = np.random.default_rng(seed)
    priors = random_block_priors(rng, n, k)
    belief = as_belief(priors, n, k, config)
    blocks = [(c, s) for c in range(n) for s in (0, 1)]
    per_block = [hypotheses(n, c, k) for c, _ in blocks]
    structures = np.stack(np.unravel_index(np.arange(9 ** len(blocks)), (9,) * len(blocks)), axis=1)
    weights = np.ones(len(structures))
    for b, (c, s) in enumerate(blocks):
        weights *= np.array([priors[c, s][h] for h in per_block[b]])[structures[:, b]]
    weights /= weights.sum()
    where = index_of_sets(n, k)
    for states, c, moved in true_observations(rng, n, k, 8, config):
        b = blocks.index((c, int(states[c])))
        held = np.array([holds(h, states) for h in per_block[b]])[structures[:, b]]
        lik = np.array([likelihood(h, moved, config) for h in (False, True)])[held.astype(int)]
        p_move = float(
            (weights * np.array([likelihood(h, True, config) for h in (False, True)])[held.astype(int)]).sum()
        )
        assert belief.probability_moves(states, c) == pytest.approx(p_move, abs=1e-12)
        weights = weights * lik / (weights * lik).sum()
        belief.update(states, c, moved)
        for b2, (c2, s2) in enumerate(blocks):
            marginal = np.bincount(structures[:, b2], weights, minlength=9)
            expected = np.zeros(belief.sets.count)
            expected[[where[h] for h in per_block[b2]]] = marginal
            np.testing.assert_allclose(belief.probs[c2, s2], expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("config", [EXACT, NOISY], ids=["exact", "noisy"])
@pytest.mark.parametrize("seed", range(3))
def test_four_components_equal_bayes_by_hand_per_block(config, seed):
    """N = 4, k = 2 (19 hypotheses per block): each block's posterior is its prior times the likelihood of
    every try of its component in its state, normalised; the free probability in every joint state is the
    posterior mass of the hypotheses that do not hold."""
    n, k = 4, 2
    rng = np.random.default_rng(100 + seed)
    priors = random_block_priors(rng, n, k)
    belief = as_belief(priors, n, k, config)
    observations = true_observations(rng, n, k, 12, config)
    for states, c, moved in observations:
        belief.update(states, c, moved)
    posterior = {}
    for (c, s), block in priors.items():
        weights = dict(block)
        for states, tried, moved in observations:
            if tried == c and states[c] == s:
                weights = {h: w * likelihood(holds(h, states), moved, config) for h, w in weights.items()}
        total = sum(weights.values())
        posterior[c, s] = {h: w / total for h, w in weights.items()}
    where = index_of_sets(n, k)
    for (c, s), block in posterior.items():
        for hypothesis, p in block.items():
            assert belief.probs[c, s, where[hypothesis]] == pytest.approx(p, abs=1e-12)
    all_bits = (np.arange(1 << n)[:, None] >> np.arange(n)) & 1
    expected = np.array(
        [[sum(p for h, p in posterior[c, int(x[c])].items() if not holds(h, x)) for x in all_bits] for c in range(n)]
    )
    np.testing.assert_allclose(belief.free_table(), expected, atol=1e-12)
    np.testing.assert_allclose(belief.free_probabilities(all_bits), expected.T, atol=1e-12)
    for x in range(1 << n):
        np.testing.assert_allclose(belief.free_vector(x), expected[:, x], atol=1e-12)
        assert [belief.probability_free(all_bits[x], c) for c in range(n)] == pytest.approx(expected[:, x], abs=1e-12)


def test_a_component_held_by_two_lockers_is_believed_held_until_both_are_open():
    """Slide 2 is held closed by 0 and by 1 (both closed): a one-locker belief cannot say it; this one
    learns it from three tries and predicts the fourth."""
    belief = MultiBelief.uninformed(3, 2, EXACT)
    belief.update(np.array([0, 0, 0]), 2, moved=False)
    belief.update(np.array([1, 0, 0]), 2, moved=False)  # 0 open: still held (by 1)
    belief.update(np.array([0, 1, 0]), 2, moved=False)  # 1 open: still held (by 0)
    both = index_of_sets(3, 2)[frozenset({(0, 0), (1, 0)})]
    assert belief.probs[2, 0, both] == pytest.approx(1.0)
    assert belief.probability_free(np.array([1, 1, 0]), 2) == pytest.approx(1.0)
    assert belief.probability_free(np.array([1, 0, 0]), 2) == 0.0


def test_an_impossible_observation_falls_back_to_the_uninformed_block():
    belief = MultiBelief.uninformed(3, 1, EXACT)
    belief.update(np.array([0, 0, 0]), 2, moved=False)
    belief.update(np.array([1, 0, 0]), 2, moved=False)
    belief.update(np.array([0, 1, 0]), 2, moved=False)  # k = 1 cannot explain three failures
    np.testing.assert_allclose(belief.probs[2, 0], MultiBelief.uninformed(3, 1, EXACT).probs[2, 0])


def test_sets_are_the_empty_set_then_singletons_in_the_one_locker_layout_then_pairs():
    sets = locker_sets(8, 2)
    assert sets.count == locker_set_count(8, 2) == 1 + 16 + 28 * 4
    assert locker_set_count(32, 2) == 2049
    assert sets.sizes[0] == 0 and np.all(sets.members[1:17, 0] == np.arange(16))  # hypothesis 1 + 2m + s'
    owners = np.where(sets.members < 16, sets.members // 2, -1)
    assert all(len(set(row[row >= 0])) == len(row[row >= 0]) for row in owners)  # one state per locker
    for c in range(8):  # the sets containing c are not hypotheses of c's blocks
        assert np.array_equal(sets.possible[c], ~(owners == c).any(axis=1))
    with pytest.raises(ConfigError, match="max_lockers"):
        locker_sets(4, 0)


# -- the prior ---------------------------------------------------------------------------------------------


def test_the_set_prior_at_one_locker_is_the_one_locker_prior():
    rng = np.random.default_rng(0)
    n = 5
    single = default_prior(n) * rng.random((n, 2, 1 + 2 * n))
    single /= single.sum(axis=2, keepdims=True)
    np.testing.assert_allclose(set_prior(single, locker_sets(n, 1)), single, rtol=1e-12, atol=1e-15)


def test_the_set_prior_keeps_independence_and_weighs_sets_as_products_of_their_lockers():
    n = 8
    single = default_prior(n, 0.7)
    prior = MultiBelief.from_single_prior(single, 2, EXACT).probs
    sets = locker_sets(n, 2)
    np.testing.assert_allclose(prior[:, :, 0], 0.7)
    np.testing.assert_allclose(prior.sum(axis=2), 1.0)
    q = 0.3 / 14  # one pair's one-locker probability
    pairs = 21 * 4  # two-locker sets of component 7's blocks: two of the 7 others, each in one of 2 states
    two = prior[7, 0, sets.sizes == 2].sum()
    assert two == pytest.approx(0.3 * pairs * q**2 / (14 * q + pairs * q**2))  # 3.4 % of the mass
    assert two == pytest.approx(0.034, abs=0.001)
    assert np.all(prior[3, 1, ~sets.possible[3]] == 0.0)


def test_the_one_locker_view_shares_each_sets_mass_among_its_lockers():
    belief = MultiBelief.uninformed(4, 2, EXACT)
    view = belief.single_locker_probs()
    assert view.shape == (4, 2, 9)
    np.testing.assert_allclose(view.sum(axis=2), 1.0)
    np.testing.assert_allclose(view[:, :, 0], belief.probs[:, :, 0])
    assert np.all(view[1, :, 3:5] == 0.0)  # component 1 never holds itself


# -- exploration and planning over sets ----------------------------------------------------------------------


def random_multi_belief(seed: int, n: int, config: BeliefConfig = NOISY, tries: int = 6) -> MultiBelief:
    rng = np.random.default_rng(seed)
    belief = as_belief(random_block_priors(rng, n, 2), n, 2, config)
    for states, c, moved in true_observations(rng, n, 2, tries, config):
        belief.update(states, c, moved)
    return belief


@pytest.mark.parametrize("seed", range(4))
def test_information_values_over_sets_equal_the_mutual_information_by_hand(seed):
    n = 4
    belief = random_multi_belief(seed, n)
    states = np.random.default_rng(seed).integers(0, 2, n)
    values = information_values(belief, states)
    for c in range(n):
        block = belief.probs[c, states[c]]
        held = np.array([holds(h, states) for h in hypotheses(n, c, 2)])
        where = [index_of_sets(n, 2)[h] for h in hypotheses(n, c, 2)]
        p = block[where]
        mutual = 0.0
        for moved in (True, False):
            lik = np.array([likelihood(h, moved, NOISY) for h in held])
            p_outcome = float((p * lik).sum())
            post = p * lik / p_outcome
            mutual += p_outcome * float(np.sum(np.where(post > 0, post * np.log(np.where(post > 0, post / p, 1)), 0)))
        assert values[c] == pytest.approx(mutual, abs=1e-12)
        assert expected_information_gain(belief, states, c) == pytest.approx(mutual, abs=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_exploit_values_over_sets_are_the_bellman_values_of_the_free_table(seed):
    n, goal, goal_state, gamma = 5, seed % 5, 1, 0.9
    belief = random_multi_belief(seed, n)
    table = free_table(belief)
    values = value_iteration(table, goal, goal_state, gamma)
    for x in range(1 << n):
        if (x >> goal) & 1 == goal_state:
            continue
        states = (x >> np.arange(n)) & 1
        q = exploit_values(belief, states, goal, goal_state)
        expected = [gamma * table[c, x] * values[x ^ (1 << c)] for c in range(n)]
        np.testing.assert_allclose(q, expected, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("seed", range(4))
def test_best_first_search_over_sets_equals_value_iteration(seed, monkeypatch):
    """Beyond the exact planner's size A* runs with the generic heuristic: with an ample budget it finds
    the same values (it is admissible)."""
    n, goal = 6, seed % 6
    belief = random_multi_belief(seed, n, EXACT, tries=10)
    rng = np.random.default_rng(seed)
    config = planner.PlannerConfig(max_expansions=10**6)
    cases = [rng.integers(0, 2, n) for _ in range(5)]
    for states in cases:
        states[goal] = 0
    exact = [exploit_values(belief, states, goal, 1, config) for states in cases]
    monkeypatch.setattr(planner, "EXACT_MAX_COMPONENTS", 0)
    searched = [exploit_values(belief, states, goal, 1, config) for states in cases]
    np.testing.assert_allclose(searched, exact, rtol=1e-9, atol=1e-15)


def test_open_rows_are_the_free_tables_non_goal_columns():
    n, goal, goal_state = 6, 2, 1
    belief = random_multi_belief(7, n)
    index = np.arange(1 << n)
    open_states = index[((index >> goal) & 1) != goal_state]
    rows = np.array([0, 2, 5])
    np.testing.assert_allclose(
        belief.open_free_rows(rows, goal, goal_state), free_table(belief)[rows][:, open_states], atol=1e-15
    )


def test_free_upper_bounds_bound_every_state():
    n = 5
    belief = random_multi_belief(3, n)
    table, bounds = free_table(belief), belief.free_upper_bounds()
    own = (np.arange(1 << n)[None, :] >> np.arange(n)[:, None]) & 1
    for s in (0, 1):
        assert np.all(np.where(own == s, table, 0.0).max(axis=1) <= bounds[:, s] + 1e-12)


def test_the_generic_heuristic_is_admissible_for_the_one_locker_belief_too():
    """The set planner asks only for free probabilities and their bounds: over a one-locker belief its A*
    finds the values of value iteration as well."""
    from random_beliefs import random_problem

    from puzzlebox.learning.set_best_first import SetBestFirstPlanner

    for seed in range(3):
        rng, belief, goal, goal_state = random_problem(seed, 6)
        values = planner.state_values(belief, goal, goal_state, 0.9)
        search = SetBestFirstPlanner(belief, goal, goal_state, 0.9)
        table = free_table(belief)
        for x in rng.integers(0, 1 << 6, size=6):
            if (x >> goal) & 1 == goal_state:
                continue
            expected = [0.9 * table[c, x] * values[x ^ (1 << c)] for c in range(6)]
            np.testing.assert_allclose(search.exploit_values(int(x), budget=10**6), expected, rtol=1e-9, atol=1e-15)
