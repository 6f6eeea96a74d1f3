"""The training log lives in the memory file: it matches the memory, survives concurrent trainers and
accumulates; schema 1 files are upgraded; stored values outside [0, 1] or a bad scale are refused."""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from legacy_memory import make_legacy

from puzzlebox.learning.errors import MemoryFileError
from puzzlebox.learning.memory import SCHEMA_VERSION, MemoryStore, se3_pose_keys

ROOT = Path(__file__).resolve().parents[2]


def _episode(store: MemoryStore, **log) -> None:
    n = 2
    keys = se3_pose_keys(np.array([[0.0, 0.0, 0.0], [0.05, 0.02, 1.0]]), 0.02)
    pair_values = np.full((n, n, 6), 0.5)
    store.add_episode(("door", "slide"), keys, pair_values, np.full((n, 2), 0.5), **log)


def test_the_log_holds_every_run_and_episode_in_order(tmp_path):
    path = tmp_path / "m.sqlite"
    store = MemoryStore(path)
    first = store.begin_training_run({"episodes": 2})
    _episode(store, spec="a", seed=0, solved=True, num_actions=5, training_run=first)
    _episode(store, spec="b", seed=1, solved=False, num_actions=9, training_run=first)
    store.close()
    store = MemoryStore(path)  # a later run on the same file accumulates
    second = store.begin_training_run({"episodes": 1})
    _episode(store, spec="c", seed=7, solved=True, num_actions=4, training_run=second)
    log = store.training_log()
    assert [r["id"] for r in log] == [first, second] and log[1]["config"] == {"episodes": 1}
    assert [(e["spec"], e["seed"], e["solved"], e["num_actions"]) for r in log for e in r["episodes"]] == [
        ("a", 0, True, 5), ("b", 1, False, 9), ("c", 7, True, 4)
    ]  # fmt: skip
    assert store.num_episodes == 3 == sum(len(r["episodes"]) for r in log)


def test_a_schema_1_file_is_read_as_it_is_and_upgraded_when_trained(tmp_path):
    path = tmp_path / "old.sqlite"
    store = MemoryStore(path)
    _episode(store, spec="old", num_actions=3)
    store.close()
    make_legacy(path, 1)  # the schema 1 file an earlier version wrote
    store = MemoryStore.open_existing(path)
    assert [[e["spec"] for e in r["episodes"]] for r in store.training_log()] == [["old"]]
    run = store.begin_training_run({"episodes": 1})
    _episode(store, spec="new", seed=2, training_run=run)
    log = store.training_log()
    assert [(r["id"], [e["spec"] for e in r["episodes"]]) for r in log] == [(None, ["old"]), (run, ["new"])]
    meta = dict(sqlite3.connect(path).execute("SELECT key, value FROM meta").fetchall())
    assert meta["schema_version"] == str(SCHEMA_VERSION) == "4"
    assert store.provenance()["symbolic"] == {"episodes": 2}  # what a schema 1 file held was symbolic


def test_a_schema_2_file_counts_its_episodes_symbolic_and_takes_twin_episodes_with_their_provenance(tmp_path):
    path = tmp_path / "two.sqlite"
    store = MemoryStore(path)
    _episode(store, spec="old", num_actions=3)
    store.close()
    make_legacy(path, 2)  # the schema 2 file an earlier version wrote
    store = MemoryStore.open_existing(path)
    assert store.provenance()["symbolic"] == {"episodes": 1} and store.provenance()["twin"]["episodes"] == 0
    _episode(store, spec="a", source="twin", profile="realistic", robot_time=1800.0)
    _episode(store, spec="b", source="twin", profile="harsh", robot_time=900.0)
    _episode(store, spec="c")
    store.close()
    provenance = MemoryStore.open_existing(path).provenance()  # read back from the file
    assert provenance == {
        "episodes": 4,
        "symbolic": {"episodes": 2},
        "twin": {"episodes": 2, "robot_hours": 0.75, "profiles": {"realistic": 1, "harsh": 1}},
    }
    with pytest.raises(ValueError, match="unknown episode source 'robot'"):
        _episode(MemoryStore(), source="robot")


@pytest.mark.parametrize("trainers", [2, 4])
def test_concurrent_trainers_on_one_memory_all_land_in_the_memory_and_its_log(tmp_path, trainers):
    specs = tmp_path / "specs"
    subprocess.run([sys.executable, ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs],
                   check=True, capture_output=True)  # fmt: skip
    memory = tmp_path / "shared.sqlite"
    episodes = 4
    procs = [
        subprocess.Popen(
            [
                sys.executable,
                ROOT / "scripts/train.py",
                "--specs",
                *sorted(specs.glob("*.json")),
                "--episodes",
                str(episodes),
                "--memory",
                memory,
                "--seed",
                str(100 * k),
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )  # fmt: skip
        for k in range(trainers)
    ]
    for proc in procs:
        _, err = proc.communicate(timeout=300)
        assert proc.returncode == 0, err
    store = MemoryStore.open_existing(memory)
    log = store.training_log()
    assert store.num_episodes == trainers * episodes
    assert sorted(len(r["episodes"]) for r in log) == [episodes] * trainers
    seeds = sorted(e["seed"] for r in log for e in r["episodes"])
    assert seeds == sorted(100 * k + e for k in range(trainers) for e in range(episodes))
    exported = json.loads(Path(str(memory) + ".train.json").read_text())
    assert len(exported["runs"]) >= 1 and not list(tmp_path.glob("*.tmp")) and not list(tmp_path.glob(".*.tmp"))


def _tamper(path: Path, sql: str, *params) -> None:
    conn = sqlite3.connect(path)
    with conn:
        conn.execute(sql, params)
    conn.close()


def test_stored_values_outside_zero_one_or_a_non_finite_scale_are_refused(tmp_path):
    path = tmp_path / "m.sqlite"
    store = MemoryStore(path)
    _episode(store)
    store.close()
    for table in ("pair_entries", "independence_entries"):
        bad = tmp_path / f"{table}.sqlite"
        bad.write_bytes(path.read_bytes())
        size = 6 if table == "pair_entries" else 2
        _tamper(bad, f"UPDATE {table} SET value = ?", np.array([-0.2] + [0.5] * (size - 1)).tobytes())
        with pytest.raises(MemoryFileError, match=r"outside \[0, 1\]"):
            MemoryStore.open_existing(bad)
    for scale in ("inf", "nan", "-0.02"):
        bad = tmp_path / f"scale-{scale}.sqlite"
        bad.write_bytes(path.read_bytes())
        _tamper(bad, "UPDATE meta SET value = ? WHERE key = 'position_scale'", scale)
        with pytest.raises(MemoryFileError, match="position_scale"):
            MemoryStore.open_existing(bad)


def test_training_a_read_only_memory_is_one_line_before_any_work(tmp_path):
    specs = tmp_path / "specs"
    subprocess.run([sys.executable, ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs],
                   check=True, capture_output=True)  # fmt: skip
    memory = tmp_path / "m.sqlite"
    store = MemoryStore(memory)
    _episode(store)
    store.close()
    memory.chmod(0o444)
    immutable = False
    if os.geteuid() == 0:  # root writes read-only files: make it immutable instead, where the file system can
        chattr = shutil.which("chattr")
        immutable = chattr is not None and subprocess.run([chattr, "+i", memory], capture_output=True).returncode == 0
        if not immutable:
            pytest.skip("running as root on a file system without chattr: a read-only file is writable")
    try:
        result = subprocess.run(
            [sys.executable, ROOT / "scripts/train.py", "--specs", *sorted(specs.glob("*.json")), "--episodes", "1",
             "--memory", memory],
            capture_output=True, text=True,
        )  # fmt: skip
    finally:
        if immutable:
            subprocess.run([chattr, "-i", memory], check=True)
    assert result.returncode == 2 and "read-only" in result.stderr and "Traceback" not in result.stderr
    assert MemoryStore.open_existing(memory).num_episodes == 1
