"""sweep.py runs a grid of trials on the runner, aggregates it per cell, survives a kill -9, and refuses a
malformed sweep in one line."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

from puzzlebox.lab.trial_task import without_timing  # noqa: E402


def sweep(*args, timeout=600):
    return subprocess.run([sys.executable, str(ROOT / "scripts/sweep.py"), *map(str, args)], capture_output=True,
                          text=True, timeout=timeout)  # fmt: skip


RECIPE = {"generator": "random", "components": 6, "multi_locker": True, "seed": 0, "count": 2}
SYMBOLIC = {"sim": "symbolic", "generate": RECIPE, "seeds": {"start": 5, "count": 4}, "agents": ["oracle", "dual"],
            "max_actions": 40}  # fmt: skip


def test_a_symbolic_sweep_aggregates_every_cell(tmp_path):
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps(SYMBOLIC))
    result = sweep(path, "--out", tmp_path / "out", "--workers", 1)
    assert result.returncode == 0, result.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["runs_done"] == results["runs_planned"] == len(results["runs"]) == 2 * 2 * 4
    cells = results["cells"]
    assert [(c["spec"], c["agent"]) for c in cells] == [
        ("random-n6-multi-s0", "oracle"), ("random-n6-multi-s0", "dual"),
        ("random-n6-multi-s1", "oracle"), ("random-n6-multi-s1", "dual"),
    ]  # fmt: skip
    for cell in cells:
        assert cell["runs_done"] == 4
        if cell["agent"] == "oracle":
            assert cell["success_rate"] == 1.0 and cell["mean_actions"] <= 6, "the oracle takes the shortest path"
    mean = sum(c["mean_actions"] for c in cells) / len(cells)
    assert abs(mean - results["mean_actions"]) < 1e-9, "equal cells: the overall mean is the mean of the cells"
    assert (tmp_path / "out" / "cells.md").read_text().count("\n| random-n6") == 4
    assert (tmp_path / "out" / "cells.png").read_bytes().startswith(b"\x89PNG")


def test_a_sweep_killed_half_way_and_rerun_records_every_task_once_with_the_same_results(tmp_path):
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps({**SYMBOLIC, "seeds": {"start": 0, "count": 150}}))  # 600 tasks
    assert sweep(path, "--out", tmp_path / "whole", "--workers", 1).returncode == 0
    out = tmp_path / "killed"
    command = [sys.executable, ROOT / "scripts/sweep.py", path, "--out", out, "--workers", 2]
    proc = subprocess.Popen(list(map(str, command)), stderr=subprocess.DEVNULL, stdout=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None:
        if (out / "runs").is_dir() and len(list((out / "runs").glob("*.json"))) >= 300:
            break
        time.sleep(0.02)
    assert proc.poll() is None, "the sweep ended before half way"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    kept = len(list((out / "runs").glob("*.json")))
    assert 300 <= kept < 600
    again = sweep(path, "--out", out, "--resume", "--workers", 2)
    assert again.returncode == 0, again.stderr
    assert f"({kept} reused)" in again.stdout, "only the missing tasks were computed"
    got, want = (json.loads((d / "results.json").read_text()) for d in (out, tmp_path / "whole"))
    assert len(list((out / "runs").glob("*.json"))) == 600 and len(got["runs"]) == 600
    assert without_timing(got) == without_timing(want)


def test_a_twin_sweep_places_the_box_at_each_drawn_pose(tmp_path):
    specs = tmp_path / "specs"
    subprocess.run([sys.executable, str(ROOT / "scripts/generate.py"), "paper", "--split", "test", "--out", specs],
                   check=True, capture_output=True)  # fmt: skip
    path = tmp_path / "sweep.json"
    path.write_text(json.dumps({"sim": "twin", "specs": ["specs/paper-test-0.json"], "placements": 2,
                                "placement_seed": 3, "seeds": [0], "agents": ["oracle"], "profiles": ["ideal"],
                                "max_actions": 6}))  # fmt: skip
    result = sweep(path, "--out", tmp_path / "out")
    assert result.returncode == 0, result.stderr
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    poses = [tuple(c["box_pose"]) for c in results["cells"]]
    assert len(set(poses)) == 2 and [tuple(r["box_pose"]) for r in results["runs"]] == poses
    assert results["success_rate"] == 1.0, "the oracle solves the ideal twin wherever the box stands"


def test_sweep_mistakes_are_one_line(tmp_path):
    good = {**SYMBOLIC}
    cases = [
        ({**good, "colour": 1}, "unknown key"),
        ({**good, "sim": "mujoco"}, "'sim' must be"),
        ({**good, "specs": ["*.json"]}, "give 'specs' (globs) or 'generate'"),
        ({**good, "placements": 2}, "need 'sim': 'twin'"),
        ({**good, "agents": ["nobody"]}, "unknown agent"),
        ({**good, "agents": ["memory"]}, "needs a 'memory' file"),
        ({**good, "max_actions": 0}, "'max_actions' must be"),
        ({**good, "seeds": [-1]}, "'seeds' must be"),
        ({key: v for key, v in good.items() if key != "generate"} | {"specs": ["none-*.json"]}, "match no file"),
    ]
    for k, (content, message) in enumerate(cases):
        path = tmp_path / f"s{k}.json"
        path.write_text(json.dumps(content))
        result = sweep(path, "--out", tmp_path / f"out{k}")
        assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr, (
            content, result.stderr)  # fmt: skip
        assert len(result.stderr.strip().splitlines()) == 1 and not (tmp_path / f"out{k}").exists()
    (tmp_path / "bad.json").write_text("{")
    assert "cannot read sweep" in sweep(tmp_path / "bad.json", "--out", tmp_path / "o").stderr
