"""The symbolic world and the agents on a disassembly scene (issue 14, part 1)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from puzzlebox.learning.agents.dual_agent import MemoryAgent
from puzzlebox.learning.agents.factory import make_agent
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.learning.puzzle_env import PuzzleEnv
from puzzlebox.learning.symbolic_world import SymbolicWorld
from puzzlebox.learning.trial import run_episode
from puzzlebox.models import LockTable, load_spec, spec_from_dict
from puzzlebox.models.disassembly_kinds import DISASSEMBLY_KIND_NAMES

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "disassembly"
pytestmark = pytest.mark.skipif(not DATA.is_dir(), reason=f"{DATA} (the shared disassembly data) is absent")


@pytest.fixture(scope="module")
def lab_b():
    return load_spec(DATA / "lab-computer-b.json")


def test_the_world_shows_disassembly_kinds_and_6dof_poses(lab_b):
    world = SymbolicWorld(lab_b, seed=3)
    observation = world.observe()
    assert sorted(observation.kinds) == sorted(lab_b.kinds)
    assert observation.poses.shape == (8, 6)
    assert world.env.kind_names == DISASSEMBLY_KIND_NAMES
    assert PuzzleEnv(lab_b).observation_space.contains(PuzzleEnv(lab_b).reset(seed=0)[0])


@pytest.mark.parametrize("seed", range(4))
def test_the_oracle_solves_lab_computer_b_in_its_optimum(lab_b, seed):
    assert len(LockTable.from_spec(lab_b).shortest_solution()) == 8
    run = run_episode(make_agent("oracle", lab_b), SymbolicWorld(lab_b, seed), lab_b.name, seed, 24)
    assert run.solved and run.num_actions == 8


def test_the_dual_agent_runs_on_a_disassembly_scene(lab_b):
    run = run_episode(make_agent("dual", lab_b), SymbolicWorld(lab_b, 1), lab_b.name, 1, 24)
    assert run.num_actions <= 24 and (run.solved or run.num_actions == 24)


def test_one_memory_holds_puzzle_boxes_and_disassembly_scenes_and_recalls_each_as_if_alone(lab_b, spec_dict):
    """SE(3) keys give planar boxes and 6-DOF scenes one key; buckets and the back-off stay within a kind family,
    so what a memory recalls for a computer does not depend on the puzzle boxes it also holds, and the reverse."""
    box = spec_from_dict(spec_dict)
    lab_a = load_spec(DATA / "lab-computer-a.json")
    alone_box, alone_lab, mixed = MemoryStore(), MemoryStore(), MemoryStore()
    for store, specs in ((alone_box, [box]), (alone_lab, [lab_a]), (mixed, [box, lab_a])):
        for spec in specs:
            run_episode(MemoryAgent(store, learn=True), SymbolicWorld(spec, 0), spec.name, 0, 24)
    for spec, alone in ((lab_b, alone_lab), (box, alone_box)):
        observation = SymbolicWorld(spec, 1).observe()
        np.testing.assert_array_equal(
            MemoryAgent(mixed).initial_prior(observation), MemoryAgent(alone).initial_prior(observation)
        )
    run = run_episode(MemoryAgent(mixed), SymbolicWorld(lab_b, 0), lab_b.name, 0, 24)
    assert run.solved and run.num_actions <= 24


def test_misreported_kinds_are_other_kinds_of_the_scenes_whole_family(lab_b):
    """Each episode reports exactly three components as a kind they are not, the rest as they are; the wrong kinds
    are drawn from the whole disassembly family (kinds the scene lacks too, such as ``gpu_cable``), not from the
    first three codes (the puzzle boxes' door, slide and wheel)."""
    from puzzlebox.learning.puzzle_env import FaultConfig, PuzzleEnvConfig

    env = PuzzleEnv(lab_b, PuzzleEnvConfig(faults=FaultConfig(misreported_kinds=3)))
    told: set[str] = set()
    for seed in range(40):
        obs, _ = env.reset(seed=seed)
        reported = [DISASSEMBLY_KIND_NAMES[k] for k in obs["kinds"]]
        true = [lab_b.components[env.spec_index(i)].kind for i in range(len(reported))]
        wrong = [r for r, t in zip(reported, true, strict=True) if r != t]
        assert len(wrong) == 3, (reported, true)
        told |= set(wrong)
    assert told == set(DISASSEMBLY_KIND_NAMES)
