"""The dual controller and the agents built on it: memory beats no memory, runs are reproducible."""

import itertools
from dataclasses import replace

import numpy as np
import pytest

from puzzlebox.learning import DualAgent, MemoryAgent, SymbolicWorld, run_episode, summarise
from puzzlebox.learning.belief import Belief, BeliefConfig, hypothesis_count
from puzzlebox.learning.dual_controller import DualControllerConfig, decide, max_entropy_for
from puzzlebox.learning.exploration import information_values
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.learning.planner import exploit_values
from puzzlebox.models import LockTable
from puzzlebox.models.generator import (
    TEST_INDICES,
    TRAIN_INDICES,
    BoxConfig,
    RandomGraphConfig,
    generate_chain,
    generate_random,
    paper_variant,
)

SYMBOLIC_BOX = BoxConfig(realizable=False)
"""Random boxes as drawn before lock mechanisms existed: these symbolic tests chose their seeds for their graphs."""

EXACT = BeliefConfig(jam_probability=0.0, false_move_probability=0.0)
"""The paper's exact elimination (the library default adds a 0.001 noise floor)."""

EVAL_SEEDS = range(10)
MAX_ACTIONS = 30


def train_memory(store: MemoryStore, seed: int = 0) -> MemoryStore:
    """One training episode on each of the 9 paper training variants."""
    agent = MemoryAgent(store, learn=True)
    for index in TRAIN_INDICES:
        spec = paper_variant(index, seed)
        agent.episode_label = spec.name
        run_episode(agent, SymbolicWorld(spec, index), spec.name, index, MAX_ACTIONS)
    return store


@pytest.fixture(scope="module")
def trained_store() -> MemoryStore:
    return train_memory(MemoryStore())


def evaluate(make_agent, index: int, max_actions: int = MAX_ACTIONS):
    runs = []
    for seed in EVAL_SEEDS:
        spec = paper_variant(index, seed)  # a new layout of the variant per run, as the paper samples
        runs.append(run_episode(make_agent(), SymbolicWorld(spec, seed), spec.name, seed, max_actions))
    return runs


def action_names(result):
    return [(a.component, a.moved) for a in result.actions]


# -- memory versus no memory -----------------------------------------------------------------------------------


@pytest.mark.parametrize("index", TEST_INDICES)
def test_memory_agent_trained_on_nine_variants_needs_fewer_actions_on_an_unseen_variant(trained_store, index):
    before = trained_store.summary()
    memory = summarise(evaluate(lambda: MemoryAgent(trained_store), index), MAX_ACTIONS)
    dual = summarise(evaluate(DualAgent, index), MAX_ACTIONS)
    assert memory["success_rate"] == 1.0
    assert memory["mean_actions"] < dual["mean_actions"]
    assert memory["mean_actions"] >= 5.0  # never better than the optimum
    assert trained_store.summary() == before  # evaluation (learn=False) leaves the memory untouched


def test_training_adds_one_episode_per_run_with_every_pair_and_component(trained_store):
    summary = trained_store.summary()
    assert summary["episodes"] == len(TRAIN_INDICES)
    assert sum(summary["pair_buckets"].values()) == len(TRAIN_INDICES) * 5 * 4  # ordered pairs i != j
    assert sum(summary["independence_buckets"].values()) == len(TRAIN_INDICES) * 5


def test_an_empty_memory_makes_the_memory_agent_act_like_the_dual_agent():
    for index in TEST_INDICES[:1]:
        memory = evaluate(lambda: MemoryAgent(MemoryStore()), index)
        dual = evaluate(DualAgent, index)
        assert [action_names(r) for r in memory] == [action_names(r) for r in dual]


@pytest.mark.parametrize("index", TRAIN_INDICES[:3] + TEST_INDICES)
def test_dual_agent_solves_paper_variants_within_the_budget(index):
    runs = evaluate(DualAgent, index)
    assert all(r.solved for r in runs)
    assert all(5 <= r.num_actions <= MAX_ACTIONS for r in runs)
    assert all(r.actions[-1].moved for r in runs)  # the last try is the goal opening


# -- determinism ---------------------------------------------------------------------------------------------------


def test_same_seed_gives_identical_action_sequences_for_the_dual_agent():
    spec = paper_variant(TEST_INDICES[0], 3)
    first = [run_episode(DualAgent(), SymbolicWorld(spec, s), spec.name, s, MAX_ACTIONS) for s in range(5)]
    again = [run_episode(DualAgent(), SymbolicWorld(spec, s), spec.name, s, MAX_ACTIONS) for s in range(5)]
    assert [action_names(r) for r in first] == [action_names(r) for r in again]
    assert len({tuple(action_names(r)) for r in first}) > 1  # seeds do matter


def test_same_seed_gives_identical_action_sequences_for_the_memory_agent(trained_store):
    spec = paper_variant(TEST_INDICES[1], 4)
    first = [run_episode(MemoryAgent(trained_store), SymbolicWorld(spec, s), spec.name, s, 30) for s in range(5)]
    again = [run_episode(MemoryAgent(trained_store), SymbolicWorld(spec, s), spec.name, s, 30) for s in range(5)]
    assert [action_names(r) for r in first] == [action_names(r) for r in again]


def test_training_twice_with_the_same_seeds_gives_the_same_memory_and_the_same_runs():
    a, b = train_memory(MemoryStore()), train_memory(MemoryStore())
    assert a.summary() == b.summary()
    for pair in a.summary()["pair_buckets"]:
        kind_i, kind_j = pair.split("->")
        np.testing.assert_array_equal(a.pair_bucket(kind_i, kind_j).keys, b.pair_bucket(kind_i, kind_j).keys)
        np.testing.assert_array_equal(a.pair_bucket(kind_i, kind_j).values, b.pair_bucket(kind_i, kind_j).values)
    spec = paper_variant(TEST_INDICES[2], 7)
    run_a = run_episode(MemoryAgent(a), SymbolicWorld(spec, 7), spec.name, 7, MAX_ACTIONS)
    run_b = run_episode(MemoryAgent(b), SymbolicWorld(spec, 7), spec.name, 7, MAX_ACTIONS)
    assert action_names(run_a) == action_names(run_b)


# -- puzzles with two lockers -----------------------------------------------------------------------------------


def needs_two_lockers(spec) -> bool:
    """Whether the shortest solution opens a component that two lockers hold closed."""
    table = LockTable.from_spec(spec)
    held_closed = table.locked[table.locked_state == 0].tolist()
    doubly = {c for c in held_closed if held_closed.count(c) >= 2}
    return bool(doubly & set(table.shortest_solution()))


def two_locker_seeds(count: int) -> list[int]:
    """The first generator seeds whose 6-component puzzle needs a component with two lockers opened."""
    seeds = (
        s
        for s in range(200)
        if needs_two_lockers(generate_random(RandomGraphConfig(6, multi_locker=True), s, box=SYMBOLIC_BOX))
    )
    return list(itertools.islice(seeds, count))


@pytest.mark.parametrize("spec_seed", two_locker_seeds(3))
def test_dual_agent_solves_random_puzzles_with_two_lockers_within_a_generous_budget(spec_seed):
    spec = generate_random(RandomGraphConfig(6, multi_locker=True), spec_seed, box=SYMBOLIC_BOX)
    assert needs_two_lockers(spec)
    optimum = len(LockTable.from_spec(spec).shortest_solution())
    for seed in range(5):
        result = run_episode(DualAgent(), SymbolicWorld(spec, seed), spec.name, seed, max_actions=100)
        assert result.solved, (spec.name, seed)
        assert result.num_actions >= optimum


EXACT_CONTROLLER = DualControllerConfig(belief=EXACT)
NOISY = DualControllerConfig(belief=BeliefConfig(jam_probability=0.05, false_move_probability=0.025))


@pytest.mark.parametrize(("spec_seed", "seed"), [(4, 6), (4, 9), (10, 6), (59, 3)])
def test_noise_aware_dual_agent_solves_the_two_locker_puzzles_that_trap_exact_elimination(spec_seed, seed):
    spec = generate_random(RandomGraphConfig(6, multi_locker=True), spec_seed, box=SYMBOLIC_BOX)
    result = run_episode(DualAgent(NOISY), SymbolicWorld(spec, seed), spec.name, seed, max_actions=100)
    assert result.solved


@pytest.mark.parametrize(("spec_seed", "seed"), [(4, 6), (10, 6), (59, 3)])
def test_default_dual_agent_solves_two_locker_puzzles_where_exact_elimination_cycles(spec_seed, seed):
    # With epsilon = delta = 0 these runs cycle for 300 actions: every failure with only one of the
    # goal's two lockers open blames the wrong locker. The default noise floor solves them. (It does not
    # solve everything: 3 of 1000 six-component two-locker runs still cycle, a limit of the paper's
    # single-locker belief.)
    spec = generate_random(RandomGraphConfig(6, multi_locker=True), spec_seed, box=SYMBOLIC_BOX)
    exact = run_episode(DualAgent(EXACT_CONTROLLER), SymbolicWorld(spec, seed), "exact", seed, max_actions=300)
    assert not exact.solved
    spec = generate_random(RandomGraphConfig(6, multi_locker=True), spec_seed, box=SYMBOLIC_BOX)
    assert needs_two_lockers(spec)
    result = run_episode(DualAgent(), SymbolicWorld(spec, seed), spec.name, seed, max_actions=300)
    assert result.solved, f"{spec.name}, seed {seed}: not solved in 300 actions"


# -- the dual controller -----------------------------------------------------------------------------------------


def test_max_entropy_is_the_scaled_entropy_of_a_uniform_belief_unless_given():
    config = DualControllerConfig()
    assert max_entropy_for(5, config) == pytest.approx(4.0 * 10 * np.log(9))
    assert max_entropy_for(1, config) == pytest.approx(4.0 * 2 * np.log(2))
    assert max_entropy_for(5, DualControllerConfig(max_entropy=3.0)) == 3.0
    uniform = Belief(np.ones((5, 2, hypothesis_count(5))))
    assert uniform.entropy() == pytest.approx(max_entropy_for(5, DualControllerConfig(entropy_scale=1.0)))


def test_decision_mixes_information_and_exploitation_by_the_entropy_weight():
    rng = np.random.default_rng(0)
    n = 4
    belief = Belief(rng.random((n, 2, hypothesis_count(n))))
    states = np.array([0, 1, 0, 0])
    config = DualControllerConfig()
    h_max = 2.5 * belief.entropy()
    decision = decide(belief, states, 3, 1, np.random.default_rng(0), config, h_max)
    assert decision.weight_info == pytest.approx(0.4)
    np.testing.assert_allclose(decision.q_info, information_values(belief, states, config.info_threshold))
    np.testing.assert_allclose(decision.q_exploit, exploit_values(belief, states, 3, 1, config.planner))
    q = 0.4 * decision.q_info + 0.6 * decision.q_exploit
    assert decision.action == int(np.argmax(q))


def test_weight_is_clipped_and_extremes_pick_pure_exploration_or_pure_exploitation():
    rng = np.random.default_rng(1)
    n = 5
    belief = Belief(rng.random((n, 2, hypothesis_count(n))) ** 4)
    states = np.zeros(n, dtype=np.int64)
    config = DualControllerConfig(info_threshold=0.0)
    explore = decide(belief, states, 4, 1, np.random.default_rng(0), config, h_max=1e-6)
    assert explore.weight_info == 1.0
    assert explore.action == int(np.argmax(explore.q_info))
    exploit = decide(belief, states, 4, 1, np.random.default_rng(0), config, h_max=1e12)
    assert exploit.weight_info < 1e-9
    assert exploit.action == int(np.argmax(exploit.q_exploit))
    assert decide(belief, states, 4, 1, np.random.default_rng(0), config, h_max=0.0).weight_info == 0.0


def test_ties_are_broken_at_random_but_reproducibly():
    belief = Belief.uninformed(4, EXACT)
    states = np.zeros(4, dtype=np.int64)
    config = DualControllerConfig()
    h_max = 1e-9  # pure exploration: the uninformed belief is symmetric, so all four actions tie
    decision = decide(belief, states, 3, 1, np.random.default_rng(0), config, h_max)
    assert decision.weight_info == 1.0
    assert np.ptp(decision.q_info) < 1e-12 and decision.q_info.max() > 0.0
    picks = [decide(belief, states, 3, 1, np.random.default_rng(s), config, h_max).action for s in range(40)]
    again = [decide(belief, states, 3, 1, np.random.default_rng(s), config, h_max).action for s in range(40)]
    assert picks == again
    assert set(picks) == {0, 1, 2, 3}  # no component is always favoured


class _MisreadUntilMoved:
    """A world that tells one component's kind wrong until a try moves it, and from then on the kind that moved
    it — as ``skills.robot_world.RobotWorld`` reports a kind it found."""

    def __init__(self, world: SymbolicWorld, name: str, told: str) -> None:
        self.world, self.name, self.told, self.found = world, name, told, False

    def _index(self) -> int:
        return next(i for i in range(len(self.world.observe())) if self.world.ground_truth_name(i) == self.name)

    def observe(self):
        observation = self.world.observe()
        if self.found:
            return observation
        components = list(observation.components)
        components[self._index()] = replace(components[self._index()], kind=self.told)
        return replace(observation, components=tuple(components))

    def try_toggle(self, index: int):
        result = self.world.try_toggle(index)
        self.found = self.found or (result.moved and index == self._index())
        return result

    def ground_truth_name(self, index: int) -> str:
        return self.world.ground_truth_name(index)


@pytest.mark.parametrize("max_lockers", [1, 2])
def test_the_memory_stores_the_kind_that_moved_a_part_never_the_misread_one(max_lockers):
    spec = generate_chain(["slide", "door", "slide", "wheel"], seed=2)
    told = _MisreadUntilMoved(SymbolicWorld(spec, 1), "door-1", "wheel")
    assert told.observe().kinds.count("wheel") == 2  # the door is told a wheel
    store = MemoryStore()
    agent = MemoryAgent(store, DualControllerConfig(max_lockers=max_lockers), learn=True)
    result = run_episode(agent, told, spec.name, 1, MAX_ACTIONS)
    assert result.solved and told.found
    doors, wheels = store.independence_values("door"), store.independence_values("wheel")
    assert doors is not None and len(doors) == 1 and wheels is not None and len(wheels) == 1
    assert store.pair_bucket("slide", "door") is not None  # the door's lock, kept under the door's kind


def test_a_kind_found_remakes_the_belief_from_its_prior_with_the_evidence_so_far():
    spec = generate_chain(["slide", "door", "slide", "wheel"], seed=2)
    trained = train_memory(MemoryStore())
    told = _MisreadUntilMoved(SymbolicWorld(spec, 1), "door-1", "wheel")
    agent = MemoryAgent(trained)
    result = run_episode(agent, told, spec.name, 1, MAX_ACTIONS)
    assert result.solved and told.found
    # the same belief as one that started from the true kinds' prior and saw the same tries
    fresh = MemoryAgent(trained)
    fresh.begin_episode(told.observe(), np.random.default_rng(1))
    for states, component, moved in agent._evidence:
        fresh.belief.update(states, component, moved)
    np.testing.assert_array_equal(fresh.belief.probs, agent.belief.probs)
