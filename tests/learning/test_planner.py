"""The exploitation planner (Eq. 2): values over joint states, exact and best-first."""

import collections
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import puzzlebox.learning.planner as planner
from puzzlebox.learning.belief import Belief, BeliefConfig, hypothesis_count
from puzzlebox.learning.planner import PlannerConfig, exploit_values, free_table, state_values
from puzzlebox.models import LockTable
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_random, paper_family

SYMBOLIC_BOX = BoxConfig(realizable=False)
"""Random boxes as drawn before lock mechanisms existed: these symbolic tests chose their seeds for their graphs."""

EXACT = BeliefConfig(jam_probability=0.0, false_move_probability=0.0)
"""The paper's exact elimination (the library default adds a 0.001 noise floor)."""


def one_locker_per_block(spec) -> bool:
    """Whether every block (component, state) of ``spec`` has at most one locker."""
    table = LockTable.from_spec(spec)
    blocks = collections.Counter(zip(table.locked.tolist(), table.locked_state.tolist(), strict=True))
    return max(blocks.values(), default=0) <= 1


def single_locker_specs():
    """Paper chains and small random specs whose blocks have at most one locker each."""
    specs = list(paper_family("all"))
    for n, seed in itertools.product((3, 4, 6, 8), range(4)):
        specs.append(generate_random(RandomGraphConfig(n, reverse_lock_probability=0.0), seed, box=SYMBOLIC_BOX))
    for n, seed in itertools.product((4, 6, 7), range(8)):
        spec = generate_random(RandomGraphConfig(n), seed, box=SYMBOLIC_BOX)
        if one_locker_per_block(spec):
            specs.append(spec)
    return specs


SPECS = single_locker_specs()


def true_structure_belief(table: LockTable, confidence: float = 1.0) -> Belief:
    """A belief with ``confidence`` on the spec's true structure (indices = spec component order)."""
    n = table.num_components
    truth = np.zeros((n, 2, hypothesis_count(n)))
    truth[:, :, 0] = 1.0
    for locker, locker_state, locked, locked_state in zip(
        table.locker, table.locker_state, table.locked, table.locked_state, strict=True
    ):
        truth[locked, locked_state] = 0.0
        truth[locked, locked_state, 1 + 2 * locker + locker_state] = 1.0
    if confidence == 1.0:
        return Belief(truth)
    possible = Belief.uninformed(n, EXACT).probs > 0.0
    rest = possible & (truth == 0.0)
    probs = confidence * truth + (1.0 - confidence) * rest / rest.sum(axis=-1, keepdims=True)
    return Belief(probs, EXACT)


def bits_of(x: int, n: int) -> np.ndarray:
    return (x >> np.arange(n)) & 1


def greedy_exploit_length(table: LockTable, belief: Belief, config: PlannerConfig, limit: int = 40) -> int:
    """Take argmax Q_exploit and toggle until the goal: the number of actions; every one must move."""
    n = table.num_components
    x = 0
    for step in range(limit):
        if table.is_goal(x):
            return step
        q = exploit_values(belief, bits_of(x, n), table.goal, table.goal_state, config)
        action = int(np.argmax(q))
        assert q[action] > 0.0
        assert table.can_move(x, action), f"the planner tried a locked component {action} in state {x:b}"
        x ^= 1 << action
    raise AssertionError(f"no goal within {limit} actions")


def test_paper_chains_and_random_graphs_without_reverse_locks_hold_each_block_by_one_locker():
    """The premise of the specs these tests take unfiltered: a random graph without reverse locks is a tree of
    "anchor closed keeps new closed" rules (one locker for every component but the first), and the paper's chains
    hold each block by one locker; with reverse locks an anchor may be kept open by several new components."""
    assert all(one_locker_per_block(spec) for spec in paper_family("all"))
    for n, seed in itertools.product((3, 4, 6, 8), range(4)):
        table = LockTable.from_spec(
            generate_random(RandomGraphConfig(n, reverse_lock_probability=0.0), seed, box=SYMBOLIC_BOX)
        )
        assert table.locker_state.tolist() == table.locked_state.tolist() == [0] * (n - 1)
        assert len(set(table.locked.tolist())) == n - 1
    with_reverse = [generate_random(RandomGraphConfig(n), seed, box=SYMBOLIC_BOX) for n in (6, 7) for seed in range(8)]
    assert not all(one_locker_per_block(spec) for spec in with_reverse)  # why single_locker_specs filters these


@pytest.mark.parametrize("spec", SPECS, ids=lambda s: s.name)
def test_greedy_exploitation_of_the_true_structure_takes_the_bfs_optimal_number_of_actions(spec):
    table = LockTable.from_spec(spec)
    optimum = len(table.shortest_solution())
    assert greedy_exploit_length(table, true_structure_belief(table), PlannerConfig()) == optimum


@pytest.mark.parametrize("spec", SPECS[::3], ids=lambda s: s.name)
def test_greedy_exploitation_stays_optimal_with_a_confident_but_uncertain_belief(spec):
    table = LockTable.from_spec(spec)
    optimum = len(table.shortest_solution())
    belief = true_structure_belief(table, confidence=0.98)
    assert greedy_exploit_length(table, belief, PlannerConfig(gamma=0.95)) == optimum


@pytest.mark.parametrize("spec", SPECS[::4], ids=lambda s: s.name)
def test_values_of_the_true_structure_are_gamma_to_the_bfs_distance(spec):
    table = LockTable.from_spec(spec)
    n = table.num_components
    gamma = 0.8
    values = state_values(true_structure_belief(table), table.goal, table.goal_state, gamma)
    for x in range(1 << n):
        plan = table.shortest_solution(x)
        expected = 0.0 if plan is None else gamma ** len(plan)
        assert values[x] == pytest.approx(expected, rel=1e-12, abs=1e-300), x


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 7), st.integers(0, 2**32 - 1), st.floats(0.5, 0.99))
def test_state_values_are_one_at_goal_states_and_in_zero_one_elsewhere(n, seed, gamma):
    rng = np.random.default_rng(seed)
    belief = Belief(rng.random((n, 2, hypothesis_count(n))))
    goal, goal_state = int(rng.integers(n)), int(rng.integers(2))
    values = state_values(belief, goal, goal_state, gamma)
    index = np.arange(1 << n)
    is_goal = ((index >> goal) & 1) == goal_state
    assert np.all(values[is_goal] == 1.0)
    assert np.all((values[~is_goal] >= 0.0) & (values[~is_goal] <= gamma + 1e-12))
    # Bellman: V(x) = max_c gamma P(c free | x) V(x ^ c) away from the goal
    free = free_table(belief)
    for x in np.flatnonzero(~is_goal):
        best = max(gamma * free[c, x] * values[x ^ (1 << c)] for c in range(n))
        assert values[x] == pytest.approx(best, rel=1e-12, abs=1e-15)


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6), st.integers(0, 2**32 - 1))
def test_free_table_equals_belief_free_probabilities_in_every_state(n, seed):
    rng = np.random.default_rng(seed)
    probs = rng.random((n, 2, hypothesis_count(n))) * (rng.random((n, 2, hypothesis_count(n))) < 0.6)
    probs[:, :, 0] += 1e-3
    belief = Belief(probs, EXACT)
    table = free_table(belief)
    assert table.shape == (n, 1 << n)
    bits = np.array([bits_of(x, n) for x in range(1 << n)])
    np.testing.assert_allclose(table, belief.free_probabilities(bits).T, atol=1e-12)
    for x in range(1 << n):
        for c in range(n):
            assert table[c, x] == pytest.approx(belief.probability_free(bits[x], c), abs=1e-12)


def test_exploit_values_are_gamma_times_free_times_the_next_value():
    rng = np.random.default_rng(3)
    n = 5
    belief = Belief(rng.random((n, 2, hypothesis_count(n))))
    config = PlannerConfig(gamma=0.85)
    values = state_values(belief, 4, 1, config.gamma)
    for x in (0, 5, 17, 30):
        states = bits_of(x, n)
        q = exploit_values(belief, states, 4, 1, config)
        expected = [config.gamma * belief.probability_free(states, c) * values[x ^ (1 << c)] for c in range(n)]
        np.testing.assert_allclose(q, expected, rtol=1e-12)


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 6), st.integers(0, 2**32 - 1), st.floats(0.5, 0.99))
def test_best_first_search_agrees_with_the_exact_planner_when_the_budget_is_ample(n, seed, gamma):
    rng = np.random.default_rng(seed)
    probs = rng.random((n, 2, hypothesis_count(n))) ** 3 * (rng.random((n, 2, hypothesis_count(n))) < 0.7)
    probs[:, :, 0] += 0.05
    belief = Belief(probs, EXACT)
    goal, goal_state = int(rng.integers(n)), int(rng.integers(2))
    config = PlannerConfig(gamma=gamma, max_expansions=10 * (1 << n))
    for x in rng.integers(0, 1 << n, size=4):
        exact = exploit_values(belief, bits_of(int(x), n), goal, goal_state, config)
        searched = planner._best_first_values(belief, int(x), goal, goal_state, config)
        np.testing.assert_allclose(searched, exact, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("spec", SPECS[:12:4] + SPECS[12::6], ids=lambda s: s.name)
def test_exploit_values_beyond_the_exact_limit_plan_the_same_path(spec, monkeypatch):
    table = LockTable.from_spec(spec)
    optimum = len(table.shortest_solution())
    belief = true_structure_belief(table, confidence=0.95)
    config = PlannerConfig(max_expansions=4 * (1 << table.num_components))
    exact = [exploit_values(belief, bits_of(x, table.num_components), table.goal, 1, config) for x in (0, 1, 3)]
    monkeypatch.setattr(planner, "EXACT_MAX_COMPONENTS", 0)
    searched = [exploit_values(belief, bits_of(x, table.num_components), table.goal, 1, config) for x in (0, 1, 3)]
    np.testing.assert_allclose(searched, exact, rtol=1e-9)
    assert greedy_exploit_length(table, belief, config) == optimum


@settings(max_examples=40, deadline=None)
@given(st.integers(3, 6), st.integers(0, 2**32 - 1), st.integers(1, 6))
def test_best_first_search_with_a_small_budget_never_overestimates(n, seed, budget):
    rng = np.random.default_rng(seed)
    belief = Belief(rng.random((n, 2, hypothesis_count(n))) ** 2)
    goal = int(rng.integers(n))
    config = PlannerConfig(max_expansions=budget)
    x = int(rng.integers(0, 1 << n))
    exact = exploit_values(belief, bits_of(x, n), goal, 1, config)
    searched = planner._best_first_values(belief, x, goal, 1, config)
    assert np.all(searched <= exact * (1.0 + 1e-9))
    assert np.all(searched >= 0.0)


def test_a_shorter_plan_wins_at_equal_probability():
    # 3 free components, goal: component 2 open. Toggling 2 directly beats any detour.
    n = 3
    probs = np.zeros((n, 2, hypothesis_count(n)))
    probs[:, :, 0] = 1.0
    q = exploit_values(Belief(probs, EXACT), np.zeros(n, dtype=np.int64), goal=2, goal_state=1)
    assert int(np.argmax(q)) == 2
    assert q[2] == pytest.approx(0.9)
    assert q[0] == pytest.approx(0.9**2) and q[1] == pytest.approx(0.9**2)  # a detour of one action


def test_a_surely_locked_component_has_zero_exploit_value():
    n = 2
    probs = np.zeros((n, 2, hypothesis_count(n)))
    probs[:, :, 0] = 1.0
    probs[1, 0] = 0.0
    probs[1, 0, 1 + 2 * 0 + 0] = 1.0  # 0 closed keeps 1 closed
    q = exploit_values(Belief(probs, EXACT), np.array([0, 0]), goal=1, goal_state=1)
    assert q[1] == 0.0
    assert q[0] == pytest.approx(0.9 * 0.9)
