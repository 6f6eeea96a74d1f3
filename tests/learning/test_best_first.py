"""The bitset planner and belief: A* on int bitmask states, the bitset belief and the vectorised exploration
equal their reference forms, and a 32-component decision plans the known answer."""

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from random_beliefs import EXACT, NOISY, random_belief, random_problem

import puzzlebox.learning.planner as planner
from puzzlebox.learning.belief import Belief, hypothesis_count, state_bits
from puzzlebox.learning.best_first import BestFirstPlanner
from puzzlebox.learning.dual_controller import DualControllerConfig, decide
from puzzlebox.learning.exploration import expected_information_gain, information_values
from puzzlebox.learning.planner import PlannerConfig, exploit_values, free_table, state_values, value_iteration


def brute_force_cost(belief: Belief, source: int, goal: int, goal_state: int, gamma: float) -> float:
    """Least ``-log(gamma * P)`` path cost by Bellman-Ford over all 2^N states (inf if none)."""
    n = belief.num_components
    states = range(1 << n)
    cost = [0.0 if ((x >> goal) & 1) == goal_state else math.inf for x in states]
    edges = {}
    for x in states:
        free = [belief.probability_free(state_bits(x, n), c) for c in range(n)]
        edges[x] = [(x ^ (1 << c), -math.log(gamma) - math.log(p)) for c, p in enumerate(free) if p > 0.0]
    for _ in states:
        changed = False
        for x in states:
            for y, w in edges[x]:
                if w + cost[y] < cost[x] - 1e-15:
                    cost[x], changed = w + cost[y], True
        if not changed:
            break
    return cost[source]


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 6), st.integers(0, 2**32 - 1), st.floats(0.5, 0.99))
def test_a_star_cost_equals_the_brute_force_shortest_path(n, seed, gamma):
    rng, belief, goal, goal_state = random_problem(seed, n, EXACT)
    search = BestFirstPlanner(belief, goal, goal_state, gamma)
    for source in rng.integers(0, 1 << n, size=4):
        expected = brute_force_cost(belief, int(source), goal, goal_state, gamma)
        found = search.cost_to_go(int(source), budget=10**6)
        assert found == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assert search.exact


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 9), st.integers(0, 2**32 - 1))
def test_a_star_exploit_values_equal_value_iteration(n, seed):
    rng, belief, goal, goal_state = random_problem(seed, n, NOISY if seed % 2 else EXACT)
    values = state_values(belief, goal, goal_state, 0.9)
    search = BestFirstPlanner(belief, goal, goal_state, 0.9)
    for x in rng.integers(0, 1 << n, size=3):
        x = int(x)
        reference = [0.9 * belief.probability_free(state_bits(x, n), c) * values[x ^ (1 << c)] for c in range(n)]
        np.testing.assert_allclose(search.exploit_values(x, budget=10**6), reference, rtol=1e-9, atol=1e-15)


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 7), st.integers(0, 2**32 - 1))
def test_bitset_free_vector_equals_the_per_component_marginal_in_every_state(n, seed):
    rng = np.random.default_rng(seed)
    belief = random_belief(rng, n)
    for x in range(1 << n):
        expected = [belief.probability_free(state_bits(x, n), c) for c in range(n)]
        np.testing.assert_allclose(belief.free_vector(x), expected, atol=1e-12)


def test_locker_matrix_is_a_view_that_follows_updates():
    belief = Belief.uninformed(4, EXACT)
    lockers = belief.locker_matrix()
    belief.update(np.array([1, 0, 0, 0]), 2, moved=False)  # held in state 0 by (0, 1), (1, 0) or (3, 0)
    assert lockers[2 * 2 + 0, 2 * 0 + 1] == pytest.approx(1.0 / 3.0)
    assert lockers[2 * 2 + 0, 2 * 0 + 0] == 0.0
    assert belief.free_vector(0b0001)[2] == 0.0


@settings(max_examples=30, deadline=None)
@given(st.integers(2, 7), st.integers(0, 2**32 - 1), st.booleans())
def test_vectorised_information_values_equal_the_per_component_gain(n, seed, noisy):
    rng = np.random.default_rng(seed)
    belief = random_belief(rng, n, NOISY if noisy else EXACT)
    for _ in range(3):  # a few updates, so that some blocks are resolved
        belief.update(rng.integers(0, 2, n), int(rng.integers(n)), bool(rng.integers(2)))
    states = rng.integers(0, 2, n)
    expected = [expected_information_gain(belief, states, c) for c in range(n)]
    np.testing.assert_allclose(information_values(belief, states), expected, rtol=1e-9, atol=1e-15)


def test_free_table_and_value_iteration_are_unchanged_by_the_in_place_forms():
    """The in-place doubling and Gauss-Seidel sweeps equal a per-state reference, bit for bit where
    the reference sums in the same order (the sweep: any order reaches the same least fixed point)."""
    rng = np.random.default_rng(7)
    n = 11
    belief = random_belief(rng, n, NOISY)
    table = free_table(belief)
    lockers = belief.probs[:, :, 1:].reshape(n, 2, n, 2)
    for x in rng.integers(0, 1 << n, size=50):
        bits = state_bits(int(x), n)
        for c in range(n):
            held = 0.0
            for m in range(n):
                held += lockers[c, bits[c], m, bits[m]]
            assert table[c, x] == min(max(1.0 - held, 0.0), 1.0)
    values = value_iteration(table, 3, 1, 0.9)
    jacobi = (((np.arange(1 << n) >> 3) & 1) == 1).astype(float)
    for _ in range(1 << n):
        new = jacobi.copy()
        for c in range(n):
            np.maximum(new, 0.9 * table[c] * jacobi[np.arange(1 << n) ^ (1 << c)], out=new)
        if np.array_equal(new, jacobi):
            break
        jacobi = new
    np.testing.assert_array_equal(values, jacobi)


def chain_belief(n: int) -> Belief:
    """The paper's chain rules, known for certain: k closed keeps k+1 closed, k+1 open keeps k open."""
    probs = np.zeros((n, 2, hypothesis_count(n)))
    probs[:, :, 0] = 1.0
    for k in range(n - 1):
        probs[k + 1, 0] = 0.0
        probs[k + 1, 0, 1 + 2 * k + 0] = 1.0
        probs[k, 1] = 0.0
        probs[k, 1, 1 + 2 * (k + 1) + 1] = 1.0
    return Belief(probs, EXACT)


@pytest.mark.parametrize("opened", [0, 7, 20, 31])
def test_a_32_component_chain_decision_opens_the_next_component_with_the_known_value(opened):
    n = 32
    belief = chain_belief(n)
    states = np.array([1] * opened + [0] * (n - opened))
    config = DualControllerConfig(max_entropy=1.0)
    decision = decide(belief, states, n - 1, 1, np.random.default_rng(0), config, h_max=1.0)
    assert decision.weight_info == 0.0  # the belief is certain: pure exploitation
    assert decision.action == opened
    gamma = config.planner.gamma
    assert decision.q_exploit[opened] == pytest.approx(gamma ** (n - opened), rel=1e-12)
    if opened > 0:  # closing the last opened component is possible but one more detour each way
        assert decision.q_exploit[opened - 1] == pytest.approx(gamma ** (n - opened + 2), rel=1e-12)
    others = [c for c in range(n) if c not in (opened, opened - 1)]
    assert np.all(decision.q_exploit[others] == 0.0)  # surely held


def test_a_32_component_chain_is_solved_by_following_the_planner():
    n = 32
    belief = chain_belief(n)
    states = np.zeros(n, dtype=np.int64)
    for step in itertools.count():
        if states[-1] == 1:
            break
        action = int(np.argmax(exploit_values(belief, states, n - 1, 1)))
        assert action == step
        states[action] ^= 1
    assert step == n


def test_a_search_stopped_by_its_budget_is_a_lower_bound_and_says_so():
    n = 24
    belief = chain_belief(n)
    search = BestFirstPlanner(belief, n - 1, 1, 0.9)
    cost = search.cost_to_go(0, budget=5)
    assert not search.exact
    assert cost == math.inf or cost >= -n * math.log(0.9)
    config = PlannerConfig(max_expansions=5)
    q = planner._best_first_values(belief, 0, n - 1, 1, config)
    assert np.all(q <= 0.9**n * (1.0 + 1e-12))


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 6), st.integers(0, 2**32 - 1), st.floats(0.5, 0.99), st.booleans())
def test_the_heuristic_never_exceeds_the_true_cost_to_go(n, seed, gamma, noisy):
    rng, belief, goal, goal_state = random_problem(seed, n, NOISY if noisy else EXACT)
    search = BestFirstPlanner(belief, goal, goal_state, gamma)
    for x in range(1 << n):
        if search.is_goal(x):
            continue
        costs, heuristic = search.expand(x)
        for c in range(n):
            y = x ^ (1 << c)
            if not search.is_goal(y):
                assert heuristic[c] <= brute_force_cost(belief, y, goal, goal_state, gamma)
