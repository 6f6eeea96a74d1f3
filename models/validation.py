"""Validation of puzzle spec files: every problem at once, each naming the field or component.

Two kind families exist (SPEC.md extended, issue 14): puzzle boxes (``box`` required, the registered kinds of
:mod:`models.kinds` — door, slide, wheel and any kind module added there —, planar poses ``[x, y, yaw]``,
footprints inside the lid and not overlapping; a kind mounted at the lid's edge,
:attr:`models.kinds.template.KindTemplate.edge_x`, has its front face on the lid edge its +x points out of
and only its footprint's part behind that face on the lid) and disassembly scenes (no ``box``, kinds of
:mod:`models.disassembly_kinds`, 6-DOF poses ``[x, y, z, roll, pitch, yaw]``, no footprint rules). A spec
without a box that has a disassembly kind is a disassembly scene; one family's kind in the other's spec is a
problem naming the component. The generic rules (names, locks, goal, reachability) apply to both.

:func:`validate_data` takes the parsed JSON value (anything ``json.loads`` may return) and never
raises on bad input: it returns the list of problems, empty for a valid spec.
"""

from __future__ import annotations

import math
from typing import Any, TypeGuard

from puzzlebox.models.disassembly_kinds import DISASSEMBLY_KIND_NAMES, DISASSEMBLY_KINDS, DISASSEMBLY_POSE_SIZE
from puzzlebox.models.errors import ReachabilityUndecided, SpecProblem
from puzzlebox.models.geometry import polygon_gap
from puzzlebox.models.kinds import get_kind, registered_kinds
from puzzlebox.models.kinds.template import KindTemplate
from puzzlebox.models.lock_table import LockTable
from puzzlebox.models.markers import MAX_MARKER_ID
from puzzlebox.models.names import name_problem
from puzzlebox.models.spec import SPEC_FORMAT, build_from_valid_data

MAX_COMPONENTS = 62
"""Symbolic states are 64-bit bitmasks; more components than this cannot be represented."""
OVERLAP_TOLERANCE = 1e-6
"""Footprints may touch; they overlap when they interpenetrate by more than this [m]."""
INSIDE_TOLERANCE = 1e-6
"""A footprint may reach the lid edge up to this much beyond it [m] (rounding in files)."""
EDGE_TOLERANCE = 1e-4
"""An edge-mounted component's front face may lie this far off its lid edge [m] (rounding in files)."""
EDGE_ANGLE_TOLERANCE = 1e-3
"""An edge-mounted component's yaw may be this far off a multiple of 90 degrees [rad] (rounding in files)."""
SIDE_NAMES = {(1.0, 0.0): "+x", (-1.0, 0.0): "-x", (0.0, 1.0): "+y", (0.0, -1.0): "-y"}


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


def _number_list(value: Any, lengths: tuple[int, ...]) -> TypeGuard[list[float]]:
    return isinstance(value, list) and len(value) in lengths and all(_is_number(v) for v in value)


def is_disassembly_data(data: Any) -> bool:
    """Whether a parsed spec is a disassembly scene: no ``box`` and some component of a disassembly kind."""
    if not isinstance(data, dict) or data.get("box") is not None or not isinstance(data.get("components"), list):
        return False
    return any(isinstance(c, dict) and c.get("kind") in DISASSEMBLY_KINDS for c in data["components"])


def _is_box_kind(kind: Any) -> bool:
    """Whether ``kind`` is a registered puzzle-box kind (:mod:`models.kinds.registry`)."""
    return isinstance(kind, str) and kind in registered_kinds()


def _known_kinds(disassembly: bool) -> str:
    puzzle, other = f"puzzle-box kinds {list(registered_kinds())}", f"disassembly kinds {list(DISASSEMBLY_KIND_NAMES)}"
    return f"{other}; {puzzle}" if disassembly else f"{puzzle}; {other}"


def _check_pose(pose: Any, kind: Any, where: str, problem: Any) -> bool:
    """The pose's length follows its kind's family: ``[x, y, yaw]`` for puzzle-box kinds, ``[x, y, z, roll,
    pitch, yaw]`` for disassembly kinds (either for an unknown kind, already reported)."""
    bound = f"finite numbers within +-{MAX_MAGNITUDE:g} [m, rad]"
    if _is_box_kind(kind):
        if _number_list(pose, (3,)):
            return True
        if isinstance(pose, list) and len(pose) == DISASSEMBLY_POSE_SIZE:
            problem(
                f"{where}.pose",
                f"6-DOF pose on puzzle-box kind {kind!r}: a {kind} takes a planar pose [x, y, yaw] (3 {bound}); "
                "6-DOF poses [x, y, z, roll, pitch, yaw] are for disassembly scenes",
            )
        else:
            problem(f"{where}.pose", f"must be a planar pose [x, y, yaw]: a list of 3 {bound}")
        return False
    if isinstance(kind, str) and kind in DISASSEMBLY_KINDS:
        if _number_list(pose, (DISASSEMBLY_POSE_SIZE,)):
            return True
        got = f"a list of {len(pose)}" if isinstance(pose, list) else type(pose).__name__
        problem(
            f"{where}.pose",
            f"disassembly kind {kind!r} takes a 6-DOF pose [x, y, z, roll, pitch, yaw]: a list of 6 {bound}; got {got}",
        )
        return False
    if not _number_list(pose, (3, 6)):
        problem(f"{where}.pose", f"must be a list of 3 or 6 {bound}")
        return False
    return True


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

    name_issue = name_problem(data.get("name"))  # the one rule for names (models.names): any such name is keyed
    if name_issue is not None:
        problem("name", name_issue)

    components = data.get("components")
    valid_components: dict[str, dict[str, Any]] = {}  # name -> component, for components without problems
    names: set[str] = set()
    if not isinstance(components, list) or not components:
        problem("components", "missing or not a non-empty list")
        components = []
    elif len(components) > MAX_COMPONENTS:
        problem("components", f"{len(components)} components; at most {MAX_COMPONENTS} are supported")
    disassembly = is_disassembly_data(data)
    markers: dict[int, str] = {}
    for k, comp in enumerate(components):
        where = f"components[{k}]"
        if not isinstance(comp, dict):
            problem(where, "must be an object with name, kind and pose")
            continue
        ok = True
        name = comp.get("name")
        if name_problem(name) is not None:
            problem(f"{where}.name", str(name_problem(name)))
            ok = False
        else:
            assert isinstance(name, str)
            where = f"component {name!r}"
            if name in names:
                problem(where, f"duplicate name {name!r} (names must be unique)")
                ok = False
            names.add(name)
        kind = comp.get("kind")
        if not isinstance(kind, str):
            problem(f"{where}.kind", f"missing or not a string; known kinds: {_known_kinds(disassembly)}")
            ok = False
        elif not _is_box_kind(kind) and kind not in DISASSEMBLY_KINDS:
            problem(f"{where}.kind", f"unknown kind {kind!r}; known kinds: {_known_kinds(disassembly)}")
            ok = False
        elif disassembly and _is_box_kind(kind):
            problem(
                f"{where}.kind",
                f"puzzle-box kind {kind!r} in a disassembly scene (no box, disassembly kinds); a spec has one "
                f"kind family: disassembly kinds are {list(DISASSEMBLY_KIND_NAMES)}",
            )
            ok = False
        elif not disassembly and kind in DISASSEMBLY_KINDS:
            problem(
                f"{where}.kind",
                f"disassembly kind {kind!r} in a puzzle-box spec (it has a box); a disassembly scene has no box "
                f"and 6-DOF poses; puzzle-box kinds are {list(registered_kinds())}",
            )
            ok = False
        if not _check_pose(comp.get("pose"), kind, where, problem):
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
            assert isinstance(name, str)  # else not ok
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
    box_kinds = [c for c in components.values() if _is_box_kind(c["kind"])]
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
    assert size is not None  # size_ok

    half_x, half_y = size[0] / 2.0, size[1] / 2.0
    footprints = {}
    for name, comp in components.items():
        if not _is_box_kind(comp["kind"]):
            continue
        template = get_kind(comp["kind"])
        pose = tuple(comp["pose"])
        polygon = template.footprint_in_lid(pose)
        footprints[name] = polygon  # overlaps: the whole footprint, an edge-mounted one's swept part included
        outward = None
        if template.at_edge:
            outward, problem = _check_edge(name, comp["kind"], template, pose, half_x, half_y)
            if problem is not None:
                problems.append(problem)
            polygon = template.on_lid_footprint_in_lid(pose)  # its swept part lies beyond the lid edge
        # on the lid: how far the footprint reaches past each edge (past its own edge, an edge-mounted
        # component's front is checked above)
        beyond = max(
            float(abs(polygon[:, 0]).max() - half_x)
            if outward is None or outward[1] != 0.0
            else float((-outward[0] * polygon[:, 0]).max() - half_x),
            float(abs(polygon[:, 1]).max() - half_y)
            if outward is None or outward[0] != 0.0
            else float((-outward[1] * polygon[:, 1]).max() - half_y),
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


def _check_edge(
    name: str, kind: str, template: KindTemplate, pose: tuple[float, ...], half_x: float, half_y: float
) -> tuple[tuple[float, float] | None, SpecProblem | None]:
    """An edge-mounted component's placement: its +x must point out of the lid perpendicular to an edge (yaw a
    multiple of 90 degrees) and its front face (x = ``edge_x`` in its frame) lie on that edge. Returns the
    outward axis (None when the yaw faces no edge) and the problem, if any."""
    x, y, yaw = pose
    where = f"component {name!r}"
    quarter = math.pi / 2.0
    if abs(yaw - round(yaw / quarter) * quarter) > EDGE_ANGLE_TOLERANCE:
        return None, SpecProblem(
            where,
            f"a {kind} is mounted at the lid's edge, its +x pointing out of the lid perpendicular to an edge: its "
            f"yaw must be a multiple of 90 degrees, got {math.degrees(yaw):.1f} degrees",
        )
    placement = template.front_in_lid((x, y, yaw))  # its +x's lid axis, its front's coordinate along it
    edge_x = template.edge_x
    assert placement is not None and edge_x is not None  # an edge-mounted kind's (template.at_edge)
    outward, front = placement
    half = half_x if outward[0] != 0.0 else half_y
    off = front - half
    if abs(off) <= EDGE_TOLERANCE:
        return outward, None
    side = SIDE_NAMES[outward]
    inward = outward[0] * x + outward[1] * y < 0.0
    return outward, SpecProblem(
        where,
        f"a {kind} is mounted at the lid's edge: its front face (x = {edge_x * 1000:.0f} mm in its frame) must lie "
        f"on the lid edge its +x points out of, but its +x points to {side} and its front face is "
        f"{abs(off) * 1000:.1f} mm {'inside' if off < 0 else 'beyond'} the {side} edge"
        + (" (it points into the lid, toward the far edge: turn it to point out)" if inward else ""),
    )


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
