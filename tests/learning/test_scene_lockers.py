"""Defaults that fit the scene (issue 36 item 5): with no max_lockers given, a computer, or a memory that learned
parts held by two lockers, gets a belief over sets of two; the paper's boxes keep the one-locker belief."""

from __future__ import annotations

from pathlib import Path

import pytest

from puzzlebox.learning import DualAgent, MemoryAgent, SymbolicWorld, make_agent, run_episode
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.learning.scene_lockers import scene_max_lockers, training_max_lockers
from puzzlebox.models import load_spec
from puzzlebox.models.disassembly_variants import disassembly_variant
from puzzlebox.models.generator import TEST_INDICES, TRAIN_INDICES, RandomGraphConfig, generate_random, paper_variant
from puzzlebox.models.generator.chain import BoxConfig

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "disassembly"


def _train(specs, episodes: int, max_lockers: int, store: MemoryStore | None = None) -> MemoryStore:
    store = store if store is not None else MemoryStore()
    config = None if max_lockers == 1 else DualControllerConfig(max_lockers=max_lockers)
    for e in range(episodes):
        spec = specs[e % len(specs)]
        run_episode(MemoryAgent(store, config=config, learn=True), SymbolicWorld(spec, e), spec.name, e, 50)
    return store


def _lockers(agent) -> int:
    """The most lockers a belief agent's belief allows one component."""
    assert isinstance(agent, DualAgent)
    return agent.config.max_lockers


@pytest.mark.skipif(not DATA.is_dir(), reason=f"{DATA} (the shared disassembly data) is absent")
def test_by_default_a_third_computer_is_taken_apart_which_one_locker_cannot():
    train, test = load_spec(DATA / "lab-computer-a.json"), load_spec(DATA / "lab-computer-b.json")
    third = disassembly_variant(test, 1001)  # two RAM sticks and a GPU cable more than lab-computer-b
    k = training_max_lockers([train])
    assert k == 2 and scene_max_lockers(third) == 2 and scene_max_lockers(third, agent="oracle") == 1
    memory = _train([train], 1, k)  # one episode, as train.py does by default
    default = run_episode(make_agent("memory", third, memory), SymbolicWorld(third, 0), third.name, 0, 24)
    assert default.solved and default.num_actions <= 13
    assert _lockers(make_agent("memory", third, memory, max_lockers=1)) == 1  # given, it wins
    # the defaults before: trained and deciding with one locker a part, never within the budget
    paper = _train([train], 1, 1)
    one = run_episode(make_agent("memory", third, paper, max_lockers=1), SymbolicWorld(third, 0), third.name, 0, 24)
    assert not one.solved


def test_a_memory_that_learned_two_lockers_sets_the_default_and_says_so_after_reopening(tmp_path):
    box = BoxConfig(realizable=False)
    specs = [generate_random(RandomGraphConfig(8, multi_locker=True), seed=s, box=box) for s in range(1050, 1058)]
    assert training_max_lockers(specs) == 2
    path = tmp_path / "multi.sqlite"
    memory = _train(specs, 8, 2, MemoryStore(path))
    assert memory.learned_several_lockers() and memory.most_lockers >= 1.9
    reopened = MemoryStore.open_existing(path)
    assert reopened.most_lockers == pytest.approx(memory.most_lockers)
    test = generate_random(RandomGraphConfig(8, multi_locker=True), seed=7, box=box)
    assert scene_max_lockers(test) == 1  # the box alone says nothing: its lock rules are not the agent's to read
    assert _lockers(make_agent("memory", test, reopened)) == 2
    assert _lockers(make_agent("memory", test, reopened, max_lockers=1)) == 1


def test_paper_boxes_keep_the_one_locker_belief_and_decide_as_before():
    train = [paper_variant(i, 0) for i in TRAIN_INDICES]
    test = paper_variant(TEST_INDICES[0], 0)
    assert training_max_lockers(train) == 1
    memory = _train(train, 9, 1)
    assert memory.most_lockers <= 1.0 + 1e-9 and scene_max_lockers(test, memory) == 1
    # a belief over sets of two, left unsure on one-locker chains, has not learned two lockers either
    assert not _train(train, 9, 2).learned_several_lockers()
    runs = [
        run_episode(make_agent("memory", test, memory, max_lockers=k), SymbolicWorld(test, 3), test.name, 3, 30)
        for k in (None, 1)
    ]
    assert runs[0].solved and runs[0].actions == runs[1].actions
