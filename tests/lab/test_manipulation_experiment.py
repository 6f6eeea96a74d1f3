"""experiment.py manipulation: PPO from scratch on BoxManipulation-v0, learning curves written as they are made."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from puzzlebox.lab.errors import ExperimentFailed
from puzzlebox.lab.experiment_flags import ExperimentFlags
from puzzlebox.lab.experiment_protocols import run_experiment
from puzzlebox.scripts.experiment import main

ROOT = Path(__file__).resolve().parents[2]


def experiment(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts/experiment.py"), "manipulation", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=300,
    )


def test_quick_run_writes_a_curve_point_per_evaluation_a_figure_a_table_and_its_config(tmp_path):
    pytest.importorskip("stable_baselines3")
    result = experiment("--out", tmp_path, "--quick")
    assert result.returncode == 0, result.stderr[-2000:]
    summary = json.loads((tmp_path / "manipulation.json").read_text())
    config = summary["config"]
    assert summary["experiment"] == "manipulation" and config["algo"] == "ppo" and config["steps"] == 512
    assert [(r["task"], r["seed"], r["finished"]) for r in summary["runs"]] == [("slide", 0, True), ("wheel", 0, True)]
    for run in summary["runs"]:  # at 0, then every eval_every env steps up to the budget
        points = run["curve"]
        assert [p["steps"] for p in points] == list(range(0, config["steps"] + 1, config["eval_every"]))
        assert all(0.0 <= p["success"] <= 1.0 and p["wall_s"] >= 0 for p in points)
        assert run["steps"] == config["steps"] and run["steps_per_s"] > 0
    for task in ("slide", "wheel"):
        t = summary["tasks"][task]
        assert t["seeds"] == 1 and len(t["mean"]) == len(t["min"]) == len(t["max"]) == len(t["steps"]) == 3
        assert t["min"] <= t["mean"] <= t["max"]
    assert summary["wall_time_s"] > 0
    assert (tmp_path / "manipulation.png").read_bytes().startswith(b"\x89PNG")
    table = (tmp_path / "manipulation.md").read_text()
    assert "| slide | PPO | 1 | 512 |" in table and "| wheel | PPO | 1 | 512 |" in table
    saved = json.loads((tmp_path / "manipulation.config.json").read_text())
    assert saved["protocol"] == "manipulation" and saved["manipulation"]["steps"] == 512 and saved["quick"]


@pytest.mark.parametrize(
    "args, words",
    [(["--algo", "dqn"], "--algo"), (["--steps", "0"], "--steps"), (["--runs", "3"], "--runs"),
     (["--seeds", "0"], "--seeds")],
)  # fmt: skip
def test_a_bad_flag_is_one_line_and_exit_2(tmp_path, capsys, args, words):
    with pytest.raises(SystemExit) as exited:
        main(["manipulation", "--out", str(tmp_path), "--quick", *args])
    stderr = capsys.readouterr().err
    assert exited.value.code == 2 and stderr.count("\n") == 1 and words in stderr, stderr
    assert not (tmp_path / "manipulation.json").exists()


def test_a_bad_flag_through_the_command_line_is_one_line_without_a_traceback(tmp_path):
    result = experiment("--out", tmp_path, "--algo", "dqn")
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and "--algo" in result.stderr, result.stderr


def test_steps_and_algo_belong_to_the_manipulation_protocol(tmp_path):
    with pytest.raises(Exception, match="--steps and --algo go with the manipulation protocol"):
        run_experiment(ExperimentFlags(protocol="kinds", out=str(tmp_path), steps=10))


def test_without_stable_baselines3_the_error_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "stable_baselines3", None)  # import fails as if not installed
    with pytest.raises(ExperimentFailed, match=r"pip install puzzlebox\[rl\]"):
        run_experiment(ExperimentFlags(protocol="manipulation", out=str(tmp_path), quick=True))
