"""Turn a memory file written today into the file an earlier version wrote (schema 1, 2 or 3): the tables of
that schema and its compact planar keys (x, y, sin, cos) in place of the SE(3) keys."""

from __future__ import annotations

import math
import sqlite3
from pathlib import Path

import numpy as np


def compact_planar_key(se3_key: np.ndarray) -> np.ndarray:
    """The (x, y, sin yaw, cos yaw) key of a planar SE(3) key (rotation weight 1)."""
    rotation = se3_key[3:].reshape(3, 3) * math.sqrt(2.0)
    return np.array([se3_key[0], se3_key[1], rotation[1, 0], rotation[0, 0]])


def make_legacy(path: Path, schema: int) -> None:
    """Rewrite the memory at ``path`` as a schema ``schema`` (1, 2 or 3) file."""
    conn = sqlite3.connect(path)
    with conn:
        rows = conn.execute("SELECT rowid, key FROM pair_entries").fetchall()
        conn.executemany(
            "UPDATE pair_entries SET key = ? WHERE rowid = ?",
            [(compact_planar_key(np.frombuffer(key, dtype=np.float64)).tobytes(), rowid) for rowid, key in rows],
        )
        conn.execute("DELETE FROM meta WHERE key = 'rotation_weight'")
        if schema <= 2:
            for column in ("source", "profile", "robot_time"):
                conn.execute(f"ALTER TABLE episodes DROP COLUMN {column}")
        if schema == 1:
            conn.execute("DROP TABLE training_runs")
            for column in ("training_run", "seed"):
                conn.execute(f"ALTER TABLE episodes DROP COLUMN {column}")
        conn.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(schema),))
    conn.close()
