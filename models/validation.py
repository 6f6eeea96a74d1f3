"""Validation of puzzle spec files: every problem at once, each naming the field or component.

:func:`validate_data` takes the parsed JSON value (anything ``json.loads`` may return) and never
raises on bad input: it returns the list of problems, empty for a valid spec.
"""

from __future__ import annotations

import math
from typing import Any

from models.errors import ReachabilityUndecided, SpecProblem
from models.geometry import polygon_gap
from models.kinds import KIND_NAMES, PUZZLE_KINDS, get_kind
from models.lock_table import LockTable
from models.markers import MAX_MARKER_ID
from models.spec import SPEC_FORMAT, build_from_valid_data

MAX_COMPONENTS = 62
"""Symbolic states are 64-bit bitmasks; more components than this cannot be represented."""
OVERLAP_TOLERANCE = 1e-6
"""Footprints may touch; they overlap when they interpenetrate by more than this [m]."""
INSIDE_TOLERANCE = 1e-6
"""A footprint may reach the lid edge up to this much beyond it [m] (rounding in files)."""


MAX_MAGNITUDE = 1000.0
"""Largest magnitude accepted for any pose or size entry [m or rad]: beyond it geometry overflows."""


def _is_number(value: Any) -> bool:
    return (
        isinstance(value, int | float)
        and not isinstance(value, bool)
        and math.isfinite(value)
        and abs(value) <= MAX_MAGNITUDE
    )


def _is_state(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value in (0, 1)


def _number_list(value: Any, lengths: tuple[int, ...]) -> bool:
    return isinstance(value, list) and len(value) in lengths and all(_is_number(v) for v in value)


def validate_data(data: Any) -> list[SpecProblem]:
    """All problems of a parsed spec; an empty list means valid."""
    problems: list[SpecProblem] = []

    def problem(where: str, message: str) -> None:
        problems.append(SpecProblem(where, message))

    if not isinstance(data, dict):
        problem("file", f"top level must be a JSON object, got {type(data).__name__}")
        return problems

    if "format" not in data:
        problem("format", f"missing; must be {SPEC_FORMAT!r}")
    elif data["format"] != SPEC_FORMAT:
        problem("format", f"unsupported format {data['format']!r}; this version reads {SPEC_FORMAT!r}")

    if not isinstance(data.get("name"), str):
        problem("name", "missing or not a string")

    components = data.get("components")
    valid_components: dict[str, dict[str, Any]] = {}  # name -> component, for components without problems
    names: set[str] = set()
    if not isinstance(components, list) or not components:
        problem("components", "missing or not a non-empty list")
        components = []
    elif len(components) > MAX_COMPONENTS:
        problem("components", f"{len(components)} components; at most {MAX_COMPONENTS} are supported")
    markers: dict[int, str] = {}
    for k, comp in enumerate(components):
        where = f"components[{k}]"
        if not isinstance(comp, dict):
            problem(where, "must be an object with name, kind and pose")
            continue
        ok = True
        name = comp.get("name")
        if not isinstance(name, str) or not name:
            problem(f"{where}.name", "missing or not a non-empty string")
            ok = False
        else:
            where = f"component {name!r}"
            if name in names:
                problem(where, f"duplicate name {name!r} (names must be unique)")
                ok = False
            names.add(name)
        kind = comp.get("kind")
        if not isinstance(kind, str):
            problem(f"{where}.kind", f"missing or not a string; known kinds: {list(KIND_NAMES)}")
            ok = False
        elif kind not in KIND_NAMES:
            problem(f"{where}.kind", f"unknown kind {kind!r}; known kinds: {list(KIND_NAMES)}")
            ok = False
        pose_lengths = (3,) if isinstance(kind, str) and kind in PUZZLE_KINDS else (3, 6)
        if not _number_list(comp.get("pose"), pose_lengths):
            shape = " or ".join(str(n) for n in pose_lengths)
            problem(f"{where}.pose", f"must be a list of {shape} finite numbers within +-{MAX_MAGNITUDE:g} [m, rad]")
            ok = False
        marker = comp.get("marker")
        if marker is not None:
            if not isinstance(marker, int) or isinstance(marker, bool) or marker < 0:
                problem(f"{where}.marker", f"must be a non-negative integer ArUco id, got {marker!r}")
                ok = False
            elif marker > MAX_MARKER_ID:
                problem(
                    f"{where}.marker",
                    f"ArUco id {marker} is outside the project's dictionary (DICT_4X4_250: ids 0..{MAX_MARKER_ID}); "
                    "the twin cannot render it nor the camera read it",
                )
                ok = False
            elif marker in markers:
                problem(f"{where}.marker", f"ArUco id {marker} already used by component {markers[marker]!r}")
                ok = False
            else:
                markers[marker] = name if isinstance(name, str) else where
        if ok:
            valid_components[name] = comp

    locks = data.get("locks")
    valid_locks: list[dict[str, Any]] = []
    if not isinstance(locks, list):
        problem("locks", "missing or not a list (use [] for a puzzle without locks)")
        locks = []
    seen_locks: dict[tuple[Any, ...], int] = {}
    for k, rule in enumerate(locks):
        where = f"locks[{k}]"
        if not isinstance(rule, dict):
            problem(where, "must be an object with locker, locker_state, locked, locked_state")
            continue
        ok = True
        for field in ("locker", "locked"):
            ref = rule.get(field)
            if not isinstance(ref, str):
                problem(f"{where}.{field}", "missing or not a component name")
                ok = False
            elif ref not in names:
                problem(f"{where}.{field}", f"unknown component {ref!r}; components: {sorted(names)}")
                ok = False
        for field in ("locker_state", "locked_state"):
            if not _is_state(rule.get(field)):
                problem(f"{where}.{field}", f"must be 0 or 1, got {rule.get(field)!r}")
                ok = False
        if isinstance(rule.get("locker"), str) and rule.get("locker") == rule.get("locked"):
            problem(where, f"component {rule['locker']!r} locks itself")
            ok = False
        if ok:
            key = (rule["locker"], rule["locker_state"], rule["locked"], rule["locked_state"])
            if key in seen_locks:
                problem(where, f"duplicates locks[{seen_locks[key]}] ({key[0]} in {key[1]} holds {key[2]} in {key[3]})")
                continue
            seen_locks[key] = k
            valid_locks.append(rule)

    goal = data.get("goal")
    goal_ok = False
    if not isinstance(goal, dict):
        problem("goal", "missing or not an object with a component")
    else:
        target = goal.get("component")
        if not isinstance(target, str):
            problem("goal.component", "missing or not a component name")
        elif target not in names:
            problem("goal.component", f"unknown component {target!r}; components: {sorted(names)}")
        else:
            goal_ok = True
        if "state" in goal and not _is_state(goal["state"]):
            problem("goal.state", f"must be 0 or 1, got {goal['state']!r}")
            goal_ok = False

    problems.extend(_check_geometry(data, valid_components))

    structural_ok = not problems
    if structural_ok and goal_ok:
        problems.extend(_check_reachable(data))
    return problems


def _check_geometry(data: dict[str, Any], components: dict[str, dict[str, Any]]) -> list[SpecProblem]:
    problems: list[SpecProblem] = []
    box_kinds = [c for c in components.values() if c["kind"] in PUZZLE_KINDS]
    box = data.get("box")
    if box is None:
        if box_kinds:
            problems.append(SpecProblem("box", "missing; required for puzzle boxes (door/slide/wheel)"))
        return problems
    if not isinstance(box, dict):
        return [SpecProblem("box", "must be an object with size (and optional pose)")]
    size = box.get("size")
    size_ok = _number_list(size, (3,)) and all(v > 0 for v in size)
    if not size_ok:
        problems.append(SpecProblem("box.size", "must be 3 positive numbers: lid length, lid width, height [m]"))
    if box.get("pose") is not None and not _number_list(box["pose"], (3,)):
        problems.append(SpecProblem("box.pose", "must be 3 finite numbers: x, y, yaw [m, m, rad]"))
    if not size_ok:
        return problems

    half_x, half_y = size[0] / 2.0, size[1] / 2.0
    footprints = {}
    for name, comp in components.items():
        if comp["kind"] not in PUZZLE_KINDS:
            continue
        polygon = get_kind(comp["kind"]).footprint_in_lid(tuple(comp["pose"]))
        footprints[name] = polygon
        beyond = max(
            float(abs(polygon[:, 0]).max() - half_x),
            float(abs(polygon[:, 1]).max() - half_y),
        )
        if beyond > INSIDE_TOLERANCE:
            problems.append(
                SpecProblem(
                    f"component {name!r}",
                    f"footprint reaches {beyond * 1000:.1f} mm beyond the lid "
                    f"(lid is {size[0]:.3f} x {size[1]:.3f} m, centred on the origin)",
                )
            )
    ordered = list(footprints)
    for a_i, a in enumerate(ordered):
        for b in ordered[a_i + 1 :]:
            gap = polygon_gap(footprints[a], footprints[b])
            if gap < -OVERLAP_TOLERANCE:
                problems.append(SpecProblem(f"component {a!r}", f"overlaps component {b!r} by {-gap * 1000:.1f} mm"))
    return problems


def _check_reachable(data: dict[str, Any]) -> list[SpecProblem]:
    spec = build_from_valid_data(data)
    try:
        path = LockTable.from_spec(spec).shortest_solution()
    except ReachabilityUndecided as err:
        return [SpecProblem("goal", f"reachability undecided: {err}")]
    if path is None:
        return [
            SpecProblem(
                "goal",
                f"unreachable: no sequence of toggles from the all-closed state brings "
                f"{spec.goal.component!r} to state {spec.goal.state}",
            )
        ]
    return []
