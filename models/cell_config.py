"""A cell's configuration: what a robot cell has and the pipeline needs to know of it, in one JSON file.

The file (format tag :data:`CELL_CONFIG_FORMAT`) is flat; every key is a field of :class:`CellConfig`::

    {"format": "puzzlebox-cell/1", "name": "lab-a",
     "camera_names": ["overview", "wrist"], "overview_camera": "overview", "wrist_camera": "wrist",
     "camera_devices": {"overview": 0, "wrist": "/dev/video2"},
     "aruco_dictionary": "DICT_4X4_250", "marker_size": 0.036,
     "force_limit": 60.0, "blocked_force": 20.0, "stop_force": 90.0,
     "gripper_open": 850.0, "gripper_closed": 0.0,
     "rest_posture": [-1.5708, -0.247, 0.0, 0.909, 0.0, 1.156, 0.0],
     "workspace_min": [-0.62, -0.62, 0.0], "workspace_max": [0.62, 0.62, 0.58],
     "ft_rate_hz": 100.0}

Which marker sits on which component is the puzzle spec's business; the cell fixes only the dictionary and
the printed marker size. Camera intrinsics and extrinsics are the calibration's (:mod:`models.calibration`).
Frames: the robot base frame (z up, origin at the base on the table top), as everywhere in the project.
"""

from __future__ import annotations

import json
import math
from dataclasses import MISSING, dataclass, field, fields
from pathlib import Path
from typing import Any

import cv2

from puzzlebox.models.atomic import write_text_atomically
from puzzlebox.models.errors import ModelsError
from puzzlebox.models.json_input import JsonInputError, read_json

CELL_CONFIG_FORMAT = "puzzlebox-cell/1"
STOP_FORCE_FACTOR = 1.5
"""A driver's hard stop, by default, over the skills' ``force_limit`` [-] (60 N: 90 N, within the xArm F/T's
150 N range)."""
EXAMPLE: dict = {
    "format": CELL_CONFIG_FORMAT,
    "name": "lab-a",
    "camera_names": ["overview", "wrist"],
    "overview_camera": "overview",
    "wrist_camera": "wrist",
    "camera_devices": {"overview": 0, "wrist": "/dev/video2"},
    "aruco_dictionary": "DICT_4X4_250",
    "marker_size": 0.036,
    "force_limit": 60.0,
    "blocked_force": 20.0,
    "stop_force": 90.0,
    "gripper_open": 850.0,
    "gripper_closed": 0.0,
    "rest_posture": [-1.5708, -0.247, 0.0, 0.909, 0.0, 1.156, 0.0],
    "workspace_min": [-0.62, -0.62, 0.0],
    "workspace_max": [0.62, 0.62, 0.58],
    "ft_rate_hz": 100.0,
}
"""The module docstring's example file, as data: a start for a real cell's own (``CellConfig.from_dict``)."""


class CellConfigError(ModelsError):
    """A cell config that cannot be used; :attr:`problems` lists every problem found, not only the first."""

    def __init__(self, problems: list[str], source: str | None = None) -> None:
        self.problems = tuple(problems)
        self.source = source
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"invalid cell config{f' {source}' if source else ''} ({len(problems)} problem(s)):\n{lines}")


def aruco_dictionary_names() -> tuple[str, ...]:
    """Names of OpenCV's predefined ArUco dictionaries (``cv2.aruco.DICT_*``)."""
    return tuple(sorted(n for n in dir(cv2.aruco) if n.startswith("DICT_") and isinstance(getattr(cv2.aruco, n), int)))


def aruco_dictionary_name(dictionary: int) -> str:
    """The ``DICT_*`` name of an OpenCV dictionary constant (e.g. ``cv2.aruco.DICT_4X4_250``)."""
    for name in aruco_dictionary_names():
        if getattr(cv2.aruco, name) == dictionary:
            return name
    raise CellConfigError([f"aruco_dictionary: {dictionary!r} is no cv2.aruco.DICT_* constant"])


@dataclass(frozen=True)
class CellConfig:
    """What a cell has (see the module docstring). Construction validates: every problem in one
    :class:`CellConfigError`."""

    name: str
    """The cell's name (e.g. ``twin-ideal`` or ``lab-a``)."""
    camera_names: tuple[str, ...]
    """Every camera of the cell (:attr:`models.robot.Robot.camera_names`)."""
    overview_camera: str
    """The fixed camera that looks down on the workspace (one of ``camera_names``)."""
    wrist_camera: str
    """The camera on the gripper (one of ``camera_names``)."""
    aruco_dictionary: str
    """OpenCV's name of the markers' ArUco dictionary (``DICT_4X4_250``: ``cv2.aruco.DICT_4X4_250``)."""
    marker_size: float
    """Side of a marker's black square [m]."""
    force_limit: float
    """Safety limit on the wrist force magnitude: the arm is stopped above it [N]."""
    blocked_force: float
    """Force opposing a motion that, with little progress, means the part is blocked (a latch) [N]."""
    gripper_open: float
    """Gripper command for fully open, in the gripper driver's own units (twin: ctrl 0; xArm Gripper: 850)."""
    gripper_closed: float
    """Gripper command for fully closed, in the same units (twin: ctrl 255; xArm Gripper: 0)."""
    rest_posture: tuple[float, ...]
    """The rest (home) arm posture, joints 1..7 [rad]: out of the overview camera's view."""
    workspace_min: tuple[float, float, float]
    """Lower corner of the box the TCP must stay in, base frame [m]."""
    workspace_max: tuple[float, float, float]
    """Upper corner of that box, base frame [m]."""
    ft_rate_hz: float
    """Rate at which the wrist F/T sensor delivers new readings [Hz]."""
    camera_devices: dict[str, int | str] = field(default_factory=dict)
    """OpenCV capture device of each camera of a real cell (an index or a device path); empty in the twin."""
    stop_force: float | None = None
    """Wrist force magnitude at which a real arm's driver stops the arm (emergency stop) on any raw reading [N];
    None: :data:`STOP_FORCE_FACTOR` times ``force_limit``. Above ``force_limit``, where the skills end a try on
    a filtered reading: at the same value a raw impact would stop the whole trial where the skills end a try."""

    @property
    def hard_stop_force(self) -> float:
        """The force at which a driver stops the arm [N] (:attr:`stop_force`, or its default)."""
        return self.stop_force if self.stop_force is not None else STOP_FORCE_FACTOR * self.force_limit

    def __post_init__(self) -> None:
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        problems = _normalise(values)
        problems += _check(values)
        if problems:
            raise CellConfigError(problems)
        for name, value in values.items():
            object.__setattr__(self, name, value)

    def gripper_command(self, closure: float) -> float:
        """The gripper command for a closure 0 (open) .. 1 (closed), in the driver's units."""
        return self.gripper_open + closure * (self.gripper_closed - self.gripper_open)

    def gripper_closure(self, command: float) -> float:
        """The closure 0 (open) .. 1 (closed) of a gripper position in the driver's units (clipped)."""
        closure = (command - self.gripper_open) / (self.gripper_closed - self.gripper_open)
        return min(max(closure, 0.0), 1.0)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"format": CELL_CONFIG_FORMAT}
        for f in fields(self):
            value = getattr(self, f.name)
            out[f.name] = list(value) if isinstance(value, tuple) else value
        out["camera_devices"] = dict(self.camera_devices)
        return out

    @classmethod
    def from_dict(cls, data: Any, source: str | None = None) -> CellConfig:
        """Parse a config's JSON object; every problem (format, unknown or missing keys, bad values) in one
        :class:`CellConfigError`."""
        if not isinstance(data, dict):
            raise CellConfigError([f"expected a JSON object, got {type(data).__name__}"], source)
        known = [f.name for f in fields(cls)]
        problems = []
        if data.get("format") != CELL_CONFIG_FORMAT:
            problems.append(f"format: expected {CELL_CONFIG_FORMAT!r}, got {data.get('format')!r}")
        unknown = sorted(set(data) - set(known) - {"format"})
        if unknown:
            problems.append(f"unknown key(s) {unknown}; known keys: {['format', *known]}")
        optional = {f.name for f in fields(cls) if f.default_factory is not MISSING or f.default is not MISSING}
        missing = [k for k in known if k not in data and k not in optional]
        if missing:
            problems.append(f"missing key(s) {missing}")
        values = {k: data[k] for k in known if k in data}
        problems += _normalise(values) + _check(values)
        if problems:
            raise CellConfigError(problems, source)
        return cls(**values)


def load_cell_config(path: str | Path) -> CellConfig:
    """Read and validate a cell config file (:class:`CellConfigError` lists every problem)."""
    path = Path(path)
    if not path.exists():
        raise CellConfigError([f"no such file: {path}"], str(path))
    try:
        data = read_json(path, allow_non_finite=True)  # every field's finiteness is one of the listed problems
    except JsonInputError as err:
        raise CellConfigError([f"not a readable JSON file: {err}"], str(path)) from None
    return CellConfig.from_dict(data, source=str(path))


def save_cell_config(config: CellConfig, path: str | Path) -> Path:
    """Write ``config`` to ``path`` atomically (a crash never leaves half a file)."""
    return write_text_atomically(path, json.dumps(config.to_dict(), indent=2) + "\n")


# -- validation ------------------------------------------------------------------------------------
_VECTORS = {"rest_posture": 7, "workspace_min": 3, "workspace_max": 3}
_NUMBERS = (
    "marker_size", "force_limit", "blocked_force", "gripper_open", "gripper_closed", "ft_rate_hz", "stop_force",
)  # fmt: skip
_NAMES = ("name", "overview_camera", "wrist_camera", "aruco_dictionary")


def _finite(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _normalise(values: dict[str, Any]) -> list[str]:
    """Coerce the values present to their field types in place; a value that cannot be is dropped and named."""
    problems = []
    for key in _NAMES:
        if key in values and not (isinstance(values[key], str) and values[key]):
            problems.append(f"{key}: expected a non-empty string, got {values.pop(key)!r}")
    if values.get("stop_force", 0.0) is None:
        values.pop("stop_force")  # optional: None is its default
    for key in _NUMBERS:
        if key in values:
            if _finite(values[key]):
                values[key] = float(values[key])
            else:
                problems.append(f"{key}: expected a finite number, got {values.pop(key)!r}")
    for key, n in _VECTORS.items():
        if key in values:
            v = values[key]
            if isinstance(v, list | tuple) and len(v) == n and all(_finite(x) for x in v):
                values[key] = tuple(float(x) for x in v)
            else:
                problems.append(f"{key}: expected {n} finite numbers, got {values.pop(key)!r}")
    if "camera_names" in values:
        v = values["camera_names"]
        if isinstance(v, list | tuple) and v and all(isinstance(x, str) and x for x in v):
            values["camera_names"] = tuple(v)
        else:
            problems.append(f"camera_names: expected a non-empty list of names, got {values.pop('camera_names')!r}")
    if "camera_devices" in values:
        v = values["camera_devices"]
        ok = isinstance(v, dict) and all(
            (isinstance(d, int) and not isinstance(d, bool) and d >= 0) or (isinstance(d, str) and d)
            for d in v.values()
        )
        if ok:
            values["camera_devices"] = dict(v)
        else:
            problems.append(
                "camera_devices: expected {camera: capture index >= 0 or device path}, "
                f"got {values.pop('camera_devices')!r}"
            )
    return problems


def _check(v: dict[str, Any]) -> list[str]:
    """Problems of the relations between the (normalised) values present."""
    problems = []
    cameras = v.get("camera_names")
    if cameras is not None:
        if len(set(cameras)) != len(cameras):
            problems.append(f"camera_names: names repeat in {list(cameras)}")
        for key in ("overview_camera", "wrist_camera"):
            if key in v and v[key] not in cameras:
                problems.append(f"{key}: {v[key]!r} is not a camera of the cell; cameras: {list(cameras)}")
        for name in v.get("camera_devices", {}):
            if name not in cameras:
                problems.append(f"camera_devices: {name!r} is not a camera of the cell; cameras: {list(cameras)}")
    if "overview_camera" in v and v.get("overview_camera") == v.get("wrist_camera"):
        problems.append(f"overview_camera and wrist_camera are the same camera {v['wrist_camera']!r}")
    if "aruco_dictionary" in v and v["aruco_dictionary"] not in aruco_dictionary_names():
        problems.append(
            f"aruco_dictionary: {v['aruco_dictionary']!r} is no OpenCV dictionary; "
            f"known: {list(aruco_dictionary_names())}"
        )
    for key in ("marker_size", "ft_rate_hz", "blocked_force"):
        if key in v and v[key] <= 0.0:
            problems.append(f"{key}: must be > 0, got {v[key]}")
    if "force_limit" in v and "blocked_force" in v and v["force_limit"] <= v["blocked_force"]:
        problems.append(
            f"force_limit ({v['force_limit']} N) must exceed blocked_force ({v['blocked_force']} N): a latch must be "
            "felt before the arm is stopped"
        )
    if v.get("stop_force") is not None and "force_limit" in v and v["stop_force"] <= v["force_limit"]:
        problems.append(
            f"stop_force ({v['stop_force']} N) must exceed force_limit ({v['force_limit']} N): the skills end a try "
            "before the driver stops the arm"
        )
    if "gripper_open" in v and v.get("gripper_open") == v.get("gripper_closed"):
        problems.append(f"gripper_open and gripper_closed must differ, both are {v['gripper_open']}")
    if "workspace_min" in v and "workspace_max" in v:
        low, high = v["workspace_min"], v["workspace_max"]
        if not all(a < b for a, b in zip(low, high, strict=True)):
            problems.append(f"workspace_min {list(low)} must be below workspace_max {list(high)} on every axis [m]")
    return problems


__all__ = [
    "CELL_CONFIG_FORMAT",
    "STOP_FORCE_FACTOR",
    "CellConfig",
    "CellConfigError",
    "aruco_dictionary_name",
    "aruco_dictionary_names",
    "load_cell_config",
    "save_cell_config",
]
