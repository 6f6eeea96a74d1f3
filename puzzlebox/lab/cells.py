"""Where a trial runs: a cell. :class:`TwinCell` is the twin under a reality profile with its fixed imperfections
(``cell_seed``) and the camera calibration made in it (a calibration file names the cell it was made in, and a
trial takes the cell from it); :class:`RealCell` is an arm behind the ``Robot`` seam with its cell config and
calibration. :func:`puzzlebox.lab.run_trial` runs an agent in either."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from puzzlebox.lab.errors import LabError
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.calibration import CalibrationError, CellCalibration
from puzzlebox.models.scene import ROBOT
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.reality import RealityProfile, load_profile

if TYPE_CHECKING:  # a real cell's types: the motion primitives (mink) are not imported to load a twin cell
    from puzzlebox.models.cell_config import CellConfig
    from puzzlebox.models.robot import Robot
    from puzzlebox.skills.primitives import PrimitiveConfig


class CellError(LabError, ValueError):
    """A reality profile or a calibration that cannot be loaded, or a calibration made in another cell."""


__all__ = ["CellError", "RealCell", "TwinCell", "check_twin_cameras", "load_cell", "profile_of_calibration"]


@dataclass(frozen=True)
class TwinCell:
    """The twin as a cell: a reality profile (its noise, calibration error, friction, jams, placement; its
    ``cell_seed`` fixes the cell's own imperfections) and the camera calibration made in it (None: the nominal,
    datasheet one — exact only under ``ideal``). :meth:`load` reads both from files and checks they agree."""

    profile: RealityProfile
    calibration: CellCalibration | None = None

    @classmethod
    def load(
        cls,
        reality: str | Path = "ideal",
        calibration: str | Path | None = None,
        specs: Mapping[str | Path, PuzzleSpec] | None = None,
    ) -> TwinCell:
        """The cell of the profile ``reality`` (a preset's name or a file) and the calibration file ``calibration``
        (:func:`load_cell`; ``specs`` are checked against the calibration's box height). Raises :class:`CellError`."""
        profile, loaded = load_cell(reality, calibration, specs or {})
        return cls(profile, loaded)


@dataclass(frozen=True)
class RealCell:
    """A real cell: ``robot`` (an arm behind the ``Robot`` protocol, e.g. ``puzzlebox.real.XArmRobot``, connected),
    its ``config`` (cameras, markers, force thresholds [N], rest posture [rad]: ``puzzlebox-cell/1``) and the
    camera ``calibration`` made in it; ``primitives`` overrides the motion primitives' config the cell config gives.
    There is no ground truth in a real cell: its trials record only what was sensed."""

    robot: Robot
    config: CellConfig
    calibration: CellCalibration
    primitives: PrimitiveConfig | None = None


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


TWIN_CAMERAS = {"overview": False, f"{ROBOT}gripper/wrist_camera": True}
"""The twin's cameras a calibration must calibrate, each with whether it rides on the arm."""


def check_twin_cameras(calibration: CellCalibration, source: str) -> None:
    """Refuse (:class:`CellError`, one line naming ``source``) a calibration that lacks a camera of the twin's
    cell or has it fixed where it rides on the arm (or the reverse): every run would fail on it, after the work."""
    missing = [name for name in TWIN_CAMERAS if name not in calibration.cameras]
    if missing:
        raise CellError(f"{source} does not calibrate the camera(s) {missing} of the cell (it calibrates "
                        f"{sorted(calibration.cameras)}): make one with scripts/calibrate.py")  # fmt: skip
    wrong = [name for name, on_arm in TWIN_CAMERAS.items() if calibration.cameras[name].on_arm != on_arm]
    if wrong:
        was = "fixed" if TWIN_CAMERAS[wrong[0]] else "on the arm"
        raise CellError(f"{source}: camera(s) {wrong} calibrated as {was}, but they are not: make one with "
                        "scripts/calibrate.py")  # fmt: skip


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
        check_twin_cameras(loaded, f"--calibration {calibration}")  # the cell's cameras, before any run
    return profile, loaded
