import numpy as np

from puzzlebox.learning import OracleAgent, PuzzleEnvConfig, RandomAgent, SymbolicWorld, run_episode, summarise
from puzzlebox.learning.puzzle_env import FaultConfig
from puzzlebox.models import LockTable, World
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random, paper_family

SYMBOLIC_BOX = BoxConfig(realizable=False)
"""Random boxes as drawn before lock mechanisms existed: these symbolic tests chose their seeds for their graphs."""


def test_symbolic_world_satisfies_the_world_protocol():
    assert isinstance(SymbolicWorld(paper_family("test")[0], seed=0), World)


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
