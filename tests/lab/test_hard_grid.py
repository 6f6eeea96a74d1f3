"""``experiment.py hard-sets``: the hard test sets end to end in the twin, every step kept and resumed, the figures
counted as the issue states them (an unsolved trial counts the budget; runs over the 45 N margin), and the command
line's mistakes refused in one line before any work."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from puzzlebox.lab.hard_grid import FORCE_MARGIN_N, HardGridConfig, run_hard_grid, summarise_grid
from puzzlebox.lab.learning_boxes import LearningBox
from puzzlebox.lab.twin_learning import TwinLearningConfig
from puzzlebox.models.generator import paper_family

ROOT = Path(__file__).resolve().parents[2]


def _run(spec: str, solved: bool, actions: int, force: float, moved: list[bool]) -> dict:
    timeline = [{"outcome": "moved" if m else "failed", "reason": "" if m else "blocked: held", "moved": m,
                 "true_moved": m} for m in moved]  # fmt: skip
    return {"spec": spec, "seed": 1, "solved": solved, "num_actions": actions, "peak_true_wrist_force_n": force,
            "timeline": timeline, "perceived_position_error_m": {"a": 0.002}, "sim_time_s": 1.0,
            "wall_time_s": 1.0, "ended": None if solved else "GraspFailure: closed on nothing"}  # fmt: skip


def test_an_unsolved_trial_counts_the_budget_and_a_run_past_the_margin_is_counted():
    a, b = paper_family("test", seed=0)[:2]
    tests = [LearningBox(a, "random8", 1, 5), LearningBox(b, "chain8", 1, 6)]
    runs = [
        _run(a.name, True, 6, 30.0, [True] * 6),
        _run(a.name, False, 3, FORCE_MARGIN_N + 1.0, [True, False, False]),
        _run(b.name, True, 6, 20.0, [True] * 6),
    ]
    rows = {r["set"]: r for r in summarise_grid(HardGridConfig(max_actions=40), "realistic", runs, tests)["rows"]}
    assert rows["random8"]["solved"] == 1 and rows["random8"]["mean_actions"] == (6 + 40) / 2
    assert rows["random8"]["ratio_to_optimum"] == pytest.approx(23 / 5)
    assert rows["random8"]["runs_over_margin"] == 1 and rows["chain8"]["runs_over_margin"] == 0
    assert rows["all"]["trials"] == 3 and rows["all"]["peak_true_wrist_force_n"] == FORCE_MARGIN_N + 1.0
    assert rows["all"]["optimum"] == pytest.approx((5 + 5 + 6) / 3)
    assert rows["all"]["unsolved_reasons"] == [f"{a.name} seed 1: GraspFailure: closed on nothing"]


def test_both_cells_are_summarised_apart_each_family_and_all():
    a, b = paper_family("test", seed=0)[:2]
    tests = [LearningBox(a, "random8", 1, 5), LearningBox(b, "chain8", 1, 6)]
    runs = {
        "calibrated": [_run(a.name, True, 5, 30.0, [True] * 5), _run(b.name, True, 6, 20.0, [True] * 6)],
        "uncalibrated": [_run(a.name, False, 3, 50.0, [True, False, False]), _run(b.name, True, 6, 25.0, [True] * 6)],
    }
    rows = summarise_grid(HardGridConfig(max_actions=40), "realistic", runs, tests)["rows"]
    assert [(r["calibration"], r["set"]) for r in rows] == [
        ("calibrated", "random8"), ("calibrated", "chain8"), ("calibrated", "all"),
        ("uncalibrated", "random8"), ("uncalibrated", "chain8"), ("uncalibrated", "all"),
    ]  # fmt: skip
    assert rows[2]["solved"] == 2 and rows[5]["solved"] == 1 and rows[5]["runs_over_margin"] == 1
    assert rows[3]["mean_actions"] == 40 and rows[2]["peak_true_wrist_force_n"] == 30.0


def test_fresh_seeds_draw_other_boxes_and_placements_and_never_the_training_ones():
    fresh = HardGridConfig().with_seed(91_000)
    assert (fresh.test_seed, fresh.eval_seed) == (91_000, 91_100)
    with pytest.raises(ValueError, match="overlap"):
        HardGridConfig().with_seed(500)  # the training boxes' seeds 0..999
    with pytest.raises(ValueError, match="calibrations"):
        HardGridConfig(calibrations=("calibrated", "calibrated"))


def test_the_grid_runs_each_family_in_the_twin_keeps_every_trial_and_resumes(tmp_path):
    # without a calibration file (the calibrated cell's trials are those of every other twin experiment)
    config = HardGridConfig(boxes=1, placements=1, train_boxes=1, max_actions=3, calibrations=("uncalibrated",))
    summary = run_hard_grid(tmp_path, config, workers=1)
    rows = {r["set"]: r for r in summary["rows"]}
    assert list(rows) == ["random8", "multi8", "chain8", "all"] and rows["all"]["trials"] == 3
    assert {r["calibration"] for r in summary["rows"]} == {"uncalibrated"} and not (tmp_path / "calibrations").exists()
    assert rows["chain8"]["solved"] == 0 and rows["chain8"]["mean_actions"] == 3  # a chain of 8 takes 8
    assert all(0.0 < r["peak_true_wrist_force_n"] < 60.0 for r in rows.values())  # the arm touched every box
    trials = sorted((tmp_path / "trials").glob("*.json"))
    assert len(trials) == 3
    records = [json.loads(t.read_text()) for t in trials]
    assert {r["record"]["seed"] for r in records} == {config.eval_seed}
    assert all(r["key"].endswith("-p0-uncalibrated") for r in records)
    assert (tmp_path / "memory" / "memory-s0.sqlite").is_file() and not list((tmp_path / "memory").glob(".*"))
    assert (tmp_path / "hard-sets.png").read_bytes().startswith(b"\x89PNG")
    assert "| all | 3 |" in (tmp_path / "hard-sets.md").read_text()
    stamps = [t.stat().st_mtime_ns for t in trials]
    again = run_hard_grid(tmp_path, config, workers=1)  # resumes: every trial reused, the same figures
    assert [t.stat().st_mtime_ns for t in trials] == stamps
    assert again["rows"] == summary["rows"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--profile", "stormy"), "--profile:"),
        (("--boxes", "0"), "--boxes must be >= 1"),
        (("--runs", "0"), "--runs must be >= 1"),
        (("--seeds", "2"), "takes only --out, --profile"),
        (("--memory", "missing.sqlite"), "--memory missing.sqlite: no such file"),
        (("--seed", "10"), "--seed 10: test seeds from 10 and training seeds from 0 overlap"),
        (("--calibration", "sometimes"), "invalid choice: 'sometimes'"),
    ],
)
def test_hard_sets_command_line_mistakes_are_one_line_and_exit_2(tmp_path, args, message):
    result = subprocess.run([sys.executable, str(ROOT / "scripts/experiment.py"), "hard-sets", "--out",
                             str(tmp_path / "out"), *args], capture_output=True, text=True, timeout=120)  # fmt: skip
    assert result.returncode == 2 and message in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr
    assert not (tmp_path / "out").exists()  # refused before any work


def test_profile_and_boxes_go_with_the_hard_sets_protocol_only(tmp_path):
    result = subprocess.run([sys.executable, str(ROOT / "scripts/experiment.py"), "twin-learning", "--out",
                             str(tmp_path / "out"), "--profile", "harsh"], capture_output=True, text=True)  # fmt: skip
    assert result.returncode == 2 and "--profile goes with the hard-sets protocol" in result.stderr
    result = subprocess.run([sys.executable, str(ROOT / "scripts/experiment.py"), "reality", "--out",
                             str(tmp_path / "out"), "--seed", "91000", "--calibration", "without"],
                            capture_output=True, text=True)  # fmt: skip
    assert (
        result.returncode == 2 and "--seed and --calibration go with the hard-sets and twin-learning" in result.stderr
    )


def test_twin_learning_takes_fresh_seeds_and_a_cell_without_calibration(tmp_path):
    """``twin-learning --seed S``: test placements from S, training episodes from S + 10000; ``--calibration``: with
    or without a calibration file (not both: a memory learns through one cell)."""
    fresh = TwinLearningConfig().with_seed(83_000)
    assert (fresh.eval_seed, fresh.train_seed) == (83_000, 93_000)
    command = [sys.executable, str(ROOT / "scripts/experiment.py"), "twin-learning", "--out", str(tmp_path / "out")]
    result = subprocess.run([*command, "--calibration", "both"], capture_output=True, text=True)
    assert result.returncode == 2 and "twin-learning --calibration: with or without" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()
