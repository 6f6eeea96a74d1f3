"""Where a run's task records live: ``DIR/KEY.json``, one file per finished task, each written atomically
(a kill leaves it whole or absent) with the hash of the task's settings beside the record."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from puzzlebox.lab.runner.task import Task
from puzzlebox.models.atomic import write_text_atomically


class RecordStore:
    """The records of one run's tasks in ``directory`` (created on the first record)."""

    def __init__(self, directory: str | Path) -> None:
        self.directory = Path(directory)

    def path(self, key: str) -> Path:
        return self.directory / f"{key}.json"

    def get(self, task: Task) -> dict[str, Any] | None:
        """The record of ``task`` if it finished earlier with the same settings, else None."""
        try:
            stored = json.loads(self.path(task.key).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError):
            return None  # absent (a torn file cannot happen with atomic writes: recompute rather than trust)
        if not isinstance(stored, dict) or stored.get("settings_sha256") != task.settings_hash:
            return None
        return stored.get("record")

    def put(self, task: Task, record: dict[str, Any]) -> Path:
        """Keep the record of a finished task."""
        text = json.dumps({"key": task.key, "settings_sha256": task.settings_hash, "record": record}, indent=1)
        return write_text_atomically(self.path(task.key), text)

    def keys(self) -> list[str]:
        """Keys of every stored record (whatever its settings)."""
        return sorted(p.stem for p in self.directory.glob("*.json")) if self.directory.is_dir() else []

    def remove_stale(self) -> int:
        """Remove the hidden temporaries a killed writer left; returns how many."""
        stale = list(self.directory.glob(".*.tmp")) if self.directory.is_dir() else []
        for path in stale:
            path.unlink(missing_ok=True)
        return len(stale)
