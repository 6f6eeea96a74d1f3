"""experiment.py --quick runs every symbolic protocol end to end and writes JSON, PNG and tables."""

import json
import sqlite3
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def experiment(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts/experiment.py"), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.mark.parametrize("protocol", ["variants", "episodes", "noise"])
def test_quick_protocol_writes_results_plot_and_paper_table(tmp_path, protocol):
    result = experiment(protocol, "--agents", "memory,dual,oracle", "--out", tmp_path, "--quick")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / f"{protocol}.json").read_text())
    assert (tmp_path / f"{protocol}.png").read_bytes().startswith(b"\x89PNG")
    assert "| figure | agent | ours | paper |" in (tmp_path / f"{protocol}.md").read_text()
    for point in data["points"]:
        assert point["oracle"]["success_rate"] == 1.0 and point["oracle"]["mean_actions"] == 5.0
        assert point["memory"]["mean_actions"] >= 5.0  # no agent beats the optimum


def test_memory_after_nine_variants_beats_no_memory_in_the_variants_protocol(tmp_path):
    assert experiment("variants", "--agents", "memory", "--out", tmp_path, "--quick").returncode == 0
    points = {
        p["training_variants"]: p["memory"] for p in json.loads((tmp_path / "variants.json").read_text())["points"]
    }
    assert points[9]["mean_actions"] < points[0]["mean_actions"]


def test_unknown_agents_are_clear_errors(tmp_path):
    bad = experiment("variants", "--agents", "memory,genius", "--out", tmp_path, "--quick")
    assert bad.returncode == 2 and "genius" in bad.stderr and "Traceback" not in bad.stderr
    oracle = experiment("disassembly", "--agents", "memory,oracle", "--out", tmp_path, "--quick")
    assert oracle.returncode == 2 and "oracle" in oracle.stderr and "Traceback" not in oracle.stderr
    assert "available: ['memory', 'dual', 'dqn', 'model-based']" in oracle.stderr


def test_quick_all_runs_every_deep_agent_and_resumes_from_its_saved_jobs(tmp_path):
    agents = "memory,dqn,model-based,mt-dqn,mt-model-based"
    first = experiment("all", "--agents", agents, "--out", tmp_path, "--quick")
    assert first.returncode == 0, first.stderr
    assert "6 job(s) run, 0 reused" in first.stdout
    results = {p: json.loads((tmp_path / f"{p}.json").read_text()) for p in ("variants", "episodes", "noise")}
    for deep in agents.split(",")[1:]:
        assert [p["training_episodes"] for p in results["episodes"]["points"] if deep in p] == [0, 5, 10]
        assert len([p for p in results["noise"]["points"] if deep in p]) == 5
    assert {p["training_variants"] for p in results["variants"]["points"] if "dqn" in p} == {0, 1, 9}
    assert "Episodes to 100%" in (tmp_path / "all.md").read_text()
    assert (tmp_path / "episodes.png").read_bytes().startswith(b"\x89PNG")

    # an interrupted run: one job's file is missing; the rerun computes only that job, identically
    (tmp_path / "jobs" / "mt-dqn-v9-s0.json").unlink()
    again = experiment("all", "--agents", agents, "--out", tmp_path, "--quick")
    assert again.returncode == 0, again.stderr
    assert "1 job(s) run, 5 reused" in again.stdout
    rerun = json.loads((tmp_path / "episodes.json").read_text())
    assert rerun["points"] == results["episodes"]["points"]

    # every job's network is a checkpoint trial.py can run
    specs = tmp_path / "specs"
    generate = [sys.executable, str(ROOT / "scripts/generate.py"), "paper", "--split", "test", "--out", str(specs)]
    assert subprocess.run(generate, capture_output=True, timeout=120).returncode == 0
    trial = subprocess.run(
        [sys.executable, str(ROOT / "scripts/trial.py"), "--specs", str(specs / "paper-test-0.json"),
         "--agent", "mt-dqn", "--checkpoint", str(tmp_path / "jobs/mt-dqn-v9-s0.pt"), "--runs", "1",
         "--sim", "symbolic", "--seed", "0", "--max-actions", "30",
         "--out", str(tmp_path / "trial")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert trial.returncode == 0, trial.stderr
    assert json.loads((tmp_path / "trial/results.json").read_text())["runs"][0]["num_actions"] >= 5


def test_quick_reality_sweep_calibrates_each_cell_runs_placed_boxes_and_resumes(tmp_path):
    result = experiment("reality", "--out", tmp_path, "--quick")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "reality.json").read_text())
    assert {(p["series"], p["level"]) for p in data["points"]} == {("force-torque", 0.0), ("force-torque", 1.0)}
    for point in data["points"]:
        assert point["trials"] == 3 and point["success_rate"] in (0.0, 1 / 3, 2 / 3, 1.0)
        assert point["calibration_reprojection_px"] < 0.5
        assert len(point["unsolved_reasons"]) == round(3 * (1 - point["success_rate"]))
    assert (tmp_path / "reality.png").read_bytes().startswith(b"\x89PNG")
    assert "| force-torque | 1 | 3 |" in (tmp_path / "reality.md").read_text()
    trials = sorted((tmp_path / "trials").glob("*.json"))
    assert len(trials) == 6 and len(list((tmp_path / "calibrations").glob("*.json"))) == 2
    records = [json.loads(t.read_text())["record"] for t in trials]
    poses = {(r["spec"], r["seed"], tuple(r["box_pose"])) for r in records}
    assert len(poses) == 3  # each level meets the same placements (common random numbers)...
    assert all(0.30 <= x <= 0.60 and abs(y) <= 0.30 for _, _, (x, y, _) in poses)  # ... drawn in the workspace
    stamps = [t.stat().st_mtime_ns for t in trials]
    again = experiment("reality", "--out", tmp_path, "--quick")  # resumes: every trial reused
    assert again.returncode == 0, again.stderr
    assert [t.stat().st_mtime_ns for t in trials] == stamps
    assert json.loads((tmp_path / "reality.json").read_text())["points"] == data["points"]


def test_reality_sweep_command_line_mistakes_are_one_line(tmp_path):
    for args, words in (
        (("--agents", "dqn"), "memory agent only"),
        (("--memory", tmp_path / "none.sqlite"), "no such file"),
        (("--runs", "0"), "--runs"),
        (("--seeds", "2"), "symbolic protocols"),
    ):
        bad = experiment("reality", "--out", tmp_path / "out", *args)
        assert bad.returncode == 2 and words in bad.stderr and "Traceback" not in bad.stderr, bad.stderr
    symbolic = experiment("variants", "--out", tmp_path / "out")
    assert symbolic.returncode == 2 and "needs --agents" in symbolic.stderr


def test_quick_twin_learning_trains_each_start_in_the_twin_measures_its_checkpoints_and_resumes(tmp_path):
    result = experiment("twin-learning", "--out", tmp_path, "--quick", "--workers", 1)
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / "twin-learning.json").read_text())
    points = {(p["start"], p["hours"]): p for p in data["points"]}
    assert set(points) == {("empty", 0.0), ("empty", 0.02), ("symbolic", 0.0), ("symbolic+twin", 0.0),
                           ("symbolic+twin", 0.02), ("dqn", 0.0)}  # fmt: skip
    assert all(p["seeds"][0]["trials"] == 1 and p["success_rate"] in (0.0, 1.0) for p in points.values())
    # the deep agent ran the same test trial from the network it trained in the symbolic simulator
    # the symbolic and symbolic+twin memories at 0 h hold the same: their trial is run once and stands for both
    assert data["same_trial_as"] == {"symbolic+twin-s0@0h-paper-test-0-p0": "symbolic-s0@0h-paper-test-0-p0"}
    assert not (tmp_path / "trials" / "symbolic+twin-s0@0h-paper-test-0-p0.json").exists()
    dqn_trial = json.loads((tmp_path / "trials" / "dqn-v9-s0-paper-test-0-p0.json").read_text())["record"]
    assert dqn_trial["spec"] == "paper-test-0" and dqn_trial["actions"], dqn_trial
    assert (tmp_path / "deep" / "jobs" / "dqn-v9-s0.pt").stat().st_size > 0
    assert points[("dqn", 0.0)]["seeds"][0]["symbolic_success_rate"] is not None
    chains = {c["start"]: c for c in (json.loads(f.read_text())["record"] for f in (tmp_path / "chains").glob("*"))}
    for start in ("empty", "symbolic+twin"):  # each checkpoint was taken once its robot time was reached
        assert all(c["robot_hours"] >= c["hours"] for c in chains[start]["checkpoints"])
        assert chains[start]["checkpoints"][-1]["twin_episodes"] >= 1
    assert chains["empty"]["checkpoints"][0] == {"hours": 0.0, "robot_hours": 0.0, "memory": "empty-s0@0h.sqlite",
                                                 "twin_episodes": 0, "episodes": 0}  # fmt: skip
    assert (
        chains["symbolic"]["checkpoints"][0]["episodes"] == 9 == chains["symbolic+twin"]["checkpoints"][0]["episodes"]
    )
    memories = tmp_path / "memories"  # the symbolic start and the symbolic part of symbolic+twin are one memory
    symbolic, both = (sqlite3.connect(memories / f"{s}-s0@0h.sqlite") for s in ("symbolic", "symbolic+twin"))
    query = "SELECT kind_i, kind_j, key, value FROM pair_entries ORDER BY rowid"
    assert symbolic.execute(query).fetchall() == both.execute(query).fetchall()
    for start in ("empty", "symbolic+twin"):  # every training episode is solved or says why it ended
        t = data["training"][start]
        assert t["episodes"] >= 1 and t["solved"] + sum(t["ended"].values()) == t["episodes"]
    assert (tmp_path / "twin-learning.png").read_bytes().startswith(b"\x89PNG")
    assert "| empty | 0 |" in (tmp_path / "twin-learning.md").read_text()
    trials = sorted((tmp_path / "trials").glob("*.json"))
    stamps = [t.stat().st_mtime_ns for t in trials]
    again = experiment("twin-learning", "--out", tmp_path, "--quick", "--workers", 1)  # resumes: all reused
    assert again.returncode == 0, again.stderr
    assert [t.stat().st_mtime_ns for t in trials] == stamps
    for args, words in (
        (("--agents", "dqn"), "memory and any of"),
        (("--agents", "memory,ppo"), "memory and any of"),
        (("--runs", "0"), "--runs"),
        (("--seeds", "0"), "--seeds"),
    ):
        bad = experiment("twin-learning", "--out", tmp_path / "bad", *args)
        assert bad.returncode == 2 and words in bad.stderr and "Traceback" not in bad.stderr, bad.stderr


def test_the_hard_test_set_goes_with_twin_learning_and_its_memory_agent_only(tmp_path):
    for args, words in (
        (("variants", "--agents", "memory", "--test-set", "hard"), "--test-set goes with the twin-learning protocol"),
        (("twin-learning", "--test-set", "hard", "--agents", "memory,dqn"), "runs the memory agent only"),
    ):
        bad = experiment(*args, "--out", tmp_path / "out")
        assert bad.returncode == 2 and words in bad.stderr and "Traceback" not in bad.stderr, bad.stderr
    assert not (tmp_path / "out").exists()  # refused before any work


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--runs", "3"), "takes only --out, --workers, --cells and --quick"),
        (("--agents", "memory"), "takes only --out, --workers, --cells and --quick"),
        (("--workers", "0"), "--workers must be >= 1"),
        (("--cells", "3,x"), "--cells takes comma-separated integers"),
        (("--cells", "3,3"), "--cells takes distinct cell seeds >= 0"),
    ],
)
def test_sysid_command_line_mistakes_are_one_line_and_exit_2(tmp_path, args, message):
    result = experiment("sysid", "--out", tmp_path / "out", *args)
    assert result.returncode == 2 and message in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr


def test_cells_go_with_the_sysid_protocol_only(tmp_path):
    result = experiment("kinds", "--out", tmp_path / "out", "--cells", "3")
    assert result.returncode == 2 and "--cells goes with the sysid protocol" in result.stderr, result.stderr


@pytest.mark.parametrize("flag", ["--validation", "--no-holding-rule"])
def test_the_disassembly_flags_go_with_the_disassembly_protocol_only(tmp_path, flag):
    result = experiment("variants", "--out", tmp_path / "out", flag)
    assert result.returncode == 2 and "go with the disassembly protocol" in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_sysid_refuses_an_output_that_is_a_file(tmp_path):
    (tmp_path / "taken").write_text("")
    result = experiment("sysid", "--out", tmp_path / "taken", "--quick")
    assert result.returncode == 2 and "is a file" in result.stderr and len(result.stderr.strip().splitlines()) == 1
