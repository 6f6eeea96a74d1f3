import numpy as np

from puzzlebox.learning import OracleAgent, PuzzleEnvConfig, RandomAgent, SymbolicWorld, run_episode, summarise
from puzzlebox.learning.puzzle_env import FaultConfig
from puzzlebox.models import LockTable, World
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random, paper_family

SYMBOLIC_BOX = BoxConfig(realizable=False)
"""Random boxes as drawn before lock mechanisms existed: these symbolic tests chose their seeds for their graphs."""


def observed_order(spec, observation) -> list[int]:
    """The spec index of each observed component, found by its pose in the world frame (each is unique)."""
    truth = spec.poses_in_world()
    return [int(np.flatnonzero((truth == c.pose_in_world).all(axis=1))[0]) for c in observation.components]


def try_and_check(world, table: LockTable, order: list[int], state: int, index: int) -> tuple[int, str]:
    """Try observation ``index`` of ``world`` in true ``state`` (a bitmask in spec order), check the outcome and the
    next observation against the lock rules, and return the new true state and the outcome."""
    before = world.observe()
    result = world.try_toggle(index)
    after = world.observe()
    j = order[index]
    assert result.outcome == ("moved" if table.can_move(state, j) else "blocked")  # symbolic: never failed
    state ^= int(result.moved) << j
    assert after.states.tolist() == [(state >> k) & 1 for k in order]
    assert after.kinds == before.kinds and after.goal_index == before.goal_index
    np.testing.assert_array_equal(after.poses, before.poses)
    assert after.solved == table.is_goal(state)
    return state, result.outcome


def test_symbolic_world_keeps_the_world_protocols_promises():
    """Driven through ``observe`` and ``try_toggle`` alone, the symbolic world does what ``models.world`` promises:
    it shows the spec's components (kinds, world-frame poses, all closed, the goal) in an order shuffled per episode
    and fixed within it; a try is ``moved`` exactly when the lock rules let the component move, and the next
    observation shows that component, and only it, in its other state; ``blocked`` changes nothing; once the goal
    component reaches its goal state the observation says solved."""
    spec = paper_family("test")[0]
    table = LockTable.from_spec(spec)
    n, goal = len(spec.components), spec.index_of(spec.goal.component)
    orders, outcomes = set(), set()
    for seed in range(4):
        world = SymbolicWorld(spec, seed=seed)
        assert isinstance(world, World)
        first = world.observe()
        order = observed_order(spec, first)
        orders.add(tuple(order))
        assert sorted(order) == list(range(n))
        assert list(first.kinds) == [spec.components[j].kind for j in order]
        assert first.states.tolist() == [0] * n
        assert (order[first.goal_index], first.goal_state) == (goal, spec.goal.state) and not first.solved
        state = 0
        tries = [int(i) for i in np.random.default_rng(seed).integers(n, size=15)]  # random tries first
        for index in tries:
            state, outcome = try_and_check(world, table, order, state, index)
            outcomes.add(outcome)
        for j in table.shortest_solution(state):  # then on to the goal
            state, _ = try_and_check(world, table, order, state, order.index(j))
        assert world.observe().solved
    assert outcomes == {"moved", "blocked"}
    assert len(orders) > 1, "the order is shuffled per episode"


def test_oracle_solves_every_paper_box_in_the_optimal_five_actions():
    for spec in paper_family("all"):
        for seed in range(3):
            result = run_episode(OracleAgent(spec), SymbolicWorld(spec, seed), spec.name, seed, max_actions=30)
            assert result.solved and result.num_actions == 5
            assert [a.component for a in result.actions] == list(spec.component_names)


def test_oracle_matches_optimal_length_on_random_graphs_with_two_lockers():
    for seed in range(10):
        spec = generate_random(RandomGraphConfig(10, multi_locker=True), seed=seed, box=SYMBOLIC_BOX)
        optimum = len(LockTable.from_spec(spec).shortest_solution())
        result = run_episode(OracleAgent(spec), SymbolicWorld(spec, seed), spec.name, seed, max_actions=60)
        assert result.solved and result.num_actions == optimum


def test_oracle_recovers_from_jams_by_retrying():
    spec = paper_family("test")[1]
    config = PuzzleEnvConfig(faults=FaultConfig(jam_probability=0.3))
    result = run_episode(OracleAgent(spec), SymbolicWorld(spec, 5, config), spec.name, 5, max_actions=60)
    assert result.solved and result.num_actions >= 5
    assert all(a.moved or a.component == b.component for a, b in zip(result.actions, result.actions[1:], strict=False))


def test_random_agent_is_reproducible_and_worse_than_the_oracle():
    spec = paper_family("test")[2]
    runs = [run_episode(RandomAgent(), SymbolicWorld(spec, s), spec.name, s, max_actions=30) for s in range(20)]
    again = [run_episode(RandomAgent(), SymbolicWorld(spec, s), spec.name, s, max_actions=30) for s in range(20)]
    assert [r.actions for r in runs] == [r.actions for r in again]
    summary = summarise(runs, max_actions=30)
    assert summary["mean_actions"] > 5.0
    assert summary["success_rate"] == sum(r.solved for r in runs) / len(runs)


def test_summary_counts_unsolved_runs_at_the_budget():
    spec = paper_family("test")[0]
    runs = [run_episode(RandomAgent(), SymbolicWorld(spec, s), spec.name, s, max_actions=3) for s in range(4)]
    summary = summarise(runs, max_actions=3)
    assert summary["success_rate"] == 0.0 and summary["mean_actions"] == 3.0
    assert np.all([len(r["actions"]) == 3 for r in summary["runs"]])


def test_on_action_sees_every_try_as_it_happens():
    spec = generate_chain(["door", "slide", "wheel"], seed=0)
    seen: list = []
    result = run_episode(OracleAgent(spec), SymbolicWorld(spec, 0), spec.name, 0, 10, on_action=seen.append)
    assert seen == result.actions and len(seen) == 3


def test_a_summary_of_no_finished_run_gives_no_rate():
    # (stopped before any run ended, results.json said success_rate 0.0 and mean_actions 30.0)
    summary = summarise([], max_actions=30)
    assert summary["success_rate"] is None and summary["mean_actions"] is None
    assert summary["ended"] == "no run finished" and summary["runs"] == [] and summary["max_actions"] == 30
