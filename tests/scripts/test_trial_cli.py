"""trial.py writes results.json in the contract's form and refuses what it cannot do, clearly."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run(*args):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=300)


def test_symbolic_oracle_trial_writes_contract_results(tmp_path):
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    files = sorted(specs.glob("*.json"))
    out = tmp_path / "out"
    result = run(
        ROOT / "scripts/trial.py",
        "--specs",
        *files,
        "--sim",
        "symbolic",
        "--runs",
        2,
        "--seed",
        7,
        "--max-actions",
        15,
        "--out",
        out,
        "--agent",
        "oracle",
    )
    assert result.returncode == 0, result.stderr
    results = json.loads((out / "results.json").read_text())
    assert results["success_rate"] == 1.0 and results["mean_actions"] == 5.0
    assert len(results["runs"]) == 6
    run0 = results["runs"][0]
    assert set(run0) >= {"spec", "seed", "solved", "num_actions", "wall_time_s", "actions"}
    assert run0["spec"] == "paper-test-0" and run0["seed"] == 7 and results["runs"][1]["seed"] == 8
    action = run0["actions"][0]  # the contract's keys, plus the sensed outcome and its reason
    assert {k: action[k] for k in ("component", "moved")} == {"component": "door-0", "moved": True}
    assert action["outcome"] == "moved" and action["reason"] == ""
    config = json.loads((out / "config.json").read_text())
    assert config["agent"] == "oracle" and "versions" in config


def test_trial_refuses_bad_requests_without_traceback(tmp_path):
    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    spec = specs / "paper-test-0.json"
    common = ["--specs", spec, "--runs", 1, "--seed", 0, "--max-actions", 5, "--out", tmp_path / "o"]
    bad_agent = run(ROOT / "scripts/trial.py", *common, "--sim", "symbolic", "--agent", "genius")
    assert bad_agent.returncode == 2 and "Available agents" in bad_agent.stderr
    video = run(ROOT / "scripts/trial.py", *common, "--sim", "symbolic", "--agent", "dual", "--video")
    assert video.returncode == 2 and "Traceback" not in video.stderr and "--sim twin" in video.stderr
    no_memory = run(ROOT / "scripts/trial.py", *common, "--sim", "twin", "--agent", "memory")
    assert no_memory.returncode == 2 and "Traceback" not in no_memory.stderr and "--memory" in no_memory.stderr
    broken = tmp_path / "broken.json"
    broken.write_text("{")
    bad_spec = run(ROOT / "scripts/trial.py", *common[:1], broken, *common[2:], "--sim", "symbolic", "--agent", "dual")
    assert bad_spec.returncode == 2 and "not valid JSON" in bad_spec.stderr


def test_train_then_memory_trial_beats_dual_on_unseen_boxes(tmp_path):
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "all", "--out", specs).returncode == 0
    memory = tmp_path / "memory.sqlite"
    trained = run(
        ROOT / "scripts/train.py",
        "--specs",
        *sorted(specs.glob("paper-train-*.json")),
        "--episodes",
        9,
        "--memory",
        memory,
    )
    assert trained.returncode == 0, trained.stderr
    assert json.loads((tmp_path / "memory.sqlite.train.json").read_text())["runs"][8]["spec"] == "paper-train-8"
    tests = sorted(specs.glob("paper-test-*.json"))
    means = {}
    for agent, extra in (("memory", ["--memory", memory]), ("dual", [])):
        out = tmp_path / agent
        result = run(
            ROOT / "scripts/trial.py",
            "--specs",
            *tests,
            "--sim",
            "symbolic",
            "--runs",
            3,
            "--seed",
            0,
            "--max-actions",
            30,
            "--out",
            out,
            "--agent",
            agent,
            *extra,
        )
        assert result.returncode == 0, result.stderr
        means[agent] = json.loads((out / "results.json").read_text())["mean_actions"]
    assert means["memory"] < means["dual"]


def test_memory_trial_refuses_a_missing_or_foreign_memory(tmp_path):
    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    common = [
        "--specs",
        specs / "paper-test-0.json",
        "--sim",
        "symbolic",
        "--runs",
        1,
        "--seed",
        0,
        "--max-actions",
        5,
        "--out",
        tmp_path / "o",
        "--agent",
        "memory",
    ]
    missing = run(ROOT / "scripts/trial.py", *common, "--memory", tmp_path / "none.sqlite")
    assert missing.returncode == 2 and "no memory file" in missing.stderr
    foreign = tmp_path / "foreign.sqlite"
    foreign.write_bytes(b"this is not a database at all" * 100)
    bad = run(ROOT / "scripts/trial.py", *common, "--memory", foreign)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr and "memory" in bad.stderr


def test_twin_trial_refuses_a_calibration_made_for_another_cell(tmp_path):
    import numpy as np

    from models.calibration import CameraCalibration, CellCalibration

    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    spec = specs / "paper-test-0.json"
    box_height = json.loads(spec.read_text())["box"]["size"][2]
    K = np.array([[600.0, 0, 319.5], [0, 600.0, 239.5], [0, 0, 1]])
    camera = CameraCalibration(K, np.zeros(5), (640, 480), T_base_camera=np.eye(4))
    common = ["--specs", spec, "--sim", "twin", "--agent", "dual", "--runs", 1, "--seed", 0, "--max-actions", 5]
    for cell, reality, what in (
        ({"profile": "realistic", "cell_seed": 0, "box_height": box_height}, "ideal", "profile 'realistic'"),
        ({"profile": "realistic", "cell_seed": 7, "box_height": box_height}, "realistic", "cell seed 7 instead of 0"),
        ({"profile": "ideal", "cell_seed": 0, "box_height": box_height + 0.05}, "ideal", "box height"),
    ):
        calibration = CellCalibration({"overview": camera}, cell=cell).save(tmp_path / "cal.json")
        out = tmp_path / "out"
        result = run(
            ROOT / "scripts/trial.py", *common, "--out", out, "--reality", reality, "--calibration", calibration
        )
        assert result.returncode == 2, result.stderr
        assert what in result.stderr and "scripts/calibrate.py --reality" in result.stderr
        assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
        assert not (out / "results.json").exists()
