"""The disassembly experiment on the task runner: a record per (agent, training seed) that a rerun reuses, the
summary's figures, the command line, and the records' hash kept from before the runner moved to the lab."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

from puzzlebox.lab.disassembly_run import run_disassembly, tasks_for
from puzzlebox.learning.experiments.disassembly import DisassemblyConfig

ROOT = Path(__file__).resolve().parents[2]
QUICK = DisassemblyConfig().quick()


def test_each_task_runs_the_learning_layers_job_function_so_old_records_keep_their_hash():
    # the settings hash names the task's function: moving it would make every finished record stale
    tasks = tasks_for(["memory", "dual", "dqn"], QUICK)
    assert [t.key for t in tasks] == ["memory-s0", "memory-k2-s0", "dual-s0", "dqn-s0"]
    names = {f"{t.function.__module__}:{t.function.__qualname__}" for t in tasks}
    module = "puzzlebox.learning.experiments.disassembly"
    assert names == {f"{module}:symbolic_task", f"{module}:deep_task"}


def test_a_memory_trained_on_one_computer_beats_no_memory_on_the_other_and_a_rerun_reuses_every_record(tmp_path):
    config = replace(QUICK, memory_max_lockers=(2,))
    first = run_disassembly(tmp_path, ["memory", "dual"], config, workers=1)
    assert first["tasks"] == {"computed": 2, "reused": 0}
    assert sorted(p.name for p in (tmp_path / "records").iterdir()) == ["dual-s0.json", "memory-k2-s0.json"]
    memory, dual = first["curves"]["memory-k2"][0], first["curves"]["dual"][0]
    assert memory["episodes"] == 1 and memory["success_rate"] > dual["success_rate"]
    assert memory["mean_actions"] < dual["mean_actions"] - 4
    assert first["optimum"]["per_test"]["lab-computer-b"] == 8
    again = run_disassembly(tmp_path, ["memory", "dual"], config, workers=1)
    assert again["tasks"] == {"computed": 0, "reused": 2}
    assert again["curves"] == first["curves"]


def test_the_command_writes_results_plot_and_the_paper_table(tmp_path):
    done = subprocess.run(
        [sys.executable, ROOT / "scripts/experiment.py", "disassembly", "--agents", "memory,dual", "--out", tmp_path,
         "--quick", "--workers", "1"],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "disassembly.json").read_text())
    assert set(summary["curves"]) == {"memory", "memory-k2", "dual"}
    assert (tmp_path / "disassembly.png").read_bytes().startswith(b"\x89PNG")
    table = (tmp_path / "disassembly.md").read_text()
    assert "| memory after 1 episode | 100 %, 20 actions |" in table
    assert json.loads((tmp_path / "disassembly.config.json").read_text())["disassembly"]["variants"] == 2
