"""The disassembly experiment (issue 14 part 4): every agent on lab-computer-b and its variants, one job per
(agent, training seed) with the settings it reads. Run on the task runner, and the command line:
``tests/lab/test_disassembly_run.py``."""

from __future__ import annotations

from dataclasses import replace

import pytest

from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.experiments.disassembly import DisassemblyConfig, jobs_for, scenes

QUICK = DisassemblyConfig().quick()


def test_the_tests_are_the_measured_computer_then_its_variants_the_same_for_every_agent():
    train, tests = scenes(QUICK)
    assert train.name == "lab-computer-a"
    assert [t.name for t in tests] == ["lab-computer-b", "lab-computer-b-v1000", "lab-computer-b-v1001"]
    settings = [job.settings["tests"] for job in jobs_for(["memory", "dual"], QUICK)]
    assert all(s == settings[0] for s in settings)


def test_missing_data_and_bad_schedules_are_config_errors(tmp_path):
    with pytest.raises(ConfigError, match="disassembly data is missing"):
        scenes(replace(QUICK, data_dir=str(tmp_path)))
    with pytest.raises(ConfigError, match="increasing"):
        DisassemblyConfig(memory_episodes=(3, 1))
    with pytest.raises(ConfigError, match="unknown disassembly agents"):
        jobs_for(["oracle"], QUICK)


def test_validation_tests_on_variants_of_the_training_computer_and_never_on_the_test_computer():
    train, tests = scenes(replace(QUICK, validation=True))
    assert [t.name for t in tests] == ["lab-computer-a-v5000", "lab-computer-a-v5001"]
    assert all(t.name.startswith(train.name) for t in tests)


def test_the_holding_rule_ablation_reaches_the_belief_agents_only_and_default_tasks_keep_their_settings():
    ablation = replace(QUICK, holding_rule=False)
    assert all("holding_rule" not in j.settings for j in jobs_for(["memory", "dual"], QUICK))
    assert all(j.settings["holding_rule"] is False for j in jobs_for(["memory", "dual"], ablation))
    assert all("holding_rule" not in j.settings for j in jobs_for(["dqn"], ablation))


def test_the_measured_computers_ship_with_the_package():
    # (they were read from a folder beside the repository: a pip install could not run the experiment)
    import fnmatch
    import tomllib
    from pathlib import Path

    from puzzlebox.learning.experiments.disassembly import DATA_DIR

    root = Path(__file__).resolve().parents[2]
    patterns = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    shipped = patterns["puzzlebox.learning"]
    files = sorted(p.relative_to(DATA_DIR.parents[1]).as_posix() for p in DATA_DIR.iterdir())
    assert {"data/disassembly/lab-computer-a.json", "data/disassembly/lab-computer-b.json"} <= set(files)
    assert all(any(fnmatch.fnmatch(f, p) for p in shipped) for f in files), (files, shipped)
