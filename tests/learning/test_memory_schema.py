"""A memory file is refused unless its schema is exactly the project's: a trigger (which ``PRAGMA integrity_check``
passes and which would run its own SQL on every write), a view, an unknown table, index or column. train.py and
trial.py refuse such a file in one line, exit 2, and run nothing on it; a trigger added while a trainer holds the
file open is caught inside the next write transaction."""

from __future__ import annotations

import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from puzzlebox.learning.errors import MemoryFileError
from puzzlebox.learning.memory import MemoryStore, se3_pose_keys

ROOT = Path(__file__).resolve().parents[2]

CRAFTED = {
    "trigger": "CREATE TRIGGER wipe AFTER INSERT ON episodes BEGIN DELETE FROM pair_entries; END",
    "view": "CREATE VIEW everything AS SELECT * FROM pair_entries",
    "table": "CREATE TABLE notes (text TEXT)",
    "index": "CREATE INDEX by_kind ON pair_entries (kind_i)",
    "column": "ALTER TABLE episodes ADD COLUMN extra TEXT",
}


def _episode(store: MemoryStore) -> None:
    keys = se3_pose_keys(np.array([[0.0, 0.0, 0.0], [0.05, 0.02, 1.0]]), 0.02)
    store.add_episode(("door", "slide"), keys, np.full((2, 2, 6), 0.5), np.full((2, 2), 0.5), spec="s", seed=0)


@pytest.fixture(scope="module")
def memory(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("schema") / "memory.sqlite"
    store = MemoryStore(path)
    for _ in range(3):
        _episode(store)
    store.close()
    return path


def _crafted(memory: Path, tmp_path: Path, what: str) -> Path:
    path = tmp_path / f"{what}.sqlite"
    shutil.copy(memory, path)
    with sqlite3.connect(path) as conn:
        conn.execute(CRAFTED[what])
    conn.close()
    return path


@pytest.mark.parametrize("what", sorted(CRAFTED))
def test_a_memory_with_anything_but_the_projects_schema_is_refused(memory, tmp_path, what):
    path = _crafted(memory, tmp_path, what)
    with sqlite3.connect(path) as conn:
        assert conn.execute("PRAGMA integrity_check").fetchone()[0] == "ok", "SQLite itself finds nothing wrong"
    conn.close()
    with pytest.raises(MemoryFileError, match="never does|has columns"):
        MemoryStore.open_existing(path)
    with pytest.raises(MemoryFileError):
        MemoryStore(path)  # a trainer opens it the same way


def test_train_and_trial_refuse_a_trigger_carrying_memory_in_one_line_and_run_nothing(memory, tmp_path):
    from puzzlebox.models.generator import paper_family

    path = _crafted(memory, tmp_path, "trigger")
    before = path.read_bytes()
    spec = tmp_path / "spec.json"
    spec.write_text(paper_family("train")[0].to_json())
    commands = {
        "train": [ROOT / "scripts/train.py", "--specs", spec, "--episodes", 2, "--memory", path],
        "trial": [ROOT / "scripts/trial.py", "--specs", spec, "--sim", "symbolic", "--runs", 1, "--seed", 0,
                  "--max-actions", 20, "--memory", path, "--out", tmp_path / "out"],
    }  # fmt: skip
    for name, command in commands.items():
        result = subprocess.run([sys.executable, *map(str, command)], capture_output=True, text=True, timeout=600)
        assert result.returncode == 2, (name, result.stderr)
        assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr
        assert "trigger 'wipe'" in result.stderr and "refused" in result.stderr, result.stderr
    assert path.read_bytes() == before, "nothing ran on the file: it is byte for byte as it was"
    assert not (tmp_path / "out").exists()


def test_a_trigger_added_while_a_trainer_holds_the_file_is_caught_in_the_next_write(memory, tmp_path):
    path = tmp_path / "live.sqlite"
    shutil.copy(memory, path)
    store = MemoryStore(path)  # opened and checked while still clean
    with sqlite3.connect(path) as other:
        other.execute(CRAFTED["trigger"])
    other.close()
    with pytest.raises(MemoryFileError, match="trigger 'wipe'"):
        _episode(store)
    store.close()
    with sqlite3.connect(path) as conn:  # the write was rolled back: the trigger never fired
        episodes, pairs = (conn.execute(f"SELECT COUNT(*) FROM {t}").fetchone()[0]
                           for t in ("episodes", "pair_entries"))  # fmt: skip
    conn.close()
    assert episodes == 3 and pairs == 3 * 2
