"""``experiment.py regression``: the fixed grid's fingerprints, and a comparison with a reference that finds a
changed outcome, action or sensed hash when one is planted (and nothing when the grid is run again)."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from pathlib import Path

from puzzlebox.lab.regression_grid import RegressionGridConfig, compare, fingerprint, grid_trials, load_reference
from puzzlebox.learning.memory import MemoryStore

ROOT = Path(__file__).resolve().parents[2]


def _grid(actions: list[list[str]], sha: str = "abc") -> dict:
    return {"trials": {"realistic-box-s0": {"solved": True, "num_actions": len(actions), "actions": actions,
                                            "sensed_sha256": sha, "reasons": [""] * len(actions)}}}  # fmt: skip


def test_a_planted_outcome_action_or_hash_is_found_and_a_reason_alone_is_not():
    reference = _grid([["door-0", "blocked"], ["slide-1", "moved"]])
    assert compare(copy.deepcopy(reference), reference) == []
    changed = _grid([["door-0", "moved"], ["slide-1", "moved"]])
    assert compare(changed, reference) == [
        "realistic-box-s0: action 1 is ['door-0', 'moved'], the reference's ['door-0', 'blocked']"
    ]
    longer = _grid([["door-0", "blocked"], ["slide-1", "moved"], ["wheel-2", "moved"]])
    assert "realistic-box-s0: num_actions 3, the reference's 2" in compare(longer, reference)
    assert "realistic-box-s0: action 3 is ['wheel-2', 'moved'], the reference's nothing" in compare(longer, reference)
    assert compare(_grid(reference["trials"]["realistic-box-s0"]["actions"], "abd"), reference) == [
        "realistic-box-s0: sensed_sha256 'abd', the reference's 'abc'"
    ]
    reworded = copy.deepcopy(reference)
    reworded["trials"]["realistic-box-s0"]["reasons"] = ["latched", ""]
    assert compare(reworded, reference) == []  # the text is for reading; the types are what must hold
    assert compare({"trials": {}}, reference) == ["realistic-box-s0: not in the results"]


def test_the_grid_is_the_issue_s_52_trials_each_key_once(tmp_path):
    memories = {"paper": tmp_path / "m.sqlite", "hard": tmp_path / "m.sqlite"}
    MemoryStore(memories["paper"]).close()  # (an empty memory: the tasks are only listed)
    tasks = grid_trials(RegressionGridConfig(), tmp_path, memories, {"realistic": {}, "harsh": {}},
                        {"realistic": {}, "harsh": {}})  # fmt: skip
    keys = [t.key for t in tasks]
    assert len(keys) == len(set(keys)) == 30 + 12 + 10
    assert sum(k.startswith("harsh-") for k in keys) == 15 and sum(k.startswith("hard-") for k in keys) == 12
    assert all(t.settings.get("misreport_kind") for t in tasks if t.key.startswith("misreported-"))


def test_the_committed_reference_covers_the_grid_trial_for_trial(tmp_path):
    """``tests/regression/reference.json``: the grid as it ran before the hand's redesign (the command in it)."""
    reference = load_reference(ROOT / "tests/regression/reference.json")
    memories = {"paper": tmp_path / "m.sqlite", "hard": tmp_path / "m.sqlite"}
    MemoryStore(memories["paper"]).close()
    keys = [t.key for t in grid_trials(RegressionGridConfig(), tmp_path, memories, {"realistic": {}, "harsh": {}},
                                       {"realistic": {}, "harsh": {}})]  # fmt: skip
    assert sorted(reference["trials"]) == sorted(keys)
    assert all(
        len(t["sensed_sha256"]) == 64 and len(t["actions"]) == t["num_actions"] for t in reference["trials"].values()
    )
    planted = copy.deepcopy(reference)
    key = sorted(planted["trials"])[0]
    planted["trials"][key]["sensed_sha256"] = "0" * 64
    assert compare(planted, reference) == [f"{key}: sensed_sha256 {'0' * 64!r}, the reference's "
                                           f"{reference['trials'][key]['sensed_sha256']!r}"]  # fmt: skip


def test_the_quick_grid_runs_and_a_reference_with_a_planted_change_fails_it_in_one_line_each(tmp_path):
    out = tmp_path / "grid"
    command = [sys.executable, str(ROOT / "scripts/experiment.py"), "regression", "--quick", "--out", str(out),
               "--workers", "1"]  # fmt: skip
    first = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert first.returncode == 0, first.stderr
    grid = json.loads((out / "regression.json").read_text())
    ((key, trial),) = grid["trials"].items()
    assert trial == fingerprint(json.loads(next((out / "trials").glob("*.json")).read_text())["record"])
    assert trial["solved"] and trial["sensed_sha256"]
    same = subprocess.run([*command, "--reference", str(out / "regression.json")], capture_output=True, text=True,
                          timeout=600)  # fmt: skip
    assert same.returncode == 0 and "identical" in same.stdout, same.stdout + same.stderr
    planted = copy.deepcopy(grid)
    planted["trials"][key]["actions"][0][1] = "failed" if trial["actions"][0][1] != "failed" else "moved"
    (tmp_path / "planted.json").write_text(json.dumps(planted))
    differs = subprocess.run([*command, "--reference", str(tmp_path / "planted.json")], capture_output=True,
                             text=True, timeout=600)  # fmt: skip
    assert differs.returncode == 1, differs.stderr
    assert f"- {key}: action 1 is " in differs.stdout and "1 difference(s)" in differs.stdout


def test_a_reference_that_is_not_a_grid_is_refused_in_one_line_before_any_work(tmp_path):
    (tmp_path / "ref.json").write_text('{"rows": []}')
    result = subprocess.run([sys.executable, str(ROOT / "scripts/experiment.py"), "regression", "--out",
                             str(tmp_path / "out"), "--reference", str(tmp_path / "ref.json")], capture_output=True,
                            text=True, timeout=120)  # fmt: skip
    assert result.returncode == 2 and "--reference:" in result.stderr and "no 'trials'" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()
