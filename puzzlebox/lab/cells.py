"""A cell is a reality profile with its fixed imperfections (``cell_seed``) and the camera calibration made in it:
a calibration file names the cell it was made in, and a trial takes the cell from it."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from pathlib import Path

from puzzlebox.lab.errors import LabError
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.calibration import CalibrationError, CellCalibration
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.reality import RealityProfile, load_profile


class CellError(LabError, ValueError):
    """A reality profile or a calibration that cannot be loaded, or a calibration made in another cell."""


__all__ = ["CellError", "load_cell", "profile_of_calibration"]


def profile_of_calibration(profile: RealityProfile, calibration: CellCalibration | None) -> RealityProfile:
    """``profile`` in the cell ``calibration`` was made in: its ``cell_seed`` when the calibration names the same
    profile (``calibrate.py --cell-seed S`` makes such a file); else ``profile`` unchanged (a calibration of another
    profile, or of none, is then refused by :meth:`~puzzlebox.models.calibration.CellCalibration.check_cell`)."""
    if calibration is None or calibration.cell.get("profile") != profile.name:
        return profile
    seed = calibration.cell.get("cell_seed")
    if not isinstance(seed, int) or seed == profile.cell_seed:
        return profile
    return dataclasses.replace(profile, cell_seed=seed)


def load_cell(
    reality: str | Path, calibration: str | Path | None, specs: Mapping[str | Path, PuzzleSpec]
) -> tuple[RealityProfile, CellCalibration | None]:
    """The reality profile ``reality`` (a preset's name or a file) in the cell the calibration file was made in,
    and that calibration (None: the nominal one); raises :class:`CellError` for a profile or a calibration that
    cannot be read, or a calibration made for another profile or box height than a spec's (``specs``: spec file
    -> spec, named in the message)."""
    try:
        profile = load_profile(reality)
        loaded = CellCalibration.load(calibration) if calibration else None
    except (TwinError, CalibrationError) as err:
        raise CellError(str(err)) from err
    profile = profile_of_calibration(profile, loaded)
    if loaded is not None:  # the overview camera hangs above the lid: a calibration is of one box height
        for path, spec in specs.items():
            if spec.box is None:  # a disassembly scene: no box height to check (the twin refuses it, SceneError)
                continue
            try:
                loaded.check_cell(profile.name, profile.cell_seed, spec.box.size[2], spec=str(path))
            except CalibrationError as err:
                raise CellError(f"--calibration {calibration} for spec {spec.name}: {err}") from err
    return profile, loaded
