"""A cell's camera calibration: what the robot's pipeline knows of its cameras, and nothing more.

Perception never reads a camera's true intrinsics or pose (in the twin those carry the reality
profile's errors); it reads this file, which a calibration procedure made from images of a ChArUco
board (``scripts/calibrate.py``), as a real cell's would be.

Conventions: OpenCV's pinhole model and pixel convention (integer coordinates at pixel centres),
distortion ``[k1, k2, p1, p2, k3]``; camera frames are OpenCV's (x right, y down, z forward).
A fixed camera has ``T_base_camera``; a camera on the arm has ``T_tcp_camera`` (hand-eye), composed
at capture time with the TCP pose the arm reports.

A calibration belongs to one cell: :attr:`CellCalibration.cell` records the cell it was made for (in
the twin, the reality profile, its ``cell_seed`` and the box height, which sets where the overview
camera hangs) and :meth:`CellCalibration.check_cell` refuses to apply it to another.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.models.atomic import write_text_atomically
from puzzlebox.models.errors import ModelsError
from puzzlebox.models.json_input import JsonInputError, finite, parse_json, read_input_text

CALIBRATION_FORMAT = "puzzlebox-calibration/1"


class CalibrationError(ModelsError):
    """A calibration file that cannot be used, or a camera it does not calibrate."""


RIGID_TOLERANCE = 1e-4
"""Largest deviation of a pose's rotation from orthonormal (``|R^T R - I|``) and of its last row from
``[0, 0, 0, 1]`` a calibration file may have (files round to ~1e-15; a scaled rotation is off by 0.1 or more)."""
MAX_TRANSLATION_M = 10.0
"""Farthest a camera may be from the base or the TCP [m] (a cell is a metre or two across)."""
MAX_REPROJECTION_PX = 2.0
"""Largest RMS reprojection error of a usable intrinsic calibration [px] (the twin's: 0.06-0.08 px)."""
MAX_IMAGE_SIDE = 16384
"""Largest image side [px]."""
MAX_ASPECT = 1.5
"""Largest ratio of the two focal lengths (``fx / fy`` or ``fy / fx``): pixels are square to ~1 % on cameras of
this kind; a ratio past this is a mistyped matrix."""
RADIAL_SCALE = (0.5, 2.0)
"""Bounds of the radial distortion's factor ``1 + k1 r^2 + k2 r^4 + k3 r^6`` anywhere inside the image: wide lenses
shrink the corners by ~20-30 %; a factor of 1000 (``k1 = 1000``) would move every corner off the sensor."""
MAX_TANGENTIAL = 0.05
"""Largest tangential (decentring) coefficient ``|p1|``, ``|p2|`` (lenses: ~1e-3)."""
LENS_SAMPLES = 64
"""Radii sampled from the centre to the image's farthest corner for the distortion check."""


def _check_lens(K: np.ndarray, dist: np.ndarray, size: tuple[int, int]) -> None:
    """``K`` and ``dist`` describe a lens that maps the image (``size``, ``(width, height)`` [px]) onto itself: the
    principal point inside the image, square-ish pixels (:data:`MAX_ASPECT`), and a distortion that neither folds
    the image over (the distorted radius grows with the radius) nor scales any point of it past
    :data:`RADIAL_SCALE`, with small tangential terms. Only the reprojection error a procedure reports about itself
    was checked before: a distortion of 1000 passed and put every marker off where it stands."""
    fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    width, height = size
    if not (0.0 <= cx <= width and 0.0 <= cy <= height):
        raise CalibrationError(f"K's principal point ({cx:g}, {cy:g}) px lies outside the {width}x{height} image")
    if max(fx / fy, fy / fx) > MAX_ASPECT:
        raise CalibrationError(f"K's focal lengths fx = {fx:g} px and fy = {fy:g} px differ by more than "
                               f"{MAX_ASPECT:g}x (pixels are square)")  # fmt: skip
    k1, k2, p1, p2, k3 = (float(v) for v in dist)
    if max(abs(p1), abs(p2)) > MAX_TANGENTIAL:
        raise CalibrationError(f"dist's tangential terms p1 = {p1:g}, p2 = {p2:g} exceed {MAX_TANGENTIAL:g}")
    corner = math.hypot(max(cx, width - cx) / fx, max(cy, height - cy) / fy)  # normalised radius [-]
    r = np.linspace(0.0, corner, LENS_SAMPLES)
    factor = 1.0 + k1 * r**2 + k2 * r**4 + k3 * r**6
    low, high = RADIAL_SCALE
    folds = np.diff(r * factor) <= 0.0
    if factor.min() < low or factor.max() > high or folds.any():
        raise CalibrationError(
            f"dist's radial terms k1 = {k1:g}, k2 = {k2:g}, k3 = {k3:g} scale the image by {factor.min():.3g}-"
            f"{factor.max():.3g} out to its corners{' and fold it over' if folds.any() else ''} (a lens: "
            f"{low:g}-{high:g}, growing outwards)"
        )


def _check_rigid(T: np.ndarray, name: str) -> None:
    """``T`` is a rigid transform: a rotation (orthonormal, det +1), a bounded translation, the last row
    ``[0, 0, 0, 1]``. Anything else would aim the arm off where the camera saw a part."""
    R = T[:3, :3]
    off = float(np.abs(R.T @ R - np.eye(3)).max())
    if off > RIGID_TOLERANCE or np.linalg.det(R) < 0:
        what = "not orthonormal" if off > RIGID_TOLERANCE else "a reflection"
        raise CalibrationError(
            f"{name} is not a rigid transform: its rotation is {what} (|R^T R - I| = {off:.3g}, det "
            f"{np.linalg.det(R):.3g}); refused before the arm moves"
        )
    if float(np.abs(T[3] - (0.0, 0.0, 0.0, 1.0)).max()) > RIGID_TOLERANCE:
        raise CalibrationError(f"{name} is not a rigid transform: its last row is {T[3].tolist()}, not [0, 0, 0, 1]")
    if float(np.linalg.norm(T[:3, 3])) > MAX_TRANSLATION_M:
        raise CalibrationError(f"{name} puts the camera {np.linalg.norm(T[:3, 3]):.1f} m away (at most "
                               f"{MAX_TRANSLATION_M:g} m)")  # fmt: skip


@dataclass(frozen=True)
class CameraCalibration:
    """One camera's calibration (see the module docstring for conventions).

    Attributes:
        K: 3x3 intrinsics [px].
        dist: ``(5,)`` distortion ``[k1, k2, p1, p2, k3]``.
        image_size: ``(width, height)`` [px].
        T_base_camera: 4x4 pose of a fixed camera in the base frame [m], or None.
        T_tcp_camera: 4x4 pose of an arm camera in the TCP frame [m], or None.
        reprojection_error_px: RMS reprojection error of the intrinsic calibration [px].
        extra: figures of the procedure (pose errors, number of views, ...), for the record.
    """

    K: np.ndarray
    dist: np.ndarray
    image_size: tuple[int, int]
    T_base_camera: np.ndarray | None = None
    T_tcp_camera: np.ndarray | None = None
    reprojection_error_px: float = float("nan")
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        K = np.asarray(self.K, dtype=float)
        dist = np.asarray(self.dist, dtype=float).ravel()
        if K.shape != (3, 3) or not np.all(np.isfinite(K)) or K[0, 0] <= 0 or K[1, 1] <= 0:
            raise CalibrationError(f"K must be a finite 3x3 matrix with positive focal lengths, got {K.tolist()}")
        if dist.shape != (5,) or not np.all(np.isfinite(dist)):
            raise CalibrationError(f"dist must be 5 finite coefficients [k1, k2, p1, p2, k3], got {dist.tolist()}")
        if (self.T_base_camera is None) == (self.T_tcp_camera is None):
            raise CalibrationError("a camera is either fixed (T_base_camera) or on the arm (T_tcp_camera)")
        for name in ("T_base_camera", "T_tcp_camera"):
            T = getattr(self, name)
            if T is not None:
                T = np.asarray(T, dtype=float)
                if T.shape != (4, 4) or not np.all(np.isfinite(T)):
                    raise CalibrationError(f"{name} must be a finite 4x4 matrix")
                _check_rigid(T, name)
                object.__setattr__(self, name, T)
        size = self.image_size
        if (not isinstance(size, tuple | list) or len(size) != 2
                or not all(isinstance(v, int | np.integer) and not isinstance(v, bool) for v in size)
                or not all(0 < v <= MAX_IMAGE_SIDE for v in size)):  # fmt: skip
            raise CalibrationError(f"image_size must be two integers in [1, {MAX_IMAGE_SIDE}] px, got {size!r}")
        _check_lens(K, dist, (int(size[0]), int(size[1])))
        error = self.reprojection_error_px
        if not (math.isnan(error) or (math.isfinite(error) and 0 <= error <= MAX_REPROJECTION_PX)):
            raise CalibrationError(
                f"reprojection_error_px must be in [0, {MAX_REPROJECTION_PX}] px (a calibration worse than that "
                f"misplaces what the camera sees), got {error!r}"
            )
        object.__setattr__(self, "K", K)
        object.__setattr__(self, "dist", dist)
        object.__setattr__(self, "image_size", (int(self.image_size[0]), int(self.image_size[1])))

    @property
    def on_arm(self) -> bool:
        return self.T_tcp_camera is not None

    def pose_in_base(self, T_base_tcp: np.ndarray | None = None) -> np.ndarray:
        """The camera's pose in the base frame; an arm camera needs the TCP pose at capture [m]."""
        if self.T_base_camera is not None:
            return self.T_base_camera.copy()
        if T_base_tcp is None:
            raise CalibrationError("an arm camera's pose needs the TCP pose at capture")
        return np.asarray(T_base_tcp, dtype=float) @ self.T_tcp_camera

    def to_dict(self) -> dict[str, Any]:
        def listed(T: np.ndarray | None) -> list | None:
            return None if T is None else np.asarray(T).tolist()

        return {
            "K": self.K.tolist(),
            "dist": self.dist.tolist(),
            "image_size": list(self.image_size),
            "T_base_camera": listed(self.T_base_camera),
            "T_tcp_camera": listed(self.T_tcp_camera),
            "reprojection_error_px": None
            if math.isnan(self.reprojection_error_px)
            else float(self.reprojection_error_px),
            "extra": self.extra,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> CameraCalibration:
        known = {"K", "dist", "image_size", "T_base_camera", "T_tcp_camera", "reprojection_error_px", "extra"}
        if not isinstance(data, dict):
            raise CalibrationError(f"a camera's calibration must be an object with keys {sorted(known)}, got "
                                   f"{json.dumps(data)[:40]}")  # fmt: skip
        unknown = set(data) - known
        if unknown:
            raise CalibrationError(f"unknown camera calibration keys {sorted(unknown)}; known: {sorted(known)}")
        try:
            error = data.get("reprojection_error_px")
            return cls(
                K=np.array(data["K"], dtype=float),
                dist=np.array(data["dist"], dtype=float),
                image_size=tuple(data["image_size"]) if isinstance(data["image_size"], list) else data["image_size"],
                T_base_camera=None if data.get("T_base_camera") is None else np.array(data["T_base_camera"], float),
                T_tcp_camera=None if data.get("T_tcp_camera") is None else np.array(data["T_tcp_camera"], float),
                reprojection_error_px=float("nan") if error is None else float(error),
                extra=dict(data.get("extra", {})),
            )
        except (KeyError, TypeError, ValueError) as err:
            raise CalibrationError(f"bad camera calibration: {type(err).__name__}: {err}") from None


def _check_cell(cell: dict[str, Any]) -> None:
    """The cell a calibration records: a profile's name, a seed, a box height, each of its type and range."""
    if "profile" in cell and not isinstance(cell["profile"], str):
        raise CalibrationError(f"cell 'profile' must be a profile's name, got {cell['profile']!r}")
    seed = cell.get("cell_seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= 2**32 - 1:
        raise CalibrationError(f"cell 'cell_seed' must be an integer in [0, {2**32 - 1}], got {seed!r}")
    if "box_height" in cell and not (finite(cell["box_height"]) and 0 < cell["box_height"] < 10):
        raise CalibrationError(f"cell 'box_height' must be a finite height in (0, 10) m, got {cell['box_height']!r}")


CELL_KEYS = ("profile", "cell_seed", "box_height")
"""The keys of :attr:`CellCalibration.cell` that :meth:`CellCalibration.check_cell` compares."""

BOX_HEIGHT_TOLERANCE = 1e-6
"""Box heights closer than this [m] are the same cell (both come from a spec's JSON)."""


@dataclass(frozen=True)
class CellCalibration:
    """The calibration of every camera of a cell, by camera name."""

    cameras: dict[str, CameraCalibration]
    source: str = ""
    """How it was made (e.g. ``"charuco, profile realistic, cell seed 0"``), for the record."""
    cell: dict[str, Any] = field(default_factory=dict)
    """The cell it was made for: ``profile`` (reality profile name), ``cell_seed`` (seed of the cell's
    fixed imperfections), ``box_height`` [m] (the overview camera hangs at box height + 0.5 m,
    ``models.scene``), and anything else worth keeping (``spec``). Empty in files made before it existed."""

    def check_cell(self, profile: str, cell_seed: int, box_height: float, spec: str = "SPEC") -> None:
        """Refuse to apply this calibration to a cell other than the one it was made for.

        Args:
            profile: name of the reality profile of the cell it is to be used in.
            cell_seed: that profile's ``cell_seed``.
            box_height: height of that cell's box [m] (``spec.box.size[2]``).
            spec: the spec file to name in the remedy.

        Raises:
            CalibrationError: the file records no cell, or another one; one sentence naming what differs
                and the command that makes a matching file.
        """
        remedy = (
            f"make a matching file with `python scripts/calibrate.py --reality {profile} --cell-seed {cell_seed} "
            f"--spec {spec} --out FILE`"
        )
        missing = [key for key in CELL_KEYS if key not in self.cell]
        if missing:
            raise CalibrationError(
                f"this calibration does not record the cell it was made for (no {', '.join(missing)}), so it "
                f"cannot be checked against profile {profile!r}, cell seed {cell_seed}, box height "
                f"{box_height:.4f} m: {remedy}"
            )
        made = (self.cell["profile"], self.cell["cell_seed"], self.cell["box_height"])
        differs = []
        if str(made[0]) != profile:
            differs.append(f"profile {made[0]!r} instead of {profile!r}")
        if made[1] != cell_seed:
            differs.append(f"cell seed {made[1]} instead of {cell_seed}")
        if not isinstance(made[2], int | float) or abs(made[2] - box_height) > BOX_HEIGHT_TOLERANCE:
            differs.append(f"box height {made[2]} m instead of {box_height:.4f} m")
        if differs:
            raise CalibrationError(
                f"this calibration was made for another cell ({'; '.join(differs)}) and would misplace what "
                f"the cameras see: {remedy}"
            )

    def camera(self, name: str) -> CameraCalibration:
        try:
            return self.cameras[name]
        except KeyError:
            raise CalibrationError(
                f"camera {name!r} is not calibrated; calibrated cameras: {sorted(self.cameras)}"
            ) from None

    def to_dict(self) -> dict[str, Any]:
        return {
            "format": CALIBRATION_FORMAT,
            "source": self.source,
            "cell": self.cell,
            "cameras": {name: c.to_dict() for name, c in sorted(self.cameras.items())},
        }

    @classmethod
    def from_dict(cls, data: Any) -> CellCalibration:
        if not isinstance(data, dict) or data.get("format") != CALIBRATION_FORMAT:
            found = data.get("format") if isinstance(data, dict) else type(data).__name__
            raise CalibrationError(f"not a calibration file: format {found!r}, expected {CALIBRATION_FORMAT!r}")
        cameras = data.get("cameras")
        if not isinstance(cameras, dict) or not cameras:
            raise CalibrationError("a calibration file needs at least one camera under 'cameras'")
        cell = data.get("cell", {})
        if not isinstance(cell, dict):
            raise CalibrationError(f"'cell' must map names to values (profile, cell_seed, box_height), got {cell!r}")
        _check_cell(cell)
        checked = {}
        for name, camera in cameras.items():
            try:
                checked[str(name)] = CameraCalibration.from_dict(camera)
            except CalibrationError as err:
                raise CalibrationError(f"camera {name!r}: {err}") from None
        return cls(checked, str(data.get("source", "")), dict(cell))

    def save(self, path: str | Path) -> Path:
        return write_text_atomically(path, json.dumps(self.to_dict(), indent=1) + "\n")

    @classmethod
    def load(cls, path: str | Path) -> CellCalibration:
        try:
            text = read_input_text(path)
        except JsonInputError as err:
            raise CalibrationError(f"cannot read calibration {path}: {err}") from None
        try:
            data = parse_json(text)
        except JsonInputError as err:
            raise CalibrationError(f"calibration {path} is not JSON: {err}") from None
        try:
            return cls.from_dict(data)
        except CalibrationError as err:
            raise CalibrationError(f"calibration {path}: {err}") from None


__all__ = ["CALIBRATION_FORMAT", "CELL_KEYS", "CalibrationError", "CameraCalibration", "CellCalibration"]
