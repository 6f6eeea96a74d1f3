"""The Python API of a trial (issue 34): a user's own agent runs end to end in either sim, a user's own loop opens
the world, observers see every step without changing the trial, and the README's example runs as written."""

from __future__ import annotations

import dataclasses
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from user_agents import TryInTurn

from puzzlebox.lab import (
    RealCell,
    TrialConfig,
    TrialConfigError,
    TrialObserver,
    TrialRecord,
    TwinCell,
    open_world,
    run_trial,
)
from puzzlebox.lab.trial_task import without_timing
from puzzlebox.models.generator import paper_family

ROOT = Path(__file__).resolve().parents[2]
SPEC = paper_family("test")[0]


class Counting(TrialObserver):
    """Counts every event it is given."""

    def __init__(self):
        self.counts = {"attach": 0, "sensed": 0, "waited": 0, "begins": 0, "ended": 0, "finish": 0}

    def attach(self, trial):
        self.counts["attach"] += 1
        assert trial.world is not None and trial.agent is not None

    def sensed(self, what, value):
        self.counts["sensed"] += 1

    def waited(self, now):
        self.counts["waited"] += 1

    def action_begins(self, caption):
        self.counts["begins"] += 1

    def action_ended(self, caption):
        self.counts["ended"] += 1

    def finish(self):
        self.counts["finish"] += 1


def test_a_users_agent_solves_a_box_in_the_symbolic_sim():
    record = run_trial(SPEC, TrialConfig(sim="symbolic", seed=3, max_actions=60), agent=TryInTurn())
    assert record.solved and record.num_actions >= 5 and record.sim_time_s is None
    assert record.to_dict()["actions"][0]["component"] in {c.name for c in SPEC.components}
    assert TrialRecord.from_dict(record.to_dict()) == record  # results.json's entries read back


def test_observers_see_every_step_of_a_twin_trial_without_changing_it():
    config = TrialConfig(agent="oracle", seed=2, max_actions=2)
    plain = run_trial(SPEC, config)
    watcher = Counting()
    watched = run_trial(SPEC, config, observers=[watcher])
    assert without_timing(watched.to_dict()) == without_timing(plain.to_dict())
    assert watched.sensed_sha256 == plain.sensed_sha256 and plain.num_actions == 2
    assert TrialRecord.from_dict(plain.to_dict()) == plain
    counts = watcher.counts
    assert counts["attach"] == counts["finish"] == 1 and counts["begins"] == counts["ended"] == 2
    assert counts["sensed"] > 100 and counts["waited"] > 100  # every reading and every control tick


def test_a_twin_cell_is_the_trial_its_profile_and_calibration_make():
    config = TrialConfig(agent="oracle", seed=4, max_actions=1)
    by_config = run_trial(SPEC, dataclasses.replace(config, reality="realistic"))
    in_cell = run_trial(SPEC, config, cell=TwinCell.load("realistic"))
    assert in_cell.reality == "realistic" and in_cell.sensed_sha256 == by_config.sensed_sha256
    assert in_cell.sensed_sha256 != run_trial(SPEC, config).sensed_sha256  # the cell is not ignored
    with pytest.raises(TrialConfigError, match="TwinCell"):
        run_trial(SPEC, TrialConfig(sim="symbolic"), cell=TwinCell.load("ideal"))


def test_a_users_loop_drives_the_twin_through_open_world():
    with open_world(SPEC, TrialConfig(seed=0)) as world:
        observation = world.observe()
        assert len(observation) == len(SPEC.components)
        goal = observation.goal_index
        first = next(i for i in range(len(observation)) if i != goal)
        result = world.try_toggle(first)
        assert result.outcome in ("moved", "blocked")
        assert world.observe().components[first].state == int(result.moved)


def test_a_config_that_cannot_run_is_refused_with_every_problem():
    with pytest.raises(TrialConfigError, match="max_actions.*locks"):
        TrialConfig(max_actions=0, locks="glue")
    # absurd values and wrong types: each named, none a raw TypeError later
    with pytest.raises(TrialConfigError, match=r"seed must be <= 4294967295.*max_actions must be an integer, got 2.5"):
        TrialConfig(seed=2**70, max_actions=2.5)  # type: ignore[arg-type]
    with pytest.raises(TrialConfigError, match="agent must be an agent's name.*reality must be.*memory must be a path"):
        TrialConfig(agent=TryInTurn(), reality=3.0, memory=5)  # type: ignore[arg-type]
    assert TrialConfig(seed=np.int64(7)).seed == 7  # a numpy integer is a seed
    with pytest.raises(TrialConfigError, match="twin"):
        run_trial(SPEC, TrialConfig(sim="symbolic"), video="out.mp4")
    arm = RealCell(robot=None, config=None, calibration=None)  # type: ignore[arg-type]  # refused before use
    with pytest.raises(TrialConfigError, match="real cell"):
        run_trial(SPEC, TrialConfig(misreport_kind=True), cell=arm)
    with pytest.raises(TrialConfigError, match="real cell has no simulator"):
        run_trial(SPEC, cell=arm, video="out.mp4")


def _python_api_block() -> str:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Python API", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_python_api_example_is_a_short_program_of_public_names():
    code = _python_api_block()
    assert len(code.strip().splitlines()) <= 25
    assert "sys.path" not in code and not re.search(r"\b_[a-z]", code.replace("__", ""))


def test_the_readme_python_api_example_runs_verbatim_beside_a_users_own_models_and_learning(tmp_path):
    for shadow in ("models", "learning"):  # most ML repositories have their own
        (tmp_path / shadow).mkdir()
        (tmp_path / shadow / "__init__.py").write_text("raise ImportError('the user\\'s own package')\n")
    (tmp_path / "example.py").write_text(_python_api_block())
    result = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, capture_output=True, text=True, timeout=900)
    assert result.returncode == 0, result.stderr[-2000:]
    # it prints its record: the box solved by trying each part in turn, more actions than the 5 of a chain's
    # shortest solution, every sensed outcome the truth
    solved, actions, agreement = result.stdout.strip().splitlines()[-1].split()
    assert solved == "True" and 5 < int(actions) <= 30 and float(agreement) == 1.0, result.stdout
