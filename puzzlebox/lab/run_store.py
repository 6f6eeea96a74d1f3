"""A results directory written as it is produced, and resumable.

The directory is owned by one process at a time: the store holds its lock (``DIR/.lock``,
:class:`~puzzlebox.lab.out_lock.OutputLock`) from before it reads anything there until :meth:`RunStore.close` or the
process's end, and a second writer is refused (:class:`~puzzlebox.lab.errors.OutputInUse`, naming the holder).

Layout of ``DIR``: ``config.json`` (the experiment's resolved arguments, written first), ``runs/KEY.json``
(one record per finished run, each written atomically the moment the run ends) and ``results.json``
(the summary, rewritten from the records every few seconds and at the end, with ``runs_done`` of
``runs_planned``).
A crash, a kill or Ctrl-C keeps every finished run; ``--resume`` continues a directory of the same
configuration, skipping what is there; ``--force`` empties one that holds anything else. Without either,
a directory holding results is refused (:class:`~puzzlebox.lab.errors.OutputHoldsResults`), so no directory
ever describes one experiment and holds another's numbers. Every refusal is a
:class:`~puzzlebox.lab.errors.RunStoreError`, its message naming the command line's flags. Half-written files
a SIGKILL left (hidden temporaries of records and videos) are removed when the directory is taken up again.
"""

from __future__ import annotations

import contextlib
import errno
import json
import shutil
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from puzzlebox.lab.cli import versions, write_json
from puzzlebox.lab.errors import (
    OutputHoldsAnotherConfig,
    OutputHoldsResults,
    OutputNotADirectory,
    OutputNotWritable,
    ResumeAndForce,
)
from puzzlebox.lab.out_lock import OutputLock
from puzzlebox.lab.runner import RecordStore

RECORDS = "runs"
WRITE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.EPERM, errno.EIO, errno.EFBIG}
"""What a write fails with when the place, not the program, is at fault (full, read-only, failing)."""


class RunStore:
    """See the module docstring. ``experiment`` is what defines the results (the resolved arguments without
    the output flags); ``resume``/``force`` are the command line's."""

    def __init__(self, out: Path, experiment: dict[str, Any], resume: bool = False, force: bool = False) -> None:
        if resume and force:
            raise ResumeAndForce("--resume continues a directory, --force empties it: give one")
        if out.exists() and not out.is_dir():
            raise OutputNotADirectory(f"--out {out} is a file, not a directory")
        self.lock = OutputLock(out)  # before anything there is read, removed or written
        try:
            self._take_up(out, experiment, resume, force)
        except BaseException:
            self.lock.release()
            raise

    def _take_up(self, out: Path, experiment: dict[str, Any], resume: bool, force: bool) -> None:
        self.out, self.experiment = out, experiment
        self.records_dir = out / RECORDS
        self.records = RecordStore(self.records_dir)
        """Where each finished run's record is kept (``puzzlebox.lab.runner``)."""
        config_path = out / "config.json"
        holds = [p for p in (config_path, out / "results.json") if p.exists()] + self._record_paths()
        if holds and not force:
            old = self._read_config(config_path)
            if not resume:
                raise OutputHoldsResults(
                    f"--out {out} already holds results ({len(self._record_paths())} run(s)): add --resume to "
                    "continue them (same configuration) or --force to delete them and start over"
                )
            if old != experiment:
                changed = sorted(k for k in set(old) | set(experiment) if old.get(k) != experiment.get(k))
                raise OutputHoldsAnotherConfig(
                    f"--resume: {out} holds another configuration (differs in {', '.join(changed)}); use --force"
                )
        if force:
            shutil.rmtree(self.records_dir, ignore_errors=True)
            (out / "results.json").unlink(missing_ok=True)
        stale = [*out.glob(".*.tmp"), *out.glob(".rollout*.mp4"), *out.glob(".rollout-model.*.mjb"),
                 *out.glob(".*.rrd"), *self.records_dir.glob(".*.tmp")]  # fmt: skip
        for path in stale:  # half-written files of a killed run (a normal end or an error removes its own)
            path.unlink(missing_ok=True)
        if stale:
            print(f"removed {len(stale)} unfinished file(s) a killed run left in {out}", file=sys.stderr)
        try:
            write_json(config_path, {**experiment, "versions": versions()})
        except OSError as err:
            raise OutputNotWritable(f"--out {out}: cannot write there ({err.strerror})") from err

    def close(self) -> None:
        """Release the directory (another process may take it up); the process's exit does it too."""
        self.lock.release()

    def __enter__(self) -> RunStore:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _record_paths(self) -> list[Path]:
        return sorted(self.records_dir.glob("*.json")) if self.records_dir.is_dir() else []

    @staticmethod
    def _read_config(path: Path) -> dict[str, Any]:
        try:
            config = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError):
            return {}
        if not isinstance(config, dict):
            return {}
        config.pop("versions", None)
        return config

    def write_results(self, results: dict[str, Any]) -> Path:
        with self.keeping():
            return write_json(self.out / "results.json", results)

    @contextlib.contextmanager
    def keeping(self) -> Iterator[None]:
        """Turn a failed write (a full disk, a directory made read-only) into one :class:`OutputNotWritable` that
        says what is kept and how to go on; every record written before is whole (each atomically)."""
        try:
            yield
        except OSError as err:
            if err.errno not in WRITE_ERRNOS:
                raise
            raise OutputNotWritable(
                f"--out {self.out}: cannot write ({err.strerror or err}); {len(self._record_paths())} finished run(s) "
                "are kept there: free space (or make it writable) and continue with the same command and --resume"
            ) from err


class Periodic:
    """Calls ``write()`` at most once every ``period_s`` [s] of wall time when asked (the first time at once).

    A summary rewritten from every record after every task grows quadratic in the tasks (the records are already
    on disk, each the moment it ended): this rewrites it a few times a minute, and the caller writes it once more
    at the end."""

    def __init__(self, write: Callable[[], object], period_s: float = 5.0) -> None:
        self._write, self._period = write, period_s
        self._next = 0.0

    def __call__(self) -> None:
        now = time.monotonic()
        if now >= self._next:
            self._next = now + self._period
            self._write()
