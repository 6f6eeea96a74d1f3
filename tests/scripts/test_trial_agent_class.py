"""trial.py --agent package.module:Class runs a user's agent class in either sim, and refuses in one line (exit 2)
a module or class that does not exist or does not satisfy the Agent protocol."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# a user's agent module: the agent of the Python API tests, and a class that is not an agent
AGENTS = (
    (ROOT / "tests/lab/user_agents.py").read_text()
    + """

class Chooser:
    def choose(self, observation):
        return 0


class OffTheBox(TryInTurn):
    name = "off-the-box"

    def choose(self, observation):
        return -1


class Quitter(TryInTurn):
    name = "quitter"

    def choose(self, observation):
        raise SystemExit(0)
"""
)


@pytest.fixture
def folder(tmp_path):
    (tmp_path / "my_agents.py").write_text(AGENTS)
    specs = tmp_path / "specs"
    subprocess.run([sys.executable, ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs],
                   check=True, capture_output=True)  # fmt: skip
    return tmp_path


def trial(folder: Path, *args):
    spec = folder / "specs" / "paper-test-0.json"
    return subprocess.run([sys.executable, ROOT / "scripts/trial.py", "--specs", spec, "--seed", "0", *map(str, args)],
                          cwd=folder, capture_output=True, text=True, timeout=900)  # fmt: skip


@pytest.mark.parametrize(("sim", "extra"), [("symbolic", ["--runs", "2", "--workers", "2"]), ("twin", ["--runs", "1"])])
def test_a_users_agent_class_runs_in_either_sim(folder, sim, extra):
    max_actions = 40 if sim == "symbolic" else 2
    result = trial(folder, "--sim", sim, "--agent", "my_agents:TryInTurn", "--max-actions", max_actions, "--out",
                   folder / sim, *extra)  # fmt: skip
    assert result.returncode == 0, result.stderr
    runs = json.loads((folder / sim / "results.json").read_text())["runs"]
    assert runs and all(r["num_actions"] >= 1 for r in runs)
    if sim == "symbolic":
        assert all(r["solved"] for r in runs)  # in turn, every component is tried again: the box opens
    else:
        assert runs[0]["num_actions"] == 2 and runs[0]["sensed_sha256"]


@pytest.mark.parametrize(
    ("agent", "says"),
    [
        ("no_such_module:Agent", "cannot import module 'no_such_module'"),
        ("my_agents:Nobody", "has no 'Nobody'; its classes: ['Chooser', 'OffTheBox', 'Quitter', 'TryInTurn']"),
        ("my_agents:Chooser", "does not satisfy the Agent protocol: no method begin_episode, record, end_episode"),
    ],
)
def test_an_agent_class_that_cannot_run_is_one_line_and_exit_2(folder, agent, says):
    result = trial(folder, "--sim", "symbolic", "--agent", agent, "--runs", "1", "--max-actions", "5", "--out",
                   folder / "out")  # fmt: skip
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert (
        result.stderr.strip().startswith("error: ") and says in result.stderr and len(result.stderr.splitlines()) == 1
    )


@pytest.mark.parametrize(
    ("sim", "agent", "says"),
    [
        ("symbolic", "my_agents:Quitter", "agent 'quitter' raised SystemExit in choose()"),
        ("twin", "my_agents:OffTheBox", "agent 'off-the-box' chose -1: the box's parts are 0..4"),
    ],
)
def test_an_agent_that_misbehaves_fails_its_run_naming_it_before_the_arm_moves(folder, sim, agent, says):
    # before: -1 had the twin's arm try the last part, and SystemExit ended trial.py with exit 0 and no results
    result = trial(folder, "--sim", sim, "--agent", agent, "--runs", "1", "--max-actions", "3", "--out", folder / "o")
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert says in result.stderr and "--resume retries the failed ones" in result.stderr
