"""Puzzle spec v1: the dataclasses of a puzzle and their JSON form (the contract in SPEC.md).

A spec is immutable. Reading one is :mod:`models.spec_loading`'s (``load_spec`` / ``spec_from_json`` validate the
whole file first and raise :class:`~models.errors.SpecError` listing every problem, so an invalid file is never
half-loaded); :func:`save_spec` writes one.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.models.atomic import write_text_atomically
from puzzlebox.models.disassembly_kinds import DISASSEMBLY_FAMILY, DISASSEMBLY_KINDS, PUZZLE_BOX_FAMILY
from puzzlebox.models.geometry import compose, wrap_angle

SPEC_FORMAT = "puzzlebox-spec/1"
"""The only value of the ``format`` field this version reads and writes."""

_DECIMALS = 6  # poses and sizes are written to the micrometre / microradian


@dataclass(frozen=True)
class Box:
    """The puzzle box.

    Attributes:
        size: lid length (x), lid width (y), box height (z) [m].
        pose: where the box centre stands on the table in the robot base frame ``[x, y, yaw]``
            [m, m, rad]; ``None`` lets the twin pick a reachable default.
    """

    size: tuple[float, float, float]
    pose: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class Component:
    """One movable component.

    Attributes:
        name: unique within the spec; carries no meaning to the agent.
        kind: a kind name (``door``, ``slide``, ``wheel`` for puzzle boxes).
        pose: the component frame in the lid frame, ``[x, y, yaw]`` [m, m, rad] (planar kinds) or
            ``[x, y, z, roll, pitch, yaw]`` (3-D domains). See :mod:`models.kinds` for each frame.
        marker: ArUco id (unique within the spec).
    """

    name: str
    kind: str
    pose: tuple[float, ...]
    marker: int


@dataclass(frozen=True)
class LockRule:
    """While ``locker`` is in ``locker_state``, ``locked`` cannot leave ``locked_state``."""

    locker: str
    locker_state: int
    locked: str
    locked_state: int


@dataclass(frozen=True)
class Goal:
    """The puzzle is solved when ``component`` reaches ``state``."""

    component: str
    state: int = 1


@dataclass(frozen=True)
class PuzzleSpec:
    """A whole puzzle: components, lock rules, goal and (for puzzle boxes) the box."""

    name: str
    components: tuple[Component, ...]
    locks: tuple[LockRule, ...]
    goal: Goal
    box: Box | None = None

    @property
    def component_names(self) -> tuple[str, ...]:
        return tuple(c.name for c in self.components)

    @property
    def kinds(self) -> tuple[str, ...]:
        return tuple(c.kind for c in self.components)

    @property
    def family(self) -> str:
        """The spec's kind family: ``"disassembly"`` for a disassembly scene (no box, disassembly kinds,
        6-DOF poses), else ``"puzzle-box"`` (see :mod:`models.disassembly_kinds`)."""
        if self.box is None and any(k in DISASSEMBLY_KINDS for k in self.kinds):
            return DISASSEMBLY_FAMILY
        return PUZZLE_BOX_FAMILY

    def index_of(self, name: str) -> int:
        """Index of a component in :attr:`components`; ``KeyError`` lists the names that exist."""
        for i, c in enumerate(self.components):
            if c.name == name:
                return i
        raise KeyError(f"no component named {name!r}. Components: {list(self.component_names)}")

    def poses_in_world(self) -> np.ndarray:
        """Component poses in the world (robot base) frame, ``(N, D)``: each planar lid-frame pose
        composed with ``box.pose`` (identity when absent) and its yaw wrapped to [-pi, pi);
        6-D poses of 3-D domains are taken as given."""
        box_pose = self.box.pose if self.box is not None and self.box.pose is not None else (0.0, 0.0, 0.0)
        poses = []
        for c in self.components:
            if len(c.pose) == 3:
                poses.append(compose(box_pose, c.pose))  # type: ignore[arg-type]
            else:
                poses.append((*c.pose[:5], wrap_angle(c.pose[5])))
        return np.array(poses, dtype=np.float64)

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of SPEC.md, keys in the documented order."""
        out: dict[str, Any] = {"format": SPEC_FORMAT, "name": self.name}
        if self.box is not None:
            box: dict[str, Any] = {"size": _rounded(self.box.size)}
            if self.box.pose is not None:
                box["pose"] = _rounded(self.box.pose)
            out["box"] = box
        out["components"] = [
            {"name": c.name, "kind": c.kind, "pose": _rounded(c.pose), "marker": c.marker} for c in self.components
        ]
        out["locks"] = [
            {
                "locker": r.locker,
                "locker_state": r.locker_state,
                "locked": r.locked,
                "locked_state": r.locked_state,
            }
            for r in self.locks
        ]
        out["goal"] = {"component": self.goal.component, "state": self.goal.state}
        return out

    def to_json(self) -> str:
        """Deterministic JSON text: the same spec always gives byte-identical output."""
        return dumps_compact(self.to_dict())


def _rounded(values: tuple[float, ...]) -> list[float]:
    # +0.0 turns a rounded -0.0 into 0.0 so equal specs print equally
    return [round(float(v), _DECIMALS) + 0.0 for v in values]


def file_precision(values: tuple[float, ...]) -> tuple[float, ...]:
    """``values`` as a spec file stores them (micrometres / microradians), so that a generated spec
    equals the spec read back from its file."""
    return tuple(_rounded(values))


def dumps_compact(obj: Any) -> str:
    """JSON with 2-space indentation but lists of scalars kept on one line (poses read as rows)."""
    return _encode(obj, 0) + "\n"


def _is_flat(value: Any) -> bool:
    """A scalar or a list of scalars."""
    if isinstance(value, list | tuple):
        return all(not isinstance(v, dict | list | tuple) for v in value)
    return not isinstance(value, dict)


def _encode(obj: Any, depth: int) -> str:
    pad, inner = "  " * depth, "  " * (depth + 1)
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        if depth > 0 and all(_is_flat(v) for v in obj.values()):
            return (
                "{"
                + ", ".join(f"{json.dumps(str(k), ensure_ascii=False)}: {_encode(v, depth)}" for k, v in obj.items())
                + "}"
            )
        items = [f"{inner}{json.dumps(str(k), ensure_ascii=False)}: {_encode(v, depth + 1)}" for k, v in obj.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, list | tuple):
        if all(not isinstance(v, dict | list | tuple) for v in obj):
            return "[" + ", ".join(_encode(v, depth) for v in obj) + "]"
        return "[\n" + ",\n".join(inner + _encode(v, depth + 1) for v in obj) + "\n" + pad + "]"
    return json.dumps(obj, ensure_ascii=False, allow_nan=False)


def save_spec(spec: PuzzleSpec, path: str | Path) -> Path:
    """Write a spec as JSON (atomically: a crash never leaves a half-written file)."""
    return write_text_atomically(path, spec.to_json())


def build_from_valid_data(data: dict[str, Any]) -> PuzzleSpec:
    """Build a spec from data that passed :func:`~models.validation.validate_data` (no checks here);
    assigns missing marker ids."""
    raw_components = data["components"]
    used = {c["marker"] for c in raw_components if c.get("marker") is not None}
    free = (i for i in range(len(raw_components) + len(used) + 1) if i not in used)
    components = []
    for c in raw_components:
        marker = c.get("marker")
        components.append(
            Component(
                name=c["name"],
                kind=c["kind"],
                pose=tuple(float(v) for v in c["pose"]),
                marker=int(marker) if marker is not None else next(free),
            )
        )
    locks = tuple(
        LockRule(r["locker"], int(r["locker_state"]), r["locked"], int(r["locked_state"])) for r in data["locks"]
    )
    goal = Goal(data["goal"]["component"], int(data["goal"].get("state", 1)))
    box = None
    if data.get("box") is not None:
        raw_pose = data["box"].get("pose")
        box = Box(
            size=tuple(float(v) for v in data["box"]["size"]),  # type: ignore[arg-type]
            pose=tuple(float(v) for v in raw_pose) if raw_pose is not None else None,  # type: ignore[arg-type]
        )
    return PuzzleSpec(name=data["name"], components=tuple(components), locks=locks, goal=goal, box=box)
