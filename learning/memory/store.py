"""The memory of learned dependency graphs, persisted in SQLite.

After an episode, every ordered pair (i, j) contributes its learned belief block — the probabilities
that i, in each of its states, is among the lockers of j in each of j's states
(:meth:`learning.lock_belief.LockBelief.locker_memberships`; for the paper's one-locker belief, that it *is* the
locker; memories trained over sets of lockers before memberships stored each set's mass shared among its
lockers, which reads as a half of each of two lockers) — to the bucket of its kinds
``(kind_i, kind_j)``, keyed by j's pose in i's frame; every component contributes its probability of
being independent (per state) to the bucket of its kind. Everything lives in memory for fast
nearest-neighbour look-ups and, when a path is given, in an SQLite file: one transaction per
episode, so a crash loses at most the episode in progress.

The training log lives in the same file: each training run (:meth:`MemoryStore.begin_training_run`,
with its configuration) and each episode's outcome (spec, seed, solved, actions) are rows written in
the episode's transaction, so the log and the memory never disagree, several trainers can share one
file (SQLite serialises their transactions) and the history accumulates. :meth:`training_log` reads
it back; ``MEM.sqlite.train.json`` is an export of it. Schema 1 files (no log) are read as they are
and upgraded in place when trained further.

Each episode also keeps its provenance (schema 3): where it was experienced (``symbolic``: the symbolic
simulator; ``twin``: end to end in the MuJoCo twin, writing only what the robot sensed), under which reality
profile, and how much simulated robot time it took [s]; :meth:`MemoryStore.provenance` sums them up.
Episodes of schema 1 and 2 files, which only the symbolic simulator could write, count as ``symbolic``.

Keys are SE(3) (schema 4, :mod:`learning.memory.keys`): j's full rigid pose in i's frame, 12 numbers, with the
``rotation_weight`` the file was created with in its meta table, so planar puzzle boxes and 6-DOF disassembly
scenes share one memory. Files of schemas 1-3 hold compact keys (4 numbers planar, 9 for 6-DOF Euler angles):
they are read by converting each key to its SE(3) form (:func:`~learning.memory.keys.se3_key_from_legacy`,
rotation weight 1.0, which keeps every planar distance as it was) and migrated in place — keys rewritten,
schema raised, in one transaction — the first time they are trained further (or by ``scripts/memory.py
--migrate``).

A file that is not a puzzlebox memory (not SQLite, another application's database, a newer schema)
or that is damaged (truncated, failed integrity check, malformed rows) raises
:class:`~learning.errors.MemoryFileError`; it is never read as an empty memory. Nor is a file whose schema is not
exactly the project's (:func:`check_schema`: a trigger, a view, an unknown table, index or column): a trigger
would run its own SQL on our writes, so the check runs when the file is opened and again inside every write
transaction.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import sqlite3
import tempfile
import time
from collections import defaultdict
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from puzzlebox.learning.errors import MemoryFileError
from puzzlebox.learning.memory.keys import (
    DEFAULT_ROTATION_WEIGHT,
    PLANAR_KEY_SIZE,
    SE3_KEY_SIZE,
    SPATIAL_KEY_SIZE,
    se3_key_from_legacy,
)
from puzzlebox.models.atomic import apply_umask
from puzzlebox.models.disassembly_kinds import kind_family
from puzzlebox.models.errors import UnknownKindError

MEMORY_FORMAT = "puzzlebox-memory"
PAIR_VALUE_SIZE = 6
"""Per stored pair: 4 probabilities [s_j, s_i] and the confidence of j's two blocks."""
SCHEMA_VERSION = 4
READABLE_SCHEMAS = ("1", "2", "3", "4")
LEGACY_KEY_SCHEMAS = ("1", "2", "3")
"""Schemas whose pair keys are compact (4 or 9 numbers), converted to SE(3) keys when read."""
SAME_PAIR_RADIUS = 0.5
"""Key distance within which two episodes' entries of one box and kind pair are one pair met twice [key units, ~1 cm
at the default scale]: the twin keys a pair by the poses the robot perceived (1-2 mm off the spec's), and two pairs
of one box that differ stand a part apart (>= 5 cm)."""
SOURCES = ("symbolic", "twin")
"""Where an episode was experienced: the symbolic simulator, or end to end in the twin."""
SEVERAL_LOCKERS_LEARNED = 1.9
"""Expected number of lockers of one component in one state (its memberships summed) from which an episode has
learned a component held by several: with sets of up to two, ``P(two) >= sum - 1``, so at least 0.9. A belief
over sets of two left uncertain on a one-locker chain box sums to at most 1.62 (paper training boxes, 18
episodes); multi-locker boxes and lab-computer-a reach 1.96-2.0."""

_LOG_SCHEMA = """
CREATE TABLE training_runs (id INTEGER PRIMARY KEY, started REAL NOT NULL, config TEXT NOT NULL);
ALTER TABLE episodes ADD COLUMN seed INTEGER;
ALTER TABLE episodes ADD COLUMN training_run INTEGER REFERENCES training_runs(id);
"""
"""What schema 2 adds to schema 1: the training log."""

_PROVENANCE_SCHEMA = """
ALTER TABLE episodes ADD COLUMN source TEXT;
ALTER TABLE episodes ADD COLUMN profile TEXT;
ALTER TABLE episodes ADD COLUMN robot_time REAL;
"""
"""What schema 3 adds to schema 2: each episode's provenance (NULL source: symbolic, from before it)."""

_SCHEMA = (
    """
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL);
CREATE TABLE episodes (
    id INTEGER PRIMARY KEY, spec TEXT NOT NULL, solved INTEGER NOT NULL,
    num_actions INTEGER NOT NULL, created REAL NOT NULL);
CREATE TABLE pair_entries (
    episode INTEGER NOT NULL REFERENCES episodes(id), kind_i TEXT NOT NULL, kind_j TEXT NOT NULL,
    key BLOB NOT NULL, value BLOB NOT NULL);
CREATE TABLE independence_entries (
    episode INTEGER NOT NULL REFERENCES episodes(id), kind TEXT NOT NULL, value BLOB NOT NULL);
"""
    + _LOG_SCHEMA
    + _PROVENANCE_SCHEMA
)

_COLUMNS = {
    "meta": {"key", "value"},
    "episodes": {"id", "spec", "solved", "num_actions", "created"},
    "pair_entries": {"episode", "kind_i", "kind_j", "key", "value"},
    "independence_entries": {"episode", "kind", "value"},
}
"""Every table of a schema 1 file and its columns."""
_LOG_COLUMNS, _PROVENANCE_COLUMNS = {"seed", "training_run"}, {"source", "profile", "robot_time"}
_INDEXES = {"sqlite_autoindex_meta_1"}
"""Every index a memory file holds (SQLite's own, of meta's primary key)."""


def expected_objects(schema: str) -> dict[tuple[str, str], set[str]]:
    """What ``sqlite_master`` of a schema ``schema`` memory holds, exactly: ``(type, name)`` -> the table's
    columns (an index: none). No trigger, no view, nothing else."""
    columns = {name: set(cols) for name, cols in _COLUMNS.items()}
    if schema != "1":
        columns["training_runs"] = {"id", "started", "config"}
        columns["episodes"] |= _LOG_COLUMNS | (_PROVENANCE_COLUMNS if schema != "2" else set())
    return {**{("table", name): cols for name, cols in columns.items()}, **{("index", i): set() for i in _INDEXES}}


def check_schema(conn: sqlite3.Connection, path: Path | str, schema: str) -> None:
    """Refuse (:class:`MemoryFileError`) a file whose ``sqlite_master`` is not exactly the project's for
    ``schema``: a trigger runs code on every write (it passes ``PRAGMA integrity_check``), a view or an unknown
    table or index is not ours. Run when a file is opened and inside every write transaction."""
    found = {(kind, name) for kind, name in conn.execute("SELECT type, name FROM sqlite_master")}
    expected = expected_objects(schema)
    extra = sorted(found - set(expected))
    if extra:
        shown = ", ".join(f"{kind} {name!r}" for kind, name in extra[:5])
        raise MemoryFileError(
            f"{path} holds what a puzzlebox memory never does ({shown}{', ...' if len(extra) > 5 else ''}): "
            "refused, nothing run on it"
        )
    missing = sorted(set(expected) - found)
    if missing:
        raise MemoryFileError(f"{path} lacks {', '.join(f'{k} {n!r}' for k, n in missing)} of a schema {schema} "
                              "puzzlebox memory")  # fmt: skip
    for (kind, name), columns in expected.items():
        if kind == "table":
            got = {row[1] for row in conn.execute(f"PRAGMA table_info({name})")}
            if got != columns:
                raise MemoryFileError(
                    f"{path}: table {name!r} has columns {sorted(got)}, not a schema {schema} memory's "
                    f"{sorted(columns)}"
                )


BUSY_TIMEOUT = 120.0
"""How long a writer waits for another trainer's transaction on the same file [s]."""


@dataclass(frozen=True)
class Bucket:
    """Entries of one bucket: ``keys`` ``(M, K)``, ``values`` ``(M, V)`` and ``pairs`` ``(M,)``: which pair of which
    box each entry is a meeting of (:func:`pair_ids`: entries with one id are one pair of one box, met in several
    episodes)."""

    keys: np.ndarray
    values: np.ndarray
    pairs: np.ndarray

    @cached_property
    def distinct(self) -> bool:
        """Whether every entry is a pair of its own (no pair met twice: a pair's id is its first entry's index),
        checked once per bucket rather than at every recall of one of its pairs."""
        return bool((self.pairs == np.arange(len(self.pairs))).all())


class MemoryStore:
    """Buckets of past belief blocks; see the module docstring.

    Pair values are 6 numbers: ``P(i in s_i holds j in s_j)`` for ``(s_j, s_i)`` = (0,0), (0,1),
    (1,0), (1,1), then the confidence (1 - normalised entropy) of j's blocks for s_j = 0 and 1;
    independence values are ``[P(indep | s=0), P(indep | s=1)]``.
    """

    def __init__(
        self,
        path: str | Path | None = None,
        position_scale: float = 0.02,
        rotation_weight: float = DEFAULT_ROTATION_WEIGHT,
    ) -> None:
        """Open (or create) a memory. ``path=None`` keeps it in RAM only.

        Args:
            path: SQLite file; created with ``position_scale`` and ``rotation_weight`` when absent.
            position_scale: length that weighs like one key unit [m]. An existing file keeps the scale it
                was created with.
            rotation_weight: key units per unit of chord ``2 sin(theta/2)`` of a relative rotation
                (:mod:`learning.memory.keys`). An existing file keeps its own (1.0 for files before schema 4).
        """
        if not (math.isfinite(position_scale) and position_scale > 0.0):
            raise ValueError(f"position_scale must be a finite length > 0 [m], got {position_scale}")
        if not (math.isfinite(rotation_weight) and rotation_weight >= 0.0):
            raise ValueError(f"rotation_weight must be finite and >= 0, got {rotation_weight}")
        self.path = Path(path) if path is not None else None
        self.position_scale = position_scale
        self.rotation_weight = rotation_weight
        self._pairs: dict[tuple[str, str], list[tuple[np.ndarray, np.ndarray, int]]] = defaultdict(list)
        """Per bucket (kind_i, kind_j): every stored (key, value, episode id) in storage order."""
        self._boxes: dict[int, str] = {}
        """Episode id -> the box it met (:meth:`_box`)."""
        self._layouts: dict[str, list[np.ndarray]] = defaultdict(list)
        """Spec name -> the layout signature of each box of that name met so far (:meth:`_box`)."""
        self._independence: dict[str, list[np.ndarray]] = defaultdict(list)
        self.most_lockers = 0.0
        """The largest expected number of lockers of one component in one state over the stored episodes [-]
        (:func:`expected_lockers`; at most 1 for episodes learned with the paper's one-locker belief)."""
        self._cache: dict[tuple[str, ...], Bucket] = {}
        self.num_episodes = 0
        self._provenance: list[tuple[str, str | None, float | None]] = []
        """(source, profile, robot time [s]) of every episode, oldest first."""
        self._schema = str(SCHEMA_VERSION)
        self._conn: sqlite3.Connection | None = None
        if self.path is not None:
            self._open_file(self.path)

    @classmethod
    def open_existing(cls, path: str | Path) -> MemoryStore:
        """Open a memory that must already exist (for evaluation)."""
        if not Path(path).is_file():
            raise MemoryFileError(f"no memory file at {path}; train one with scripts/train.py")
        return cls(path)

    # -- persistence -------------------------------------------------------------------------------
    def _create(self, path: Path) -> None:
        """Create an empty memory at ``path`` whole: built under a temporary name beside it and linked into
        place only if ``path`` is still absent, so a concurrent trainer never opens a half-made (empty) file;
        whoever loses the race opens the winner's."""
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
        os.close(fd)
        try:
            conn = sqlite3.connect(name)
            with conn:
                conn.executescript(_SCHEMA)
                conn.executemany(
                    "INSERT INTO meta VALUES (?, ?)",
                    [
                        ("format", MEMORY_FORMAT),
                        ("schema_version", str(SCHEMA_VERSION)),
                        ("position_scale", repr(self.position_scale)),
                        ("rotation_weight", repr(self.rotation_weight)),
                    ],
                )
            conn.close()
            apply_umask(name)  # mkstemp made it private; the memory file is not
            with contextlib.suppress(FileExistsError):
                os.link(name, path)
        finally:
            os.unlink(name)

    def _open_file(self, path: Path) -> None:
        if not path.exists():
            self._create(path)
        if path.stat().st_size == 0:  # a memory is never empty on disk: cut short or foreign
            raise MemoryFileError(f"{path} is empty (0 bytes): truncated or not a puzzlebox memory")
        conn = None
        try:
            conn = sqlite3.connect(path, timeout=BUSY_TIMEOUT)
            self._check(conn, path)
            self._load(conn, path)
        except (sqlite3.DatabaseError, MemoryFileError) as err:
            if conn is not None:
                conn.close()
            if isinstance(err, MemoryFileError):
                raise
            raise MemoryFileError(f"{path} is not a readable puzzlebox memory: {err}") from None
        self._conn = conn

    def _check(self, conn: sqlite3.Connection, path: Path) -> None:
        status = conn.execute("PRAGMA integrity_check").fetchone()[0]
        if status != "ok":
            raise MemoryFileError(f"{path} is corrupted (SQLite integrity check: {status})")
        tables = {row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        if "meta" not in tables:
            raise MemoryFileError(f"{path} is an SQLite file but not a puzzlebox memory (tables: {sorted(tables)})")
        meta = dict(conn.execute("SELECT key, value FROM meta").fetchall())
        if meta.get("format") != MEMORY_FORMAT:
            raise MemoryFileError(f"{path} is not a puzzlebox memory (format {meta.get('format')!r})")
        if meta.get("schema_version") not in READABLE_SCHEMAS:
            raise MemoryFileError(
                f"{path} has memory schema {meta.get('schema_version')}; this version reads {list(READABLE_SCHEMAS)}"
            )
        self._schema = meta["schema_version"]
        check_schema(conn, path, self._schema)
        self.position_scale = _meta_number(meta, "position_scale", path, "a finite length > 0", positive=True)
        if self._schema in LEGACY_KEY_SCHEMAS:
            self.rotation_weight = DEFAULT_ROTATION_WEIGHT  # what the conversion of its compact keys uses
            return
        self.rotation_weight = _meta_number(meta, "rotation_weight", path, "finite and >= 0", positive=False)

    def _load(self, conn: sqlite3.Connection, path: Path) -> None:
        self.num_episodes = conn.execute("SELECT COUNT(*) FROM episodes").fetchone()[0]
        if self._schema in ("3", "4"):
            rows = conn.execute("SELECT source, profile, robot_time FROM episodes ORDER BY id").fetchall()
            self._provenance = [(source or "symbolic", profile, robot_time) for source, profile, robot_time in rows]
        else:
            self._provenance = [("symbolic", None, None)] * self.num_episodes
        sizes = dict(conn.execute("SELECT episode, COUNT(*) FROM independence_entries GROUP BY episode"))
        names = dict(conn.execute("SELECT id, spec FROM episodes"))
        by_episode: dict[int, list[np.ndarray]] = defaultdict(list)
        offsets: dict[int, list[np.ndarray]] = defaultdict(list)
        for episode, kind_i, kind_j, key, value in conn.execute(
            "SELECT episode, kind_i, kind_j, key, value FROM pair_entries ORDER BY rowid"
        ):
            key_arr, value_arr = _decode(key, path), _decode(value, path)
            legacy = self._schema in LEGACY_KEY_SCHEMAS
            key_sizes = (PLANAR_KEY_SIZE, SPATIAL_KEY_SIZE) if legacy else (SE3_KEY_SIZE,)
            if value_arr.size != PAIR_VALUE_SIZE or key_arr.size not in key_sizes:
                raise MemoryFileError(
                    f"{path} has a malformed pair entry ({key_arr.size} key, {value_arr.size} values; schema "
                    f"{self._schema} keys have {' or '.join(map(str, key_sizes))} numbers)"
                )
            if legacy:
                try:
                    key_arr = se3_key_from_legacy(key_arr, self.rotation_weight)
                except ValueError as err:
                    raise MemoryFileError(f"{path} has a malformed pair key ({kind_i} -> {kind_j}): {err}") from None
            _check_probabilities(value_arr, f"{path} has a pair entry ({kind_i} -> {kind_j})")
            _check_kinds(path, "a pair entry", kind_i, kind_j)
            self._pairs[(kind_i, kind_j)].append((key_arr, value_arr, episode))
            by_episode[episode].append(value_arr)
            offsets[episode].append(key_arr[:3])
        for episode, values in by_episode.items():
            self.most_lockers = max(self.most_lockers, _stored_expected_lockers(values, sizes.get(episode, 0)))
        for episode in sorted(offsets):
            self._boxes[episode] = self._box(names.get(episode), episode, np.array(offsets[episode]))
        for kind, value in conn.execute("SELECT kind, value FROM independence_entries ORDER BY rowid"):
            value_arr = _decode(value, path)
            if value_arr.size != 2:
                raise MemoryFileError(f"{path} has a malformed independence entry")
            _check_probabilities(value_arr, f"{path} has an independence entry ({kind})")
            _check_kinds(path, "an independence entry", kind)
            self._independence[kind].append(value_arr)
        if self._schema != "1":  # (the training log: every run's config is JSON, read by training_log)
            for run_id, config in conn.execute("SELECT id, config FROM training_runs"):
                try:
                    json.loads(config)
                except (TypeError, ValueError):
                    raise MemoryFileError(f"{path} has a training run ({run_id}) whose config is not JSON") from None

    def _write_transaction(self) -> None:
        """Begin a write transaction (holding the file's write lock) and check, inside it, that the file is still
        exactly a memory (:func:`check_schema`): what is written is written only through that check."""
        assert self._conn is not None and self.path is not None
        self._conn.execute("BEGIN IMMEDIATE")
        check_schema(self._conn, self.path, self._schema)

    def close(self) -> None:
        if self._conn is not None:
            self._conn.close()
            self._conn = None

    # -- the training log ----------------------------------------------------------------------------
    @property
    def schema(self) -> str:
        """The schema version of the file as it is now (a memory in RAM: the current one)."""
        return self._schema

    def migrate(self) -> None:
        """Bring an older file to the current schema (once, whichever trainer gets there first, in one
        transaction): add the training log (schema 1), the provenance columns (schemas 1 and 2), and rewrite
        every compact pair key as its SE(3) key (schemas 1 to 3)."""
        if self._conn is None or self._schema == str(SCHEMA_VERSION):
            return
        conn, path = self._conn, self.path
        assert path is not None  # the connection is to the file at path
        conn.execute("BEGIN IMMEDIATE")  # hold the write lock: another trainer may be upgrading too
        try:
            schema = conn.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone()[0]
            check_schema(conn, path, schema)  # nothing of another's runs on our write
            missing = {"1": _LOG_SCHEMA + _PROVENANCE_SCHEMA, "2": _PROVENANCE_SCHEMA}.get(schema, "")
            for statement in filter(str.strip, missing.split(";")):
                conn.execute(statement)
            if schema in LEGACY_KEY_SCHEMAS:
                rows = conn.execute("SELECT rowid, key FROM pair_entries").fetchall()
                conn.executemany(
                    "UPDATE pair_entries SET key = ? WHERE rowid = ?",
                    [(se3_key_from_legacy(_decode(key, path), self.rotation_weight).tobytes(), rowid)
                     for rowid, key in rows],
                )  # fmt: skip
                conn.execute("INSERT INTO meta VALUES ('rotation_weight', ?)", (repr(self.rotation_weight),))
            if schema != str(SCHEMA_VERSION):
                conn.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (str(SCHEMA_VERSION),))
            conn.commit()
        except BaseException:
            conn.rollback()
            raise
        self._schema = str(SCHEMA_VERSION)

    def begin_training_run(self, config: dict[str, object]) -> int | None:
        """Log the start of a training run with its ``config`` (JSON-able); its id for :meth:`add_episode`,
        or None for a memory kept in RAM only."""
        if self._conn is None:
            return None
        self.migrate()
        with self._conn:
            self._write_transaction()
            cursor = self._conn.execute(
                "INSERT INTO training_runs (started, config) VALUES (?, ?)",
                (time.time(), json.dumps(config, sort_keys=True)),
            )
        return cursor.lastrowid

    def training_log(self) -> list[dict[str, object]]:
        """The file's training runs, oldest first, each with its ``config`` and ``episodes`` (spec, seed,
        solved, num_actions, created [s since the epoch]) — read from the file, so it includes what other
        trainers of the same file stored. Episodes stored before the log existed (schema 1) or without
        a run come under a run with ``id`` None. Empty for a memory kept in RAM only."""
        if self._conn is None:
            return []
        runs: dict[int | None, dict[str, object]] = {}
        if self._schema != "1":
            for run_id, started, config in self._conn.execute(
                "SELECT id, started, config FROM training_runs ORDER BY id"
            ):
                runs[run_id] = {"id": run_id, "started": started, "config": json.loads(config), "episodes": []}
            rows = self._conn.execute(
                "SELECT training_run, spec, seed, solved, num_actions, created FROM episodes ORDER BY id"
            ).fetchall()
        else:
            rows = [
                (None, spec, None, solved, num_actions, created)
                for spec, solved, num_actions, created in self._conn.execute(
                    "SELECT spec, solved, num_actions, created FROM episodes ORDER BY id"
                )
            ]
        for run_id, spec, seed, solved, num_actions, created in rows:
            run = runs.setdefault(run_id, {"id": run_id, "started": created, "config": {}, "episodes": []})
            run["episodes"].append(  # type: ignore[union-attr]
                {"spec": spec, "seed": seed, "solved": bool(solved), "num_actions": num_actions, "created": created}
            )
        return sorted(runs.values(), key=lambda r: (r["id"] is not None, r["id"] or 0))

    # -- writing -----------------------------------------------------------------------------------
    def add_episode(
        self,
        kinds: tuple[str, ...],
        keys: np.ndarray,
        pair_values: np.ndarray,
        independence: np.ndarray,
        spec: str = "",
        solved: bool = True,
        num_actions: int = 0,
        seed: int | None = None,
        training_run: int | None = None,
        source: str = "symbolic",
        profile: str | None = None,
        robot_time: float | None = None,
    ) -> None:
        """Store one episode's learned graph.

        Args:
            kinds: kind of each component ``(N,)``.
            keys: ``(N, N, 12)`` SE(3) keys (``[i, j]``: j seen from i; :func:`~learning.memory.keys.se3_pose_keys`
                with this memory's ``position_scale`` and ``rotation_weight``).
            pair_values: ``(N, N, 6)`` — ``[i, j]`` the block of "i holds j" (see the class docstring).
            independence: ``(N, 2)`` probability that each component is independent, per state.
            spec, solved, num_actions, seed: the episode's outcome, for the training log.
            training_run: id from :meth:`begin_training_run` (None: an episode outside a logged run).
            source: where the episode was experienced (:data:`SOURCES`); ``profile`` the twin's reality profile
                and ``robot_time`` the episode's simulated robot time [s] (twin episodes).
        """
        if source not in SOURCES:
            raise ValueError(f"unknown episode source {source!r}; known: {list(SOURCES)}")
        if robot_time is not None and not (math.isfinite(robot_time) and robot_time >= 0.0):
            raise ValueError(f"robot_time must be a finite time >= 0 [s], got {robot_time}")
        n = len(kinds)
        if keys.shape != (n, n, SE3_KEY_SIZE):
            raise ValueError(f"keys must be (N, N, {SE3_KEY_SIZE}) SE(3) keys for N = {n}, got {keys.shape}")
        pairs = [
            (kinds[i], kinds[j], keys[i, j].astype(np.float64), pair_values[i, j].astype(np.float64))
            for i in range(n)
            for j in range(n)
            if i != j
        ]
        singles = [(kinds[j], independence[j].astype(np.float64)) for j in range(n)]
        episode_id = self.num_episodes + 1  # (unique in this store: a RAM memory has no row ids)
        if self._conn is not None:
            self.migrate()
            with self._conn:  # one transaction: the episode (log row included) is stored whole or not at all
                self._write_transaction()
                cursor = self._conn.execute(
                    "INSERT INTO episodes (spec, solved, num_actions, created, seed, training_run, source, profile, "
                    "robot_time) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (spec, int(solved), num_actions, time.time(), seed, training_run, source, profile, robot_time),
                )
                episode = cursor.lastrowid
                episode_id = int(episode or episode_id)
                self._conn.executemany(
                    "INSERT INTO pair_entries VALUES (?, ?, ?, ?, ?)",
                    [(episode, ki, kj, k.tobytes(), v.tobytes()) for ki, kj, k, v in pairs],
                )
                self._conn.executemany(
                    "INSERT INTO independence_entries VALUES (?, ?, ?)",
                    [(episode, kind, v.tobytes()) for kind, v in singles],
                )
        for ki, kj, k, v in pairs:
            self._pairs[(ki, kj)].append((k, v, episode_id))
        self._boxes[episode_id] = self._box(spec, episode_id, np.array([k[:3] for _, _, k, _ in pairs]))
        self.most_lockers = max(self.most_lockers, expected_lockers(pair_values))
        for kind, v in singles:
            self._independence[kind].append(v)
        self._cache.clear()
        self.num_episodes += 1
        self._provenance.append((source, profile, robot_time))

    def provenance(self) -> dict[str, object]:
        """Where the memory's episodes come from: per source (:data:`SOURCES`) the number of episodes, and for
        twin episodes their simulated robot hours and the count per reality profile."""
        out: dict[str, dict[str, object]] = {source: {"episodes": 0} for source in SOURCES}
        for source, profile, robot_time in self._provenance:
            entry = out[source]
            entry["episodes"] = int(entry["episodes"]) + 1  # type: ignore[call-overload]
            if source == "twin":
                entry["robot_hours"] = float(entry.get("robot_hours", 0.0)) + (robot_time or 0.0) / 3600.0  # type: ignore[arg-type]
                profiles = entry.setdefault("profiles", {})
                profiles[profile or "?"] = profiles.get(profile or "?", 0) + 1  # type: ignore[union-attr]
        out["twin"].setdefault("robot_hours", 0.0)
        out["twin"].setdefault("profiles", {})
        return {"episodes": self.num_episodes, **out}

    # -- reading -----------------------------------------------------------------------------------
    def pair_bucket(self, kind_i: str, kind_j: str) -> Bucket | None:
        entries = self._pairs.get((kind_i, kind_j))
        if not entries:
            return None
        cache_key = ("pair", kind_i, kind_j)
        if cache_key not in self._cache:
            self._cache[cache_key] = self._bucket([(kind_i, kind_j, *entry) for entry in entries])
        return self._cache[cache_key]

    def _bucket(self, entries: list[tuple[str, str, np.ndarray, np.ndarray, int]]) -> Bucket:
        """A bucket of (kind_i, kind_j, key, value, episode) entries, with their :func:`pair_ids`."""
        keys = np.stack([e[2] for e in entries])
        boxes = [(e[0], e[1], self._boxes.get(e[4], f"#episode {e[4]}")) for e in entries]
        return Bucket(keys, np.stack([e[3] for e in entries]), pair_ids(keys, boxes, [e[4] for e in entries]))

    def _box(self, name: str | None, episode: int, offsets: np.ndarray) -> str:
        """The box an episode met: its spec name and layout. Layouts of one name (the paper's variants are laid
        out anew for each episode) are told apart by their sorted pair distances (``offsets``: the position part
        of every key, in key units), equal within :data:`SAME_PAIR_RADIUS`; an episode stored without a name is a
        box of its own."""
        if not name:
            return f"#episode {episode}"
        signature = np.sort(np.linalg.norm(offsets.reshape(-1, 3), axis=1))
        layouts = self._layouts[name]
        for n, other in enumerate(layouts):
            if len(other) == len(signature) and np.abs(other - signature).max(initial=0.0) <= SAME_PAIR_RADIUS:
                return f"{name} #{n}"
        layouts.append(signature)
        return f"{name} #{len(layouts) - 1}"

    def all_pairs_bucket(self, family: str) -> Bucket | None:
        """Every stored pair of a kind family (``models.disassembly_kinds.kind_family``), whatever its kinds (for
        kind pairs the memory has never seen): a computer's screws never recall a puzzle box's doors."""
        cache_key = ("all-pairs", family)
        if cache_key not in self._cache:
            entries = [
                (kind_i, kind_j, *entry)
                for (kind_i, kind_j), bucket in self._pairs.items()
                if kind_family(kind_i) == family
                for entry in bucket
            ]
            if not entries:
                return None
            self._cache[cache_key] = self._bucket(entries)
        return self._cache[cache_key]

    def holds_family(self, family: str) -> bool:
        """Whether any stored episode is of the kind family ``family`` (``models.disassembly_kinds.kind_family``)."""
        return any(kind_family(kind) == family for kind, entries in self._independence.items() if entries)

    def learned_several_lockers(self) -> bool:
        """Whether an episode learned a component held by several lockers (:data:`SEVERAL_LOCKERS_LEARNED`)."""
        return self.most_lockers >= SEVERAL_LOCKERS_LEARNED

    def independence_values(self, kind: str) -> np.ndarray | None:
        """``(M, 2)`` stored independence probabilities of a kind, or None if never seen."""
        entries = self._independence.get(kind)
        return np.stack(entries) if entries else None

    def summary(self) -> dict[str, object]:
        return {
            "episodes": self.num_episodes,
            "provenance": {source: self.provenance()[source] for source in SOURCES},
            "pair_buckets": {f"{a}->{b}": len(v) for (a, b), v in sorted(self._pairs.items())},
            "independence_buckets": {k: len(v) for k, v in sorted(self._independence.items())},
            "position_scale": self.position_scale,
            "rotation_weight": self.rotation_weight,
            "schema": self._schema,
        }

    def __repr__(self) -> str:
        return f"MemoryStore({json.dumps(self.summary())})"


_NOT_LEARNED = (("episodes", "created"), ("episodes", "training_run"))
"""Columns that say when and by which command an episode was stored, not what it taught."""


def content_sha256(path: str | Path) -> str:
    """A digest of what a memory file holds for an agent: its settings, its episodes (spec, seed, outcome, source,
    profile, robot time: not when they were stored), its pair and independence entries in their order. Two files
    with the same digest make the same memory agent, so a trial run with one is the trial run with the other."""
    digest = hashlib.sha256()
    with contextlib.closing(sqlite3.connect(f"{Path(path).resolve().as_uri()}?mode=ro", uri=True)) as conn:
        tables = {row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        columns = {t: [row[1] for row in conn.execute(f"PRAGMA table_info({t})")] for t in tables}
        for table in sorted(tables - {"training_runs"}):  # (when and by which command: not what was learned)
            kept = [c for c in columns[table] if (table, c) not in _NOT_LEARNED]
            order = "key" if table == "meta" else "rowid"
            digest.update(f"{table}({','.join(kept)})".encode())
            for row in conn.execute(f"SELECT {', '.join(kept)} FROM {table} ORDER BY {order}"):
                digest.update(repr(row).encode())
    return digest.hexdigest()


def pair_ids(keys: np.ndarray, boxes: list[tuple[str, str, str]], episodes: list[int]) -> np.ndarray:
    """``(M,)``: which pair of which box each entry is a meeting of, as the index of the pair's first entry.

    Entries are one pair when they are of the same box and kinds (``boxes``: kind_i, kind_j, box), their keys within
    :data:`SAME_PAIR_RADIUS` of the pair's first entry, and from different episodes (two pairs one episode stored are
    two pairs, however alike their poses: a box laid out on a grid has many). Component indices cannot tell: the
    twin lists a box's parts in the order the robot found them."""
    ids = np.arange(len(boxes), dtype=np.int64)
    firsts: dict[tuple[str, str, str], list[int]] = defaultdict(list)  # box -> the first entry of each of its pairs
    met: dict[int, set[int]] = {}  # a pair's first entry -> the episodes that met it
    for m, (box, episode) in enumerate(zip(boxes, episodes, strict=True)):
        candidates = firsts[box]
        if candidates:
            near = np.linalg.norm(keys[candidates] - keys[m], axis=1) <= SAME_PAIR_RADIUS
            first = next((c for c, n in zip(candidates, near, strict=True) if n and episode not in met[c]), None)
            if first is not None:
                ids[m] = first
                met[first].add(episode)
                continue
        candidates.append(m)
        met[m] = {episode}
    return ids


def expected_lockers(pair_values: np.ndarray) -> float:
    """The largest expected number of lockers of one component in one state in an episode's ``(N, N, 6)`` pair
    values (:meth:`MemoryStore.add_episode`): its memberships ``P((i, s_i) among the lockers of j in s_j)`` summed
    over ``(i, s_i)``, ``i != j``."""
    n = pair_values.shape[0]
    off_diagonal = ~np.eye(n, dtype=bool)[:, :, None]
    memberships = np.where(off_diagonal, pair_values[:, :, :4], 0.0).reshape(n, n, 2, 2)  # [i, j, s_j, s_i]
    return float(memberships.sum(axis=(0, 3)).max(initial=0.0))


def _stored_expected_lockers(values: list[np.ndarray], n: int) -> float:
    """:func:`expected_lockers` of an episode read back: its pair values in storage order (``i`` major, ``j != i``
    minor, as :meth:`MemoryStore.add_episode` writes them) for ``n`` components (0 or a count that does not fit:
    unknown, 0)."""
    if n < 2 or len(values) != n * (n - 1):
        return 0.0
    full = np.zeros((n, n, PAIR_VALUE_SIZE))
    full[~np.eye(n, dtype=bool)] = np.stack(values)  # row-major over (i, j), the diagonal skipped
    return expected_lockers(full)


def _meta_number(meta: dict[str, str], name: str, path: Path, rule: str, positive: bool) -> float:
    """The number ``meta[name]`` of a memory file's meta table, finite and > 0 (``positive``) or >= 0."""
    try:
        value = float(meta[name])
    except (KeyError, ValueError):
        raise MemoryFileError(f"{path} has no valid {name} in its meta table ({meta.get(name)!r})") from None
    if not (math.isfinite(value) and (value > 0.0 if positive else value >= 0.0)):
        raise MemoryFileError(f"{path} has a {name} that is not {rule}: {value}")
    return value


def _check_kinds(path: Path, entry: str, *kinds: object) -> None:
    """:class:`MemoryFileError` unless every one of ``kinds`` is a kind some family knows (a memory of an unknown kind
    failed every trial of the memory agent, and ``train.py`` wrote to it before failing)."""
    for kind in kinds:
        if kind not in _KNOWN_KINDS:
            try:
                kind_family(str(kind))
            except UnknownKindError as err:
                raise MemoryFileError(f"{path} has {entry} of an unknown kind: {err}") from None
            _KNOWN_KINDS.add(str(kind))


_KNOWN_KINDS: set[str] = set()
"""Kinds :func:`_check_kinds` found known (a memory holds thousands of entries of a few kinds)."""


def _check_probabilities(values: np.ndarray, where: str) -> None:
    """Every stored value (probabilities and confidences) lies in [0, 1]."""
    if np.any(values < 0.0) or np.any(values > 1.0):
        raise MemoryFileError(f"{where} outside [0, 1]: {np.round(values, 4).tolist()}")


def _decode(blob: object, path: Path) -> np.ndarray:
    if not isinstance(blob, bytes) or len(blob) % 8:
        raise MemoryFileError(f"{path} has a malformed entry (not a float64 array)")
    values = np.frombuffer(blob, dtype=np.float64)
    if not np.all(np.isfinite(values)):
        raise MemoryFileError(f"{path} has a non-finite entry")
    return values.copy()
