"""Baseline checkpoints round-trip exactly and refuse what they cannot load."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from puzzlebox.learning import SymbolicWorld, make_agent, run_episode  # noqa: E402
from puzzlebox.learning.baselines import (  # noqa: E402
    CheckpointError,
    DQNAgent,
    DQNConfig,
    GraphNetworkConfig,
    ModelBasedAgent,
    ModelBasedConfig,
    load_checkpoint,
    save_checkpoint,
)
from puzzlebox.learning.errors import ConfigError  # noqa: E402
from puzzlebox.models.generator import generate_chain  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SMALL = GraphNetworkConfig(blocks=1, hidden=16)


@pytest.mark.parametrize("agent", [DQNAgent(DQNConfig(network=SMALL, batch_size=4)),
                                   ModelBasedAgent(ModelBasedConfig(network=SMALL, batch_size=4)),
                                   DQNAgent(DQNConfig.multitask(network=SMALL, batch_size=4)),
                                   ModelBasedAgent(ModelBasedConfig.multitask(
                                       network=GraphNetworkConfig(blocks=1, hidden=16, poses="absolute"),
                                       batch_size=4))])  # fmt: skip
def test_checkpoint_round_trip_gives_identical_outputs(tmp_path, agent):
    spec = generate_chain(["door", "slide", "wheel"], seed=0)
    for e in range(5):
        run_episode(agent, SymbolicWorld(spec, e), spec.name, e, 10)
    path = save_checkpoint(agent, tmp_path / "agent.pt")
    again = load_checkpoint(path, expected_agent=agent.name)
    observation = SymbolicWorld(spec, 99).observe()
    network = agent.q if isinstance(agent, DQNAgent) else agent.net
    reloaded = again.q if isinstance(again, DQNAgent) else again.net
    np.testing.assert_array_equal(network.evaluate(observation), reloaded.evaluate(observation))
    meta = json.loads((tmp_path / "agent.pt.json").read_text())
    assert meta["agent"] == agent.name and meta["episodes"] == 5 and "torch" in meta["versions"]
    assert not again.training and again.config == agent.config  # MT-OPT flags and pose encoding included


def test_bad_checkpoints_are_clear_errors(tmp_path):
    with pytest.raises(CheckpointError, match="no checkpoint"):
        load_checkpoint(tmp_path / "missing.pt")
    agent = DQNAgent(DQNConfig(network=SMALL))
    path = save_checkpoint(agent, tmp_path / "dqn.pt")
    with pytest.raises(CheckpointError, match="not 'model-based'"):
        load_checkpoint(path, expected_agent="model-based")
    meta = (tmp_path / "dqn.pt.json").read_text()
    path.write_bytes(b"not a checkpoint")  # the .pt is garbage, its .json intact
    with pytest.raises(CheckpointError, match="not a torch checkpoint"):
        load_checkpoint(path)
    (tmp_path / "dqn.pt.json").write_text(meta.replace('"network"', '"netwerk"'))
    with pytest.raises(CheckpointError, match="no valid dqn config"):
        load_checkpoint(path)
    (tmp_path / "dqn.pt.json").write_text("{not json")
    with pytest.raises(CheckpointError, match="JSON"):
        load_checkpoint(path)
    with pytest.raises(ConfigError, match="needs a checkpoint"):
        make_agent("dqn", generate_chain(["door", "slide"], seed=0))


def test_train_then_trial_with_a_checkpoint_from_the_command_line(tmp_path):
    box = tmp_path / "box.json"
    box.write_text(generate_chain(["door", "slide"], seed=0).to_json())
    run = lambda *a: subprocess.run([sys.executable, *map(str, a)], capture_output=True, text=True, timeout=600)  # noqa: E731
    trained = run(ROOT / "scripts/train.py", "--specs", box, "--episodes", 20, "--agent", "dqn",
                  "--checkpoint", tmp_path / "dqn.pt")  # fmt: skip
    assert trained.returncode == 0, trained.stderr
    trial = run(
        ROOT / "scripts/trial.py", "--specs", box, "--sim", "symbolic", "--agent", "dqn", "--checkpoint",
        tmp_path / "dqn.pt", "--runs", 2, "--seed", 0, "--max-actions", 10, "--out", tmp_path / "out",
    )  # fmt: skip
    assert trial.returncode == 0, trial.stderr
    assert len(json.loads((tmp_path / "out" / "results.json").read_text())["runs"]) == 2
