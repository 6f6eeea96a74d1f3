import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from puzzlebox.models import Box, Component, Goal, LockRule, LockTable, PuzzleSpec


def make_spec(n, rules, goal, goal_state=1):
    components = tuple(Component(f"c{i}", "slide", (0.0, 0.0, 0.0), i) for i in range(n))
    locks = tuple(LockRule(f"c{a}", sa, f"c{b}", sb) for a, sa, b, sb in rules)
    return PuzzleSpec("t", components, locks, Goal(f"c{goal}", goal_state), Box((1.0, 1.0, 0.1)))


def test_two_locker_component_moves_only_when_both_lockers_release_it():
    table = LockTable.from_spec(make_spec(3, [(0, 0, 2, 0), (1, 0, 2, 0)], goal=2))
    assert not table.can_move(0b000, 2)
    assert not table.can_move(0b001, 2)  # only locker 0 open
    assert not table.can_move(0b010, 2)  # only locker 1 open
    assert table.can_move(0b011, 2)
    assert table.shortest_solution() in ([0, 1, 2], [1, 0, 2])


def test_rule_only_holds_the_locked_component_in_its_locked_state():
    # 0 open keeps 1 open: 1 may still open while 0 is open, but not close again
    table = LockTable.from_spec(make_spec(2, [(0, 1, 1, 1)], goal=1))
    assert table.can_move(0b01, 1)
    assert not table.can_move(0b11, 1)
    assert table.can_move(0b10, 1)


def test_paper_chain_needs_exactly_n_actions_in_chain_order():
    n = 5
    rules = [r for k in range(n - 1) for r in ((k, 0, k + 1, 0), (k + 1, 1, k, 1))]
    assert LockTable.from_spec(make_spec(n, rules, goal=n - 1)).shortest_solution() == list(range(n))


def brute_force_shortest(table, n):
    """Shortest solution length by trying every sequence of toggles up to length 2n."""
    for length in range(0, 2**n):  # a shortest path visits each state at most once
        for seq in itertools.product(range(n), repeat=length):
            state = 0
            for j in seq:
                if not table.can_move(state, j):
                    break
                state ^= 1 << j
            else:
                if table.is_goal(state):
                    return length
    return None


@settings(max_examples=40, deadline=None)
@given(st.data())
def test_breadth_first_solution_is_as_short_as_brute_force(data):
    n = data.draw(st.integers(2, 4))
    rule = st.tuples(st.integers(0, n - 1), st.integers(0, 1), st.integers(0, n - 1), st.integers(0, 1))
    rules = [r for r in data.draw(st.lists(rule, max_size=6)) if r[0] != r[2]]
    table = LockTable.from_spec(make_spec(n, rules, goal=data.draw(st.integers(0, n - 1))))
    plan = table.shortest_solution()
    expected = brute_force_shortest(table, n) if n <= 3 else None
    if plan is not None:  # the plan is legal and ends at the goal
        state = 0
        for j in plan:
            assert table.can_move(state, j)
            state ^= 1 << j
        assert table.is_goal(state)
    if n <= 3:
        assert (None if plan is None else len(plan)) == expected


def test_vectorised_movable_agrees_with_the_scalar_rule():
    rng = np.random.default_rng(0)
    rules = [(0, 0, 3, 0), (1, 1, 3, 0), (2, 0, 3, 1), (3, 1, 0, 1)]
    table = LockTable.from_spec(make_spec(4, rules, goal=3))
    states = rng.integers(0, 16, size=50)
    for j in range(4):
        expected = [
            not any(((s >> a) & 1) == sa and ((s >> b) & 1) == sb for a, sa, b, sb in rules if b == j) for s in states
        ]
        assert table.movable(states, j).tolist() == expected


def test_held_is_exactly_what_cannot_move_in_every_joint_state():
    rules = [(0, 0, 3, 0), (1, 1, 3, 0), (2, 0, 3, 1), (3, 1, 0, 1), (0, 1, 2, 0)]
    table = LockTable.from_spec(make_spec(4, rules, goal=3))
    for state in range(16):
        bits = np.array([(state >> c) & 1 for c in range(4)])
        assert table.held(bits).tolist() == [not table.can_move(state, c) for c in range(4)]


def test_sparse_search_is_used_beyond_the_dense_limit_and_finds_the_chain():
    n = 30
    rules = [r for k in range(n - 1) for r in ((k, 0, k + 1, 0), (k + 1, 1, k, 1))]
    assert LockTable.from_spec(make_spec(n, rules, goal=n - 1)).shortest_solution() == list(range(n))
