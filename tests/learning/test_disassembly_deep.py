"""The deep baselines on the disassembly scenes: a network per kind family, checkpoints that know
their family, the dense reward, and the train-on-one-computer protocol (issue 14)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from puzzlebox.learning.agents.factory import make_agent  # noqa: E402
from puzzlebox.learning.baselines import (  # noqa: E402
    CheckpointError,
    GraphNetworkConfig,
    load_checkpoint,
    make_learner,
    observation_tensors,
    save_checkpoint,
)
from puzzlebox.learning.baselines.graph_network import NODE_FEATURES, SceneMismatch  # noqa: E402
from puzzlebox.learning.baselines.multitask import progress  # noqa: E402
from puzzlebox.learning.errors import ConfigError, LearningError  # noqa: E402
from puzzlebox.learning.experiments.disassembly_deep import train_deep_on_scene  # noqa: E402
from puzzlebox.learning.symbolic_world import SymbolicWorld  # noqa: E402
from puzzlebox.learning.trial import run_episode  # noqa: E402
from puzzlebox.models import KIND_NAMES, load_spec, spec_from_dict  # noqa: E402
from puzzlebox.models.disassembly_kinds import DISASSEMBLY_KIND_NAMES  # noqa: E402

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "disassembly"
pytestmark = pytest.mark.skipif(not DATA.is_dir(), reason=f"{DATA} (the shared disassembly data) is absent")
SMALL = {"blocks": 1, "hidden": 16}  # fast networks: the tests check plumbing, not learning


@pytest.fixture(scope="module")
def lab_a():
    return load_spec(DATA / "lab-computer-a.json")


@pytest.fixture(scope="module")
def lab_b():
    return load_spec(DATA / "lab-computer-b.json")


def test_a_puzzle_box_network_is_exactly_the_default(spec_dict):
    box = spec_from_dict(spec_dict)
    config = GraphNetworkConfig.for_spec(box)
    assert config == GraphNetworkConfig() and config.kinds == tuple(KIND_NAMES)
    assert (config.node_features, config.edge_features, config.state_column) == (NODE_FEATURES, 4, len(KIND_NAMES))


@pytest.mark.parametrize("name", ["dqn", "model-based"])
def test_the_network_builds_and_acts_on_lab_computer_b(lab_b, name):
    config = GraphNetworkConfig.for_spec(lab_b, **SMALL)
    assert config.kinds == DISASSEMBLY_KIND_NAMES and config.pose_size == 6
    observation = SymbolicWorld(lab_b, 0).observe()
    nodes, edges = observation_tensors(observation, config)
    assert nodes.shape == (8, len(DISASSEMBLY_KIND_NAMES) + 2) and edges.shape == (8, 8, 9)
    agent = make_learner(name, 0, config)
    network = agent.q if name == "dqn" else agent.net
    assert np.all(np.isfinite(network.evaluate(observation))) and network.evaluate(observation).shape == (8,)
    run = run_episode(agent, SymbolicWorld(lab_b, 1), lab_b.name, 1, 24)
    assert run.num_actions <= 24 and agent.replay_size() > 0


def test_an_observation_of_another_family_raises_a_typed_error_naming_the_kinds(lab_b, spec_dict):
    with pytest.raises(SceneMismatch, match="puzzle-box family.*'door'") as err:
        observation_tensors(SymbolicWorld(lab_b, 0).observe(), GraphNetworkConfig())
    assert isinstance(err.value, LearningError)
    box = spec_from_dict(spec_dict)
    with pytest.raises(SceneMismatch, match="disassembly family.*'motherboard'"):
        observation_tensors(SymbolicWorld(box, 0).observe(), GraphNetworkConfig.for_spec(lab_b))
    with pytest.raises(ConfigError, match="planar"):
        GraphNetworkConfig.for_spec(lab_b, poses="absolute")


@pytest.mark.parametrize("name", ["dqn", "model-based"])
def test_a_disassembly_checkpoint_reloads_with_identical_outputs(tmp_path, lab_a, lab_b, name):
    agent = make_learner(name, 0, GraphNetworkConfig.for_spec(lab_a, **SMALL), batch_size=4)
    run_episode(agent, SymbolicWorld(lab_a, 0), lab_a.name, 0, 24)
    path = save_checkpoint(agent, tmp_path / "agent.pt")
    loaded = make_agent(name, lab_b, checkpoint=str(path))  # the other computer: the same family
    assert loaded.config == agent.config and loaded.config.network.kinds == DISASSEMBLY_KIND_NAMES
    observation = SymbolicWorld(lab_b, 2).observe()
    before, after = (getattr(a, "q", None) or a.net for a in (agent, loaded))
    np.testing.assert_array_equal(before.evaluate(observation), after.evaluate(observation))


def test_a_puzzle_box_checkpoint_on_a_disassembly_scene_is_refused_naming_both_families(tmp_path, lab_b, spec_dict):
    box = spec_from_dict(spec_dict)
    path = save_checkpoint(make_learner("dqn", 0, GraphNetworkConfig(**SMALL)), tmp_path / "box.pt")
    with pytest.raises(CheckpointError, match="puzzle-box family.*disassembly family"):
        make_agent("dqn", lab_b, checkpoint=str(path))
    disassembly = save_checkpoint(
        make_learner("dqn", 0, GraphNetworkConfig.for_spec(lab_b, **SMALL)), tmp_path / "d.pt"
    )
    with pytest.raises(CheckpointError, match="disassembly family.*puzzle-box family"):
        make_agent("dqn", box, checkpoint=str(disassembly))


def test_a_checkpoint_saved_before_kind_families_loads_as_the_puzzle_box_family(tmp_path, spec_dict):
    path = save_checkpoint(make_learner("model-based", 0, GraphNetworkConfig(**SMALL)), tmp_path / "old.pt")
    meta_path = Path(str(path) + ".json")
    meta = json.loads(meta_path.read_text())
    for field in ("kinds", "pose_size"):
        del meta["config"]["network"][field]
    meta_path.write_text(json.dumps(meta))
    loaded = load_checkpoint(path, scene=spec_from_dict(spec_dict))
    assert loaded.config.network == GraphNetworkConfig(**SMALL)


def test_progress_is_plus_one_for_a_removal_and_minus_one_for_a_reinsertion():
    before = np.array([[0.0], [1.0], [0.0]])
    after = np.array([[1.0], [0.0], [0.0]])
    assert [progress(before, after, i, 0) for i in range(3)] == [1, -1, 0]


def _replay_rewards(lab_a, **overrides):
    """Rewards the replay saw in 3 fully random episodes (epsilon 1: the same tries whatever is learnt)."""
    config = GraphNetworkConfig.for_spec(lab_a, **SMALL)
    agent = make_learner("dqn", 0, config, epsilon_min=1.0, **overrides)
    for e in range(3):
        run_episode(agent, SymbolicWorld(lab_a, e), lab_a.name, e, 24)
    examples = [x for buffer in agent.replay.values() for x in buffer]
    moves = [progress(x.nodes, x.next_nodes, x.action, config.state_column) for x in examples]
    return np.array([x.reward for x in examples]), np.array(moves)


def test_a_zero_dense_reward_is_the_sparse_reward_and_a_positive_one_pays_removals(lab_a):
    sparse, moves = _replay_rewards(lab_a)
    zero, _ = _replay_rewards(lab_a, progress_reward=0.0)
    dense, _ = _replay_rewards(lab_a, progress_reward=0.1)
    np.testing.assert_array_equal(zero, sparse)
    assert set(np.round(sparse, 6)) <= {1.0, -0.05}
    assert np.any(moves == 1)
    np.testing.assert_array_equal(dense[sparse != 1.0], sparse[sparse != 1.0] + 0.1 * moves[sparse != 1.0])


@pytest.mark.parametrize("name", ["dqn", "model-based"])
def test_training_on_a_scene_is_deterministic(lab_a, lab_b, name):
    records = [train_deep_on_scene(name, lab_a, [lab_b], (0, 3), seed=1, runs_per_test=2) for _ in range(2)]
    assert records[0] == records[1]
    assert [r["episodes"] for r in records[0]] == [0, 3]
    untrained = records[0][0]  # 24 tries of an untrained network never take a motherboard out: 8 must come first
    assert untrained["solved"] == 0.0 and untrained["mean_actions"] == 24.0
    for record in records[0]:
        assert record["solved"] in (0.0, 0.5, 1.0)  # a fraction of the 2 runs
        assert set(record["per_test"]) == {lab_b.name}


def test_training_on_a_scene_refuses_bad_schedules_and_other_families(lab_a, spec_dict):
    with pytest.raises(ConfigError, match="increasing"):
        train_deep_on_scene("dqn", lab_a, [lab_a], (3, 0), seed=0)
    with pytest.raises(SceneMismatch, match="disassembly family"):
        train_deep_on_scene("dqn", lab_a, [spec_from_dict(spec_dict)], (0,), seed=0)
