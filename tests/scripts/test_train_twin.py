"""Training in the twin: the memory keeps only what the robot sensed, with its provenance; the counts add up;
a training run killed and resumed ends with the memory an uninterrupted one writes."""

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]

from puzzlebox.lab.twin_training import TwinTraining  # noqa: E402  (scripts/ is not a package)
from puzzlebox.learning import MemoryAgent  # noqa: E402
from puzzlebox.learning.memory import MemoryStore  # noqa: E402
from puzzlebox.learning.memory.keys import se3_pose_keys  # noqa: E402
from puzzlebox.models import load_spec  # noqa: E402
from puzzlebox.twin.reality import load_profile  # noqa: E402


def run(*args, **kwargs):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=600, **kwargs)


@pytest.fixture(scope="module")
def specs(tmp_path_factory) -> list[Path]:
    out = tmp_path_factory.mktemp("specs")
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "train", "--out", out).returncode == 0
    return sorted(out.glob("*.json"))


def _entries(path: Path) -> list[tuple]:
    with sqlite3.connect(path) as conn:
        return conn.execute("SELECT kind_i, kind_j, key, value FROM pair_entries ORDER BY rowid").fetchall()


def test_a_twin_episode_stores_the_poses_the_robot_perceived_not_the_simulators(specs):
    """Under the realistic cell (calibration errors, noise) seen through the nominal calibration the perceived
    poses are off the truth by millimetres: the memory's keys are those of the perceived poses, to the bit."""
    spec = load_spec(specs[0])
    store = MemoryStore()
    agent = MemoryAgent(store, learn=True)
    result = TwinTraining(load_profile("realistic")).episode(agent, spec, seed=3, max_actions=3)
    assert result.num_actions == 3
    n = len(spec.components)
    off_diagonal = ~np.eye(n, dtype=bool)
    perceived = se3_pose_keys(agent._observation.poses, store.position_scale)[off_diagonal]
    stored = np.stack([key for bucket in store._pairs.values() for key, *_ in bucket])
    assert sorted(map(tuple, stored)) == sorted(map(tuple, perceived))
    truth = se3_pose_keys(spec.poses_in_world(), store.position_scale)[off_diagonal]  # (relative: placement-free)
    assert 1e-4 < np.abs(np.sort(stored, axis=0) - np.sort(truth, axis=0)).max()
    provenance = store.provenance()["twin"]
    assert provenance["episodes"] == 1 and provenance["profiles"] == {"realistic": 1}
    assert 0.0 < provenance["robot_hours"] < 0.2


def test_symbolic_and_twin_training_of_one_memory_add_up_in_its_provenance(specs, tmp_path):
    memory = tmp_path / "m.sqlite"
    symbolic = run(ROOT / "scripts/train.py", "--specs", *specs[:2], "--episodes", 3, "--memory", memory)
    assert symbolic.returncode == 0, symbolic.stderr
    twin = run(ROOT / "scripts/train.py", "--specs", specs[0], "--episodes", 1, "--memory", memory, "--sim", "twin",
               "--max-actions", 2, "--seed", 5)  # fmt: skip
    assert twin.returncode == 0, twin.stderr
    shown = run(ROOT / "scripts/memory.py", memory, "--json")
    assert shown.returncode == 0, shown.stderr
    report = json.loads(shown.stdout)
    assert (
        report["episodes"]
        == 4
        == report["provenance"]["symbolic"]["episodes"] + report["provenance"]["twin"]["episodes"]
    )
    assert report["provenance"]["twin"]["episodes"] == 1 and report["provenance"]["twin"]["profiles"] == {"ideal": 1}
    assert [run["episodes"] for run in report["training_runs"]] == [3, 1]
    text = run(ROOT / "scripts/memory.py", memory)
    assert "symbolic simulator: 3 episode(s)" in text.stdout and "twin: 1 episode(s)" in text.stdout


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (("--reality", "realistic"), "--reality and --calibration are for --sim twin"),
        (("--sim", "twin", "--reality", "nowhere"), "nowhere"),
        (("--sim", "twin", "--agent", "dqn", "--checkpoint", "x.pt"), "trains the memory agent only"),
    ],
)
def test_a_training_command_mistake_is_one_line(specs, tmp_path, flags, message):
    result = run(ROOT / "scripts/train.py", "--specs", specs[0], "--episodes", 1, "--memory", tmp_path / "m.sqlite",
                 *flags)  # fmt: skip
    assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr


def test_a_twin_training_run_killed_and_resumed_ends_with_the_uninterrupted_memory(specs, tmp_path):
    command = ["--specs", *specs[:2], "--episodes", 3, "--sim", "twin", "--max-actions", 3, "--seed", 11]
    whole = tmp_path / "whole.sqlite"
    assert run(ROOT / "scripts/train.py", *command, "--memory", whole).returncode == 0
    killed = tmp_path / "killed.sqlite"
    proc = subprocess.Popen([sys.executable, ROOT / "scripts/train.py", *map(str, command), "--memory", str(killed)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if killed.exists() and MemoryStore.open_existing(killed).num_episodes >= 1:
            os.kill(proc.pid, signal.SIGKILL)  # mid-way through the second episode
            break
        time.sleep(0.2)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, "the run ended before it could be killed"
    assert MemoryStore.open_existing(killed).num_episodes < 3
    resumed = run(ROOT / "scripts/train.py", *command, "--memory", killed, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert "already in the memory" in resumed.stdout
    assert _entries(killed) == _entries(whole)
    again = run(ROOT / "scripts/train.py", *command, "--memory", killed, "--resume")  # complete: nothing to do
    assert again.returncode == 0 and _entries(killed) == _entries(whole)
