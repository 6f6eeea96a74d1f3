"""The exact planner's fast forms (up to EXACT_MAX_COMPONENTS): values over the non-goal states only, and the
per-belief table of step probabilities kept across decisions, equal the full computation bit for bit."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from random_beliefs import NOISY, random_belief, random_problem

import puzzlebox.learning.planner as planner
from puzzlebox.learning.belief import Belief
from puzzlebox.learning.planner import exploit_values, free_table, open_free_rows, open_index, value_iteration


def jacobi_values(table: np.ndarray, goal: int, goal_state: int, gamma: float) -> np.ndarray:
    """The reference: synchronous sweeps over all 2^N states until nothing changes."""
    n = table.shape[0]
    index = np.arange(1 << n)
    values = (((index >> goal) & 1) == goal_state).astype(float)
    while True:
        new = values.copy()
        for c in range(n):
            np.maximum(new, gamma * table[c] * values[index ^ (1 << c)], out=new)
        if np.array_equal(new, values):
            return values
        values = new


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 13), st.integers(0, 2**32 - 1))
def test_the_non_goal_rows_equal_the_full_tables_non_goal_columns_bit_for_bit(n, seed):
    rng, belief, goal, goal_state = random_problem(seed, n, NOISY)
    index = np.arange(1 << n)
    open_states = index[((index >> goal) & 1) != goal_state]
    np.testing.assert_array_equal(open_index(open_states, goal), np.arange(open_states.size))
    lockers = belief.probs[:, :, 1:].reshape(n, 2, n, 2)
    rows = np.flatnonzero(rng.random(n) < 0.5) if n > 1 else np.arange(n)
    table = free_table(belief)
    if n > planner.SMALL_N:  # the doubling sums in the same order (the small-N gather sums pairwise)
        np.testing.assert_array_equal(open_free_rows(lockers, np.arange(n), goal, goal_state), table[:, open_states])
    np.testing.assert_allclose(
        open_free_rows(lockers, rows, goal, goal_state), table[rows][:, open_states], rtol=0, atol=1e-15
    )


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 12), st.integers(0, 2**32 - 1), st.floats(0.5, 0.99))
def test_value_iteration_on_the_non_goal_states_equals_jacobi_sweeps_over_all_states(n, seed, gamma):
    rng, belief, goal, goal_state = random_problem(seed, n, NOISY)
    table = free_table(belief)
    np.testing.assert_array_equal(
        value_iteration(table, goal, goal_state, gamma), jacobi_values(table, goal, goal_state, gamma)
    )


def test_exploit_values_kept_across_belief_updates_equal_a_fresh_computation_bit_for_bit():
    rng = np.random.default_rng(3)
    n = 13
    belief = random_belief(rng, n, NOISY)
    goal, goal_state = 4, 1
    for step in range(12):
        states = rng.integers(0, 2, n)
        states[goal] = 1 - goal_state
        if step == 8:
            goal, goal_state = 7, 0  # another goal: the table is rebuilt
            states[goal] = 1 - goal_state
        kept = exploit_values(belief, states, goal, goal_state)  # the cached table, updated row by row
        fresh = Belief(belief.probs, belief.config)
        fresh.probs[...] = belief.probs  # the constructor renormalises: the very same numbers, in a new belief
        np.testing.assert_array_equal(kept, exploit_values(fresh, states, goal, goal_state))
        reference = value_iteration(free_table(fresh), goal, goal_state, 0.9)
        x = planner.bitmask(states)
        expected = [0.9 * fresh.probability_free(states, c) * reference[x ^ (1 << c)] for c in range(n)]
        np.testing.assert_array_equal(kept, expected)
        belief.update(states, int(rng.integers(n)), bool(rng.integers(2)))
