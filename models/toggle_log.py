"""A toggle as the robot logged it: what a system identification of the box fits the twin to.

Robot data only (DESIGN.md, "The seams"): at every 10 ms control tick of a toggle, the time, the measured arm
joint positions, the gripper closure, the TCP pose the arm's kinematics report from them, the wrench the wrist
sensor gave (turned into the base frame with the orientation the kinematics report), the last joint and gripper
commands the pipeline sent, and what the primitive was doing; per toggle, the component's marker and told kind,
where the robot perceived the component and the joint it derived from that (``skills.joint_model``), and how
the toggle ended. Nothing of the simulator's truth is in the fields a fit reads; an evaluator may keep
the truth in :attr:`ToggleLog.truth`, which no fit reads.

Frames and units: the robot base frame (= the twin's world frame); metres, radians, seconds, newtons,
newton-metres. The wrench is the load on the flange (what the gripper exerts on it), tared by the primitive
above the part with the fingers open, as the primitive reads it (one reading per tick, unfiltered).

A file of toggles (:func:`save_toggles`, :func:`load_toggles`) is one ``.npz``: a JSON header (each toggle's
scalars, and the file's context) and each toggle's arrays, written atomically.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.models.npz_file import load_header, save_npz

PHASES: tuple[str, ...] = ("moving", "approaching", "descending", "grasping", "actuating", "retreating")
"""What the primitive may be doing at a tick (``skills.primitives.Toggler.phase``); a log stores the index."""
FORMAT = "puzzlebox-toggle-log/1"
ARRAYS = ("time", "joints", "closure", "tcp", "force", "torque", "joint_command", "gripper_command", "phase")
"""The per-tick arrays of a toggle, in the order they are stored."""


@dataclass
class ToggleLog:
    """One toggle (one call of the toggle primitive) as the robot logged it (see the module docstring)."""

    component: str
    """The component's name as the log's writer knows it (the marker's label; bookkeeping, never fitted on)."""
    marker: int
    """The component's ArUco marker id."""
    kind: str
    """The component's kind as the robot was told it."""
    joint: str
    """Perceived joint type, ``hinge`` or ``slide``."""
    axis: np.ndarray
    """Perceived unit joint axis (positive motion opens) [-]."""
    origin: np.ndarray
    """A point on the perceived joint axis (a slide: its grasp point closed) [m]."""
    grasp_point: np.ndarray
    """Where the fingers close on the handle with the component closed, as perceived [m]."""
    pose: np.ndarray
    """``(4, 4)`` perceived component frame (its marker frame with the part closed, upright) in the base frame [m]."""
    travel: float
    """Motion from closed to open [rad or m]."""
    opening: bool
    """The toggle tried to open the component (else to close it)."""
    outcome: str
    """``moved``, ``blocked`` or ``failed``, as the primitive sensed it."""
    reason: str
    progress: float
    """Measured fraction of the travel covered, from the TCP [-]."""
    time: np.ndarray
    """``(n,)`` robot time of each tick [s]."""
    joints: np.ndarray
    """``(n, 7)`` measured arm joint positions [rad]."""
    closure: np.ndarray
    """``(n,)`` gripper closure, 0 open .. 1 closed [-]."""
    tcp: np.ndarray
    """``(n, 4, 4)`` TCP pose in the base frame from the measured joints [m]."""
    force: np.ndarray
    """``(n, 3)`` sensed force on the flange in the base frame, tared [N]."""
    torque: np.ndarray
    """``(n, 3)`` sensed torque on the flange about the F/T sensor's origin, in the base frame, tared [N·m]."""
    joint_command: np.ndarray
    """``(n, 7)`` the last arm joint targets sent before the tick's reading [rad] (NaN before any)."""
    gripper_command: np.ndarray
    """``(n,)`` the last gripper target sent before the tick's reading, 0 open .. 1 closed [-] (NaN before any)."""
    phase: np.ndarray
    """``(n,)`` index in :data:`PHASES` of what the primitive was doing at each tick."""
    context: dict[str, Any] = field(default_factory=dict)
    """Where the toggle was made (box name, trial seed, profile name, action number): bookkeeping."""
    truth: dict[str, Any] | None = None
    """Evaluation only, never read by a fit: what the simulator knew (e.g. the cell's true factors)."""

    def __post_init__(self) -> None:
        n = len(self.time)
        shapes = {
            "joints": (n, 7), "closure": (n,), "tcp": (n, 4, 4), "force": (n, 3), "torque": (n, 3),
            "joint_command": (n, 7), "gripper_command": (n,), "phase": (n,), "pose": (4, 4),
        }  # fmt: skip
        for name, shape in shapes.items():
            value = np.asarray(getattr(self, name))
            if value.shape != shape:
                raise ValueError(f"toggle log field {name!r}: expected shape {shape}, got {value.shape}")

    @property
    def ticks(self) -> int:
        return len(self.time)

    def in_phase(self, name: str) -> np.ndarray:
        """Boolean mask of the ticks spent in phase ``name`` (one of :data:`PHASES`)."""
        return self.phase == PHASES.index(name)

    def header(self) -> dict[str, Any]:
        """The toggle's scalars, JSON-ready."""
        return {
            "component": self.component, "marker": self.marker, "kind": self.kind, "joint": self.joint,
            "axis": self.axis.tolist(), "origin": self.origin.tolist(), "grasp_point": self.grasp_point.tolist(),
            "pose": self.pose.tolist(), "travel": self.travel, "opening": self.opening, "outcome": self.outcome,
            "reason": self.reason,
            "progress": self.progress, "context": self.context, "truth": self.truth,
        }  # fmt: skip


def save_toggles(path: str | Path, toggles: list[ToggleLog], context: dict[str, Any] | None = None) -> Path:
    """Write ``toggles`` (and the file's ``context``) to ``path`` (``.npz``) atomically."""
    header = {"format": FORMAT, "context": context or {}, "toggles": [t.header() for t in toggles]}
    arrays: dict[str, np.ndarray] = {}
    for i, t in enumerate(toggles):
        for name in ARRAYS:
            value = np.asarray(getattr(t, name))
            arrays[f"{i}.{name}"] = value.astype(np.int8 if name == "phase" else np.float64)
    return save_npz(path, header, arrays)


def load_toggles(path: str | Path) -> tuple[list[ToggleLog], dict[str, Any]]:
    """The toggles and the context of a file :func:`save_toggles` wrote.

    Raises:
        ValueError: not such a file (its format is named).
    """
    with np.load(path) as data:
        header = load_header(data, path, FORMAT, "a toggle log")
        toggles = []
        for i, h in enumerate(header["toggles"]):
            arrays = {name: np.array(data[f"{i}.{name}"]) for name in ARRAYS}
            arrays["phase"] = arrays["phase"].astype(np.int64)
            toggles.append(ToggleLog(
                component=h["component"], marker=h["marker"], kind=h["kind"], joint=h["joint"],
                axis=np.array(h["axis"]), origin=np.array(h["origin"]), grasp_point=np.array(h["grasp_point"]),
                pose=np.array(h["pose"]), travel=h["travel"], opening=h["opening"], outcome=h["outcome"],
                reason=h["reason"],
                progress=h["progress"], context=h["context"], truth=h["truth"], **arrays,
            ))  # fmt: skip
    return toggles, header["context"]


__all__ = ["ARRAYS", "FORMAT", "PHASES", "ToggleLog", "load_toggles", "save_toggles"]
