"""What ``train.py``'s settings resolve to, each checked before any episode runs (a mistake costs no training):
the training specs, the memory agent's controller (``--max-lockers``), the twin's episode runner
(``--sim twin``: reality profile and calibration, the calibration checked against the cell) and that an output
file can be written. Each mistake is a :class:`TrainingSetupError` or :class:`OutputFileError` whose message
names the flag; an output file is owned by one trainer at a time (:func:`hold_output_file`)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from puzzlebox.lab.cells import CellError, load_cell
from puzzlebox.lab.errors import OutputFileError, TrainingSetupError
from puzzlebox.lab.out_lock import OutputLock
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import LearningError
from puzzlebox.models import PuzzleSpec, SpecError, load_spec

if TYPE_CHECKING:
    from puzzlebox.lab.twin_training import TwinTraining


def load_training_specs(paths: Sequence[str]) -> list[PuzzleSpec]:
    """The spec of every file in ``paths``, in order."""
    try:
        return [load_spec(path) for path in paths]
    except SpecError as err:
        raise TrainingSetupError(str(err)) from err


def memory_controller(max_lockers: int, sim: str, agent: str) -> DualControllerConfig | None:
    """The symbolic memory agent's controller with a belief over sets of up to ``max_lockers`` lockers; None for
    the default (1: the paper's one-locker belief)."""
    if max_lockers == 1:
        return None
    if sim != "symbolic" or agent != "memory":
        raise TrainingSetupError(
            "--max-lockers is for the memory agent with --sim symbolic (the twin's keeps the one-locker belief)"
        )
    try:
        return DualControllerConfig(max_lockers=max_lockers)
    except LearningError as err:
        raise TrainingSetupError(f"--max-lockers: {err}") from err


def twin_training_for(
    reality: str | None, calibration: str | None, spec_paths: Sequence[str], specs: Sequence[PuzzleSpec]
) -> TwinTraining:
    """The twin episode runner for ``--sim twin`` under the profile ``reality`` (default ``ideal``), perceiving
    through the calibration file ``calibration`` if given, which must be the one of this cell (profile and box
    height, as ``trial.py`` checks) for every spec (the twin loads only when asked)."""
    from puzzlebox.lab.twin_training import TwinTraining

    try:
        profile, cell = load_cell(reality or "ideal", calibration, dict(zip(spec_paths, specs, strict=True)))
    except CellError as err:
        raise TrainingSetupError(str(err)) from err
    return TwinTraining(profile, cell)


def hold_output_file(path: Path, flag: str) -> OutputLock:
    """Own the output file ``path`` (given as ``flag``) for the training: refused now if it cannot be written or
    another process writes it (:class:`OutputInUse` naming it); released by the lock or the process's end."""
    check_writable(path, flag)
    return OutputLock(path, directory=False, what=flag)


def check_writable(path: Path, flag: str) -> None:
    """Refuse now, not after the training, an output file ``path`` (given as ``flag``) that cannot be written."""
    if path.is_dir():
        raise OutputFileError(f"{flag} {path} is a directory, not a file")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputFileError(f"{flag} {path}: cannot create its directory ({err.strerror})") from err
    target = path if path.exists() else path.parent
    if not os.access(target, os.W_OK):
        raise OutputFileError(f"{flag} {path}: cannot write {'it' if path.exists() else 'there'} (read-only)")
