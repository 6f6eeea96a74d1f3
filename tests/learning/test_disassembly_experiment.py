"""The disassembly experiment (issue 14 part 4): every agent on lab-computer-b and its variants, a record per
(agent, training seed) that a rerun reuses, the summary's figures, and the command line."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.experiments.disassembly import DATA_DIR, DisassemblyConfig, run_disassembly, scenes, tasks_for

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(not DATA_DIR.is_dir(), reason=f"{DATA_DIR} (the shared disassembly data) is absent")
QUICK = DisassemblyConfig().quick()


def test_the_tests_are_the_measured_computer_then_its_variants_the_same_for_every_agent():
    train, tests = scenes(QUICK)
    assert train.name == "lab-computer-a"
    assert [t.name for t in tests] == ["lab-computer-b", "lab-computer-b-v1000", "lab-computer-b-v1001"]
    settings = [task.settings["tests"] for task in tasks_for(["memory", "dual"], QUICK)]
    assert all(s == settings[0] for s in settings)


def test_a_memory_trained_on_one_computer_beats_no_memory_on_the_other_and_a_rerun_reuses_every_record(tmp_path):
    config = replace(QUICK, memory_max_lockers=(2,))
    first = run_disassembly(tmp_path, ["memory", "dual"], config, workers=1)
    assert first["tasks"] == {"computed": 2, "reused": 0}
    memory, dual = first["curves"]["memory-k2"][0], first["curves"]["dual"][0]
    assert memory["episodes"] == 1 and memory["success_rate"] > dual["success_rate"]
    assert memory["mean_actions"] < dual["mean_actions"] - 4
    assert first["optimum"]["per_test"]["lab-computer-b"] == 8
    again = run_disassembly(tmp_path, ["memory", "dual"], config, workers=1)
    assert again["tasks"] == {"computed": 0, "reused": 2}
    assert again["curves"] == first["curves"]


def test_missing_data_and_bad_schedules_are_config_errors(tmp_path):
    with pytest.raises(ConfigError, match="disassembly data is missing"):
        scenes(replace(QUICK, data_dir=str(tmp_path)))
    with pytest.raises(ConfigError, match="increasing"):
        DisassemblyConfig(memory_episodes=(3, 1))
    with pytest.raises(ConfigError, match="unknown disassembly agents"):
        tasks_for(["oracle"], QUICK)


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


def test_validation_tests_on_variants_of_the_training_computer_and_never_on_the_test_computer():
    train, tests = scenes(replace(QUICK, validation=True))
    assert [t.name for t in tests] == ["lab-computer-a-v5000", "lab-computer-a-v5001"]
    assert all(t.name.startswith(train.name) for t in tests)


def test_the_holding_rule_ablation_reaches_the_belief_agents_only_and_default_tasks_keep_their_settings():
    ablation = replace(QUICK, holding_rule=False)
    assert all("holding_rule" not in t.settings for t in tasks_for(["memory", "dual"], QUICK))
    assert all(t.settings["holding_rule"] is False for t in tasks_for(["memory", "dual"], ablation))
    assert all("holding_rule" not in t.settings for t in tasks_for(["dqn"], ablation))
