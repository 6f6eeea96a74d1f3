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
    assert run0["actions"][0] == {"component": "door-0", "moved": True}
    config = json.loads((out / "config.json").read_text())
    assert config["agent"] == "oracle" and "versions" in config


def test_trial_refuses_unknown_agent_and_unbuilt_sim_without_traceback(tmp_path):
    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    spec = specs / "paper-test-0.json"
    common = ["--specs", spec, "--runs", 1, "--seed", 0, "--max-actions", 5, "--out", tmp_path / "o"]
    bad_agent = run(ROOT / "scripts/trial.py", *common, "--sim", "symbolic", "--agent", "genius")
    assert bad_agent.returncode == 2 and "Available agents" in bad_agent.stderr
    twin = run(ROOT / "scripts/trial.py", *common, "--sim", "twin")
    assert twin.returncode == 2 and "Traceback" not in twin.stderr and "symbolic" in twin.stderr
    broken = tmp_path / "broken.json"
    broken.write_text("{")
    bad_spec = run(ROOT / "scripts/trial.py", *common[:1], broken, *common[2:], "--sim", "symbolic")
    assert bad_spec.returncode == 2 and "not valid JSON" in bad_spec.stderr
