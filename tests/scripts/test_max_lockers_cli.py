"""trial.py --max-lockers and a sweep agent's max_lockers: run symbolic multi-locker boxes, refuse mistakes in
one line (exit 2)."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run(*args):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=300)


def test_a_dual_trial_over_sets_of_lockers_solves_two_locker_boxes(tmp_path):
    specs = tmp_path / "specs"
    made = run(ROOT / "scripts/generate.py", "random", "--components", 5, "--multi-locker", "--seed", 0,
               "--count", 2, "--workers", 1, "--out", specs)  # fmt: skip
    assert made.returncode == 0, made.stderr
    out = tmp_path / "out"
    common = ["--specs", *sorted(specs.glob("random-*.json")), "--sim", "symbolic", "--runs", 2, "--seed", 0]
    result = run(ROOT / "scripts/trial.py", *common, "--max-actions", 40, "--out", out, "--agent", "dual",
                 "--max-lockers", 2)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert json.loads((out / "results.json").read_text())["success_rate"] == 1.0
    assert json.loads((out / "config.json").read_text())["max_lockers"] == 2
    default = run(ROOT / "scripts/trial.py", *common, "--max-actions", 40, "--out", tmp_path / "k1", "--agent", "dual")
    assert default.returncode == 0, default.stderr
    assert "max_lockers" not in json.loads((tmp_path / "k1" / "config.json").read_text())  # as before k existed


def test_trial_refuses_a_bad_max_lockers_in_one_line(tmp_path):
    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    common = ["--specs", specs / "paper-test-0.json", "--runs", 1, "--seed", 0, "--max-actions", 5,
              "--out", tmp_path / "o"]  # fmt: skip
    for extra, message in (
        (["--sim", "symbolic", "--agent", "dual", "--max-lockers", 0], "max_lockers must be an integer in 1..3"),
        (["--sim", "symbolic", "--agent", "dual", "--max-lockers", 9], "max_lockers must be an integer in 1..3"),
        (["--sim", "symbolic", "--agent", "oracle", "--max-lockers", 2], "--max-lockers is for the agents"),
        (["--sim", "twin", "--agent", "oracle", "--max-lockers", 2], "--max-lockers is for the agents"),
    ):
        result = run(ROOT / "scripts/trial.py", *common, *extra)
        assert result.returncode == 2, result.stderr
        assert "Traceback" not in result.stderr and message in result.stderr
        assert len(result.stderr.strip().splitlines()) == 1


def test_a_sweep_refuses_a_bad_max_lockers(tmp_path):
    base = {"sim": "symbolic", "generate": {"generator": "random", "components": 4, "multi_locker": True, "count": 1},
            "max_actions": 10}  # fmt: skip
    for agents, message in (
        ([{"name": "dual", "max_lockers": 5}], "max_lockers must be an integer in 1..3"),
        ([{"name": "oracle", "max_lockers": 2}], "'max_lockers' is for the symbolic agents"),
        ([{"name": "dual", "max_locker": 2}], "unknown key(s) ['max_locker']"),
    ):
        sweep = tmp_path / "sweep.json"
        sweep.write_text(json.dumps({**base, "agents": agents}))
        result = run(ROOT / "scripts/sweep.py", sweep, "--out", tmp_path / "out", "--workers", 1)
        assert result.returncode == 2, result.stderr
        assert "Traceback" not in result.stderr and message in result.stderr


def test_train_with_sets_of_lockers_writes_a_memory_any_agent_recalls(tmp_path):
    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "random", "--components", 5, "--multi-locker", "--seed", 10, "--count", 2,
        "--workers", 1, "--out", specs)  # fmt: skip
    files = sorted(specs.glob("random-*.json"))
    memory = tmp_path / "memory.sqlite"
    trained = run(ROOT / "scripts/train.py", "--specs", *files, "--episodes", 2, "--memory", memory, "--max-lockers", 2)
    assert trained.returncode == 0, trained.stderr
    log = json.loads((tmp_path / "memory.sqlite.train.json").read_text())
    assert log["runs"][-1]["config"]["max_lockers"] == 2 and len(log["runs"][-1]["episodes"]) == 2
    for k in (1, 2):
        result = run(ROOT / "scripts/trial.py", "--specs", *files, "--memory", memory, "--sim", "symbolic", "--runs", 1,
                     "--seed", 0, "--max-actions", 40, "--out", tmp_path / f"k{k}", "--max-lockers", k)  # fmt: skip
        assert result.returncode == 0, result.stderr
    twin = run(ROOT / "scripts/train.py", "--specs", *files, "--episodes", 1, "--memory", memory, "--sim", "twin",
               "--max-lockers", 2)  # fmt: skip
    assert twin.returncode == 2 and "Traceback" not in twin.stderr and "--sim symbolic" in twin.stderr
