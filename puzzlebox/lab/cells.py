"""A cell is a reality profile with its fixed imperfections (``cell_seed``) and the camera calibration made in it:
a calibration file names the cell it was made in, and a trial takes the cell from it."""

from __future__ import annotations

import dataclasses

from puzzlebox.models.calibration import CellCalibration
from puzzlebox.twin.reality import RealityProfile

__all__ = ["profile_of_calibration"]


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
