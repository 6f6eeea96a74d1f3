"""The symbolic world and the agents on a disassembly scene (issue 14, part 1)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from learning.agents.dual_agent import MemoryAgent
from learning.agents.factory import make_agent
from learning.errors import UnsupportedPoses
from learning.memory.store import MemoryStore
from learning.puzzle_env import PuzzleEnv
from learning.symbolic_world import SymbolicWorld
from learning.trial import run_episode
from models import LockTable, load_spec, spec_from_dict
from models.disassembly_kinds import DISASSEMBLY_KIND_NAMES

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


def test_a_memory_of_planar_boxes_refuses_a_6dof_scene_clearly(lab_b, spec_dict):
    store = MemoryStore()
    box = spec_from_dict(spec_dict)
    run_episode(MemoryAgent(store, learn=True), SymbolicWorld(box, 0), box.name, 0, 10)
    assert store.key_sizes() == {4}
    with pytest.raises(UnsupportedPoses, match="SE\\(3\\) memory keys"):
        run_episode(MemoryAgent(store), SymbolicWorld(lab_b, 0), lab_b.name, 0, 24)


def test_misreported_kinds_stay_in_the_scenes_family(lab_b):
    from learning.puzzle_env import FaultConfig, PuzzleEnvConfig

    env = PuzzleEnv(lab_b, PuzzleEnvConfig(faults=FaultConfig(misreported_kinds=3)))
    obs, _ = env.reset(seed=0)
    assert np.all((obs["kinds"] >= 0) & (obs["kinds"] < len(DISASSEMBLY_KIND_NAMES)))
