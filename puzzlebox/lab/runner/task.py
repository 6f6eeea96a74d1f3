"""A task: one pure, seeded, picklable unit of work, described by a module-level function and the JSON
settings it is called with. The record depends on nothing else, so the same task gives the same record
in-process, in a worker pool, on Ray and after a resume."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from puzzlebox.lab.runner.errors import RunnerError
from puzzlebox.models.names import is_key


@dataclass(frozen=True)
class Task:
    """``function(settings)`` returns the task's record (a JSON-able dict).

    Attributes:
        key: unique among a run's tasks and a file name (letters, digits, ``._+=@-``; not hidden): its
            record is ``KEY.json``.
        function: a module-level function, pickled by reference (a lambda or a closure is refused).
        settings: everything the record depends on, JSON-able (seed included). A stored record made
            with other settings is recomputed, never mixed in.
        cpus: CPU cores the task occupies (what Ray reserves for it).
        context: where the task puts side outputs (e.g. a directory for a checkpoint), JSON-able, passed as
            ``function(settings, context)`` when given; not part of the settings' hash: moving a results
            directory does not make its records stale.
    """

    key: str
    function: Callable[..., dict[str, Any]]
    settings: Mapping[str, Any] = field(default_factory=dict)
    cpus: float = 1.0
    context: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        if not is_key(self.key):  # the one rule for names and keys (models.names); make keys with name_slug
            raise RunnerError(f"task key {self.key!r} is not a file name (letters, digits, ._+=@-; not hidden)")
        name = getattr(self.function, "__qualname__", "")
        if "<" in name or not getattr(self.function, "__module__", None):
            raise RunnerError(f"task {self.key}: {name or self.function!r} is not a module-level function")
        if not self.cpus > 0:
            raise RunnerError(f"task {self.key}: cpus must be positive, got {self.cpus}")
        try:
            canonical = json.dumps(self.settings, sort_keys=True, separators=(",", ":"), allow_nan=False)
        except (TypeError, ValueError) as err:
            raise RunnerError(f"task {self.key}: settings are not JSON ({err})") from None
        digest = hashlib.sha256(f"{self.function.__module__}:{name}\n{canonical}".encode()).hexdigest()
        object.__setattr__(self, "_hash", digest)

    @property
    def settings_hash(self) -> str:
        """SHA-256 of the function's name and the canonical JSON of the settings."""
        return self._hash  # type: ignore[attr-defined]


def execute(
    function: Callable[..., dict[str, Any]], settings: Mapping[str, Any], context: Mapping[str, Any] | None = None
) -> tuple[bool, Any]:
    """Run one task where the executor put it: ``(True, record)``, or ``(False, "Type: message\\n<traceback>")``
    for an exception — returned rather than raised, so that no exception type has to survive pickling."""
    import traceback

    try:
        return True, function(settings) if context is None else function(settings, context)
    except Exception as err:  # noqa: BLE001 - any task error is reported with its key, not raised
        message = " ".join(line.strip() for line in str(err).splitlines())  # its first line is the whole reason
        return False, f"{type(err).__name__}: {message}\n{traceback.format_exc()}"
