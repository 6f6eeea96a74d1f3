"""The run store refuses what it cannot take up with typed errors (a script maps each to one line, exit 2)."""

from __future__ import annotations

import pytest

from puzzlebox.lab.errors import (
    OutputHoldsAnotherConfig,
    OutputHoldsResults,
    OutputNotADirectory,
    ResumeAndForce,
    RunStoreError,
)
from puzzlebox.lab.run_store import RunStore


def test_a_directory_holding_results_is_refused_resumed_or_emptied(tmp_path):
    out = tmp_path / "out"
    store = RunStore(out, {"command": "trial", "seed": 0})
    store.write_results({"runs": []})
    with pytest.raises(OutputHoldsResults, match="--resume"):
        RunStore(out, {"command": "trial", "seed": 0})
    with pytest.raises(OutputHoldsAnotherConfig, match="differs in seed"):
        RunStore(out, {"command": "trial", "seed": 1}, resume=True)
    RunStore(out, {"command": "trial", "seed": 0}, resume=True)  # the same configuration continues
    RunStore(out, {"command": "trial", "seed": 1}, force=True)
    assert not (out / "results.json").exists()


def test_a_file_in_the_way_and_contradictory_flags_are_refused(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputNotADirectory):
        RunStore(tmp_path / "file", {})
    with pytest.raises(ResumeAndForce):
        RunStore(tmp_path / "out", {}, resume=True, force=True)
    assert issubclass(OutputNotADirectory, RunStoreError) and issubclass(ResumeAndForce, RunStoreError)
