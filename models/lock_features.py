"""Visible lock features: what shows, on the box, the latches the twin enforces (issue 15, part 4).

A lock rule "``locker`` in state a keeps ``locked`` in state b" is enforced in physics by a latch
(:mod:`models.puzzle_box`); this module gives it a shape, so that what is seen matches what is enforced.
One feature per distinct ``(locker, locked)`` pair of ``spec.locks`` (rules naming the same pair share it):

- ``"notch"`` (black) when either component is a ``wheel``: a pin that stands from the non-wheel part and
  passes the wheel's rim, with a thin dark notch plate on the rim under the pin's end;
- ``"bolt"`` (dark red) when the locker is a ``door`` or ``slide`` and the locked part a door or slide: a
  post on the locker's plate with an arm reaching over the locked component's edge;
- ``"catch"`` (dark red) for any other pair, including kinds this module does not know ("lever",
  "drawer", ...): a taller hook block on the locker's plate whose arm ends in a lip over the locked part.

Placement, on the lid, at the closed state (every component in state 0): a feature lies on a strip along
the segment from the locker's pose origin to the locked one's (direction ``d``), starting on the locker's
plate at the locker footprint's edge facing the locked component and reaching :data:`REACH` (4 mm) into
the locked component's footprint. The locker's *plate* is its footprint at state 0: for a prismatic kind
(``template.joint == "slide"``) the footprint is the swept area and the plate is the part of it that
stays inside when moved by ``-travel`` along the joint axis. A feature of a kind without a registered
template (:class:`~models.errors.UnknownKindError`) is placed by pose only, as if the component were a
disc of :data:`UNKNOWN_RADIUS`. A strip may not overlap any component's marker quiet zone (the square of
side ``MARKER_SIZE * 4 / 3`` centred on its pose origin, turned by its yaw), any handle post, nor a feature
placed before it; if the nominal strip does, it is shifted sideways along the edge and narrowed/shortened
(:data:`WIDTHS`, :data:`BASE_DEPTHS`); failing that the feature is skipped and the reason recorded
(:class:`SkippedLockFeature`). When both ``(a, b)`` and ``(b, a)`` are locked, the two features start on
opposite sides of the segment so they never meet.

Frames and units: meshes are in the **lid frame** (origin at the lid centre on its top face, x along the box
length, z up), in **metres**; every plate's top face is at ``z = PLATE_THICKNESS`` (6 mm) above its kind's
``lift`` (0 but for raised parts: a lever's arm), so features stand there. A feature belongs to its locker: it
moves with the locker's joint (the MJCF of :func:`models.puzzle_box.build_puzzle_box` with
``lock_features=True`` carries it in the locker's body, and :func:`models.mesh_export.component_meshes` adds
it to the locker's part). Features are visual only."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import trimesh
from trimesh.visual import ColorVisuals

from puzzlebox.models.errors import UnknownKindError
from puzzlebox.models.geometry import circle_polygon, polygons_clear, rectangle, transform_points
from puzzlebox.models.kinds.parts import PLATE_THICKNESS
from puzzlebox.models.kinds.registry import get_kind
from puzzlebox.models.kinds.template import HANDLE_SIZE, MARKER_SIZE, KindTemplate
from puzzlebox.models.lock_table import LockTable
from puzzlebox.models.spec import LockRule, PuzzleSpec

__all__ = [
    "BOLT_KINDS",
    "FEATURE_RGBA",
    "QUIET_ZONE_SIZE",
    "REACH",
    "FeatureKind",
    "LockFeature",
    "LockFeatureLayout",
    "SkippedLockFeature",
    "feature_kind",
    "layout_lock_features",
    "lock_features",
    "quiet_zone",
]

FeatureKind = Literal["bolt", "notch", "catch"]
"""What a lock feature looks like (module docstring)."""

REACH = 0.004
"""How far a feature reaches into the locked component's footprint [m], nominally."""
REACHES = (REACH, 0.003, 0.002, 0.001)
"""Reaches tried, nominal first, when the nominal one would cover the locked component's marker [m]."""
WIDTHS = (0.010, 0.007, 0.005, 0.004)
"""Widths of a feature across the segment, nominal first, then narrower tries [m]."""
BASE_DEPTHS = (0.008, 0.005, 0.003, 0.0008)
"""Length of the post standing on the locker's plate, along the segment, nominal first [m]. The last
fits the 1 mm of plate a slide shows beyond its marker's quiet zone."""
POST_HEIGHT = 0.008
"""Height of a bolt's or notch pin's top above the plate tops [m]."""
CATCH_HEIGHT = 0.012
"""Height of a catch's top above the plate tops [m]."""
ARM_LIFT = 0.002
"""Gap between an arm's underside and the plate tops it passes over [m]."""
LIP = 0.003
"""Length of a catch's hook lip along the segment [m]; the lip hangs down to :data:`LIP_CLEARANCE`."""
LIP_CLEARANCE = 0.0005
"""Gap under a catch's lip [m]."""
NOTCH_THICKNESS = 0.001
"""Thickness of the dark notch plate on a wheel's rim [m] (below :data:`ARM_LIFT`: the pin passes over it)."""
SHIFT_STEP = 0.001
"""Resolution of the sideways search along the edge [m]."""
MAX_SHIFT = 0.05
"""Farthest a feature is shifted sideways from the segment [m]."""
PAIR_SEPARATION = 0.0015
"""Gap between the two features of a pair locked both ways [m]."""
CLEARANCE = 1e-4
"""Smallest gap between a feature and a quiet zone, a handle or another feature, seen from above [m]."""
UNKNOWN_RADIUS = 0.03
"""Radius of the disc a component of an unknown kind is taken to cover [m] (placement by pose only)."""
QUIET_ZONE_SIZE = MARKER_SIZE * 4 / 3
"""Side of the square around every marker that features keep clear of [m] (marker and white quiet zone)."""
BOLT_KINDS = frozenset({"door", "slide"})
"""Kinds whose locks show as bolts (both locker and locked of these kinds)."""
WHEEL_KIND = "wheel"
FEATURE_RGBA: dict[str, tuple[float, float, float, float]] = {
    "bolt": (0.5, 0.05, 0.05, 1.0),
    "catch": (0.5, 0.05, 0.05, 1.0),
    "notch": (0.03, 0.03, 0.03, 1.0),
}
"""RGBA [0-1] per feature kind: dark red bolts and catches, black notches."""


@dataclass(frozen=True)
class LockFeature:
    """The visible shape of the lock rules of one ``(locker, locked)`` pair.

    Attributes:
        name: ``"<locker>-locks-<locked>"`` (spec names).
        kind: ``"bolt"``, ``"notch"`` or ``"catch"``.
        locker: spec name of the locker; the feature belongs to it and moves with it.
        locked: spec name of the locked component.
        rules: the lock rules this feature shows (one or more with this ``(locker, locked)``), spec order.
        mesh: watertight triangle mesh in the lid frame [m], every component closed (state 0); faces
            coloured :attr:`rgba`.
        rgba: colour [0-1] (:data:`FEATURE_RGBA`).
        footprint: ``(4, 2)`` rectangle [m] in the lid frame covering the mesh seen from above.
    """

    name: str
    kind: FeatureKind
    locker: str
    locked: str
    rules: tuple[LockRule, ...]
    mesh: trimesh.Trimesh = field(repr=False, compare=False)
    rgba: tuple[float, float, float, float]
    footprint: np.ndarray = field(repr=False, compare=False)


@dataclass(frozen=True)
class SkippedLockFeature:
    """A ``(locker, locked)`` pair whose feature could not be placed, and why."""

    name: str
    locker: str
    locked: str
    rules: tuple[LockRule, ...]
    reason: str


@dataclass(frozen=True)
class LockFeatureLayout:
    """Every pair's feature, or why it has none: ``features`` + ``skipped`` cover each pair once."""

    features: tuple[LockFeature, ...]
    skipped: tuple[SkippedLockFeature, ...]


def lock_features(spec: PuzzleSpec) -> list[LockFeature]:
    """The visible lock features of a puzzle-box spec (module docstring), one per distinct
    ``(locker, locked)`` pair of ``spec.locks`` in order of first appearance; pairs that could not be
    placed are left out (:func:`layout_lock_features` says why). Empty for a spec without locks."""
    return list(layout_lock_features(spec).features)


def feature_kind(locker_kind: str, locked_kind: str) -> FeatureKind:
    """What the lock of a ``locker_kind`` on a ``locked_kind`` looks like; never raises for unknown kinds."""
    if WHEEL_KIND in (locker_kind, locked_kind):
        return "notch"
    if locker_kind in BOLT_KINDS and locked_kind in BOLT_KINDS:
        return "bolt"
    return "catch"


def quiet_zone(pose: tuple[float, ...]) -> np.ndarray:
    """The ``(4, 2)`` square [m] in the lid frame that features keep clear of around a marker at ``pose``
    ``[x, y, yaw]``: side :data:`QUIET_ZONE_SIZE`, centred on the pose origin, turned by its yaw."""
    h = QUIET_ZONE_SIZE / 2
    return transform_points(_planar(pose), rectangle(-h, h, -h, h))


def layout_lock_features(spec: PuzzleSpec) -> LockFeatureLayout:
    """Place every pair's feature (module docstring); features are placed in order of the pairs' first
    rule, each clear of the ones before it."""
    table = LockTable.from_spec(spec)
    pairs: dict[tuple[int, int], list[LockRule]] = {}
    for r, rule in enumerate(spec.locks):
        pairs.setdefault((int(table.locker[r]), int(table.locked[r])), []).append(rule)
    shapes = [_ComponentShape.of(c.kind, _planar(c.pose)) for c in spec.components]
    obstacles = _Obstacles([_ccw(quiet_zone(c.pose)) for c in spec.components])
    obstacles.polygons.extend(s.handle for s in shapes if s.handle is not None)
    features: list[LockFeature] = []
    skipped: list[SkippedLockFeature] = []
    for (i, j), rules in pairs.items():
        locker, locked = spec.components[i], spec.components[j]
        name = f"{locker.name}-locks-{locked.name}"
        kind = feature_kind(locker.kind, locked.kind)
        side = 1.0 if (j, i) in pairs else 0.0
        placed = _place(kind, shapes[i], shapes[j], obstacles, side)
        if isinstance(placed, str):
            skipped.append(SkippedLockFeature(name, locker.name, locked.name, tuple(rules), placed))
            continue
        mesh, strip = placed
        mesh.apply_translation([0.0, 0.0, _lift(locker.kind)])  # on a raised locker's plate (a lever's arm)
        rgba = FEATURE_RGBA[kind]
        assert isinstance(mesh.visual, ColorVisuals)  # a new mesh's
        mesh.visual.face_colors = np.round(255 * np.array(rgba)).astype(np.uint8)
        features.append(LockFeature(name, kind, locker.name, locked.name, tuple(rules), mesh, rgba, strip))
        obstacles.polygons.append(strip)
    return LockFeatureLayout(tuple(features), tuple(skipped))


def _lift(kind: str) -> float:
    """How far above the lid a kind's plate is raised, closed [m] (``KindTemplate.lift``; 0 if unknown)."""
    try:
        return get_kind(kind).lift
    except UnknownKindError:
        return 0.0


def _planar(pose: tuple[float, ...]) -> tuple[float, float, float]:
    """``[x, y, yaw]`` of a planar pose, or of a 6-D one (its x, y and yaw)."""
    if len(pose) == 3:
        return (float(pose[0]), float(pose[1]), float(pose[2]))
    return (float(pose[0]), float(pose[1]), float(pose[5]))


@dataclass(frozen=True)
class _ComponentShape:
    """A component on the lid at state 0: centre, footprint, plate and handle post, lid frame [m]."""

    kind: str
    centre: np.ndarray
    footprint: np.ndarray
    plate: np.ndarray
    handle: np.ndarray | None
    yaw: float

    @classmethod
    def of(cls, kind: str, pose: tuple[float, float, float]) -> _ComponentShape:
        try:
            template = get_kind(kind)
        except UnknownKindError:  # placed by pose only
            disc = _ccw(transform_points(pose, circle_polygon(UNKNOWN_RADIUS)))
            return cls(kind, np.array(pose[:2]), disc, disc, None, pose[2])
        hx, hy = template.handle_xy
        h = HANDLE_SIZE / 2
        handle = transform_points(pose, rectangle(hx - h, hx + h, hy - h, hy + h))
        footprint = _ccw(template.footprint_in_lid(pose))
        plate = _ccw(transform_points(pose, _closed_plate(template)))
        return cls(kind, np.array(pose[:2]), footprint, plate, handle, pose[2])


def _closed_plate(template: KindTemplate) -> np.ndarray:
    """The part of a kind's footprint (component frame) its plate covers at state 0: for a prismatic
    joint the swept footprint intersected with itself moved back by the travel, else the footprint."""
    footprint = np.asarray(template.footprint, dtype=float)
    axis = np.asarray(template.joint_axis[:2], dtype=float)
    if template.joint != "slide" or np.linalg.norm(axis) < 1e-9:
        return footprint
    shifted = footprint - template.travel * axis  # the in-plane part of the travel (unit joint axis)
    clipped = _clip_convex(footprint, shifted)
    return clipped if len(clipped) >= 3 else footprint


def _clip_convex(subject: np.ndarray, clip: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman: ``subject`` ∩ ``clip`` for convex polygons (counter-clockwise)."""
    clip = _ccw(clip)
    out = list(_ccw(subject))
    for a, b in zip(clip, np.roll(clip, -1, axis=0), strict=True):
        edge = b - a
        inside = [_cross(edge, p - a) >= -1e-12 for p in out]
        nxt = []
        for k, p in enumerate(out):
            q = out[(k + 1) % len(out)]
            if inside[k]:
                nxt.append(p)
            if inside[k] != inside[(k + 1) % len(out)]:
                dp, dq = _cross(edge, p - a), _cross(edge, q - a)
                nxt.append(p + (q - p) * dp / (dp - dq))
        out = nxt
        if not out:
            break
    return np.array(out, dtype=float).reshape(-1, 2)


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    """z of the cross product of two planar vectors."""
    return float(a[0] * b[1] - a[1] * b[0])


def _ccw(polygon: np.ndarray) -> np.ndarray:
    x, y = polygon[:, 0], polygon[:, 1]
    area = float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))
    return polygon if area >= 0 else polygon[::-1]


def _line_interval(polygon: np.ndarray, origin: np.ndarray, d: np.ndarray) -> tuple[float, float] | None:
    """``[a, b]`` of the ``s`` for which ``origin + s d`` lies in the convex counter-clockwise ``polygon``,
    or ``None``."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    rel = origin - polygon
    # inside every edge: cross(edge, origin + s d - a) = c0 + s c1 >= 0
    c0 = edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0]
    c1 = edges[:, 0] * d[1] - edges[:, 1] * d[0]
    flat = np.abs(c1) < 1e-15
    if np.any(flat & (c0 < 0)):
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = -c0 / c1
    lo = float(bound[~flat & (c1 > 0)].max(initial=-math.inf))
    hi = float(bound[~flat & (c1 < 0)].min(initial=math.inf))
    return (lo, hi) if lo < hi else None


def _strip_interval(polygon: np.ndarray, origin: np.ndarray, d: np.ndarray, n: np.ndarray, t: float, w: float):
    """The ``s`` range in which the whole strip ``origin + s d + v n``, ``v`` in ``t ± w/2``, lies in the
    convex ``polygon`` (entry is convex and exit concave in ``v``: the two edge lines decide), or ``None``."""
    a = _line_interval(polygon, origin + (t - w / 2) * n, d)
    b = _line_interval(polygon, origin + (t + w / 2) * n, d)
    if a is None or b is None:
        return None
    return max(a[0], b[0]), min(a[1], b[1])


def _offsets(start: float) -> list[float]:
    """Sideways offsets [m] to try, nearest to ``start`` first."""
    steps = int(round(MAX_SHIFT / SHIFT_STEP))
    out = [start]
    for k in range(1, steps + 1):
        out += [start + k * SHIFT_STEP, start - k * SHIFT_STEP]
    return out


@dataclass(frozen=True)
class _Obstacles:
    """Convex polygons a feature keeps clear of, with bounding circles for a quick first test."""

    polygons: list[np.ndarray]

    def clear(self, strip: np.ndarray) -> bool:
        """Whether the convex ``strip`` is at least :data:`CLEARANCE` from every obstacle."""
        centre = strip.mean(axis=0)
        radius = float(np.linalg.norm(strip - centre, axis=1).max())
        for polygon in self.polygons:
            c = polygon.mean(axis=0)
            if float(np.linalg.norm(c - centre)) > radius + float(np.linalg.norm(polygon - c, axis=1).max()):
                continue
            if not polygons_clear(strip, polygon, CLEARANCE):
                return False
        return True


def _place(
    kind: FeatureKind, locker: _ComponentShape, locked: _ComponentShape, obstacles: _Obstacles, side: float
) -> tuple[trimesh.Trimesh, np.ndarray] | str:
    """The feature's mesh and its strip (lid frame), or why it cannot be placed. Tries the nominal width,
    reach and post first at every sideways offset (nearest the segment first), then smaller ones."""
    delta = locked.centre - locker.centre
    distance = float(np.linalg.norm(delta))
    if distance < 1e-9:
        return "locker and locked component share a pose origin: no edge faces the locked component"
    d = delta / distance
    n = np.array([-d[1], d[0]])
    # who carries the post: a wheel locker's pin stands from the locked part and passes the wheel's rim
    post_on_locked = kind == "notch" and locker.kind == WHEEL_KIND
    reasons: dict[str, int] = {}
    for w in WIDTHS:
        start = side * (w / 2 + PAIR_SEPARATION / 2)
        for reach in REACHES:
            for depth in BASE_DEPTHS:
                for t in _offsets(start):
                    placed = _try(kind, locker, locked, d, n, t, w, depth, reach, post_on_locked)
                    if isinstance(placed, str):
                        reasons[placed] = reasons.get(placed, 0) + 1
                        continue
                    s0, s1, post, notch = placed
                    strip = _strip(locker.centre, d, n, t, w, s0, s1)
                    if not obstacles.clear(strip):
                        why = "it overlaps a marker's quiet zone, a handle or another feature"
                        reasons[why] = reasons.get(why, 0) + 1
                        continue
                    return _mesh(kind, locker.centre, d, n, t, w, s0, s1, post, notch, post_on_locked), strip
    common = max(reasons, key=reasons.__getitem__) if reasons else "no candidate"
    return f"no clear strip within {MAX_SHIFT * 1000:.0f} mm of the segment between them (mostly: {common})"


def _try(kind, locker, locked, d, n, t, w, depth, reach, post_on_locked):
    """``(s0, s1, post, notch)``: the strip's extent along ``d`` from the locker's centre [m], the post's
    length along it [m] and the notch plate's extent ``(s_a, s_b)`` (``None`` if none), or a reason."""
    on_locker = _strip_interval(locker.plate, locker.centre, d, n, t, w)
    into_locked = _strip_interval(locked.footprint, locker.centre, d, n, t, w)
    if on_locker is None or on_locker[1] - on_locker[0] < depth:
        return "the strip misses the locker's plate"
    if into_locked is None or into_locked[1] - into_locked[0] < reach:
        return "the strip misses the locked component's footprint"
    edge = on_locker[1]  # the locker plate's edge facing the locked component
    entry = max(into_locked[0], edge)
    if post_on_locked:  # the pin stands on the locked plate; its arm ends over the notch on the wheel's rim
        on_locked_plate = _strip_interval(locked.plate, locker.centre, d, n, t, w)
        post = min(depth, reach)
        if on_locked_plate is None or on_locked_plate[1] - on_locked_plate[0] < post:
            return "the strip misses the locked component's plate"
        s0 = edge - reach
        s1 = max(on_locked_plate[0] + post, entry + reach)
        if s0 < on_locker[0] or s1 > on_locked_plate[1]:
            return "a component is too thin along the segment"
        return s0, s1, post, (s0, edge)
    s0 = edge - depth
    s1 = entry + reach
    if s1 > into_locked[1]:
        return "the locked component is too thin along the segment"
    if kind == "catch" and s1 - s0 < depth + LIP + 0.001:
        return "too short for a hook"
    notch = (entry, s1) if kind == "notch" else None
    return s0, s1, depth, notch


def _strip(centre, d, n, t, w, s0, s1) -> np.ndarray:
    corners = [(s0, t - w / 2), (s1, t - w / 2), (s1, t + w / 2), (s0, t + w / 2)]
    return np.array([centre + s * d + v * n for s, v in corners])


def _mesh(kind, centre, d, n, t, w, s0, s1, post, notch, post_on_locked) -> trimesh.Trimesh:
    """The feature's solid in the lid frame: a profile in the (along-segment, z) plane extruded across
    the strip, the post at the end that stands on a plate, plus the notch plate for notches."""
    length = s1 - s0
    base = PLATE_THICKNESS
    if kind == "catch":
        h, lift, lip_low = CATCH_HEIGHT, ARM_LIFT, LIP_CLEARANCE
        profile = np.array(
            [(0, 0), (post, 0), (post, lift), (length - LIP, lift), (length - LIP, lip_low), (length, lip_low),
             (length, h), (0, h)]
        )  # fmt: skip
        triangles = [(0, 1, 2), (0, 2, 7), (2, 3, 6), (2, 6, 7), (3, 4, 5), (3, 5, 6)]
    else:
        h, lift = POST_HEIGHT, ARM_LIFT
        profile = np.array([(0, 0), (post, 0), (post, lift), (length, lift), (length, h), (0, h)])
        triangles = [(0, 1, 2), (0, 2, 5), (2, 3, 4), (2, 4, 5)]
    solid = trimesh.creation.extrude_triangulation(profile, np.array(triangles), w)
    # local (u along the arm from the post, z, across) -> lid; the post is at u = 0
    u = d if not post_on_locked else -d
    origin_s = s0 if not post_on_locked else s1
    u3 = np.array([u[0], u[1], 0.0])
    ez = np.array([0.0, 0.0, 1.0])
    across = np.cross(u3, ez)  # det[u, z, u x z] > 0: no mirroring, outward normals stay outward
    origin = np.array([*(centre + origin_s * d + t * n), base]) - across * (w / 2)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = u3, ez, across, origin
    solid.apply_transform(T)
    pieces = [solid]
    if notch is not None:
        a, b = notch
        mid = centre + (a + b) / 2 * d + t * n
        plate = trimesh.creation.box(extents=(b - a, w, NOTCH_THICKNESS))
        R = np.eye(4)
        R[:3, 0], R[:3, 1] = (d[0], d[1], 0.0), (n[0], n[1], 0.0)
        R[:3, 3] = [mid[0], mid[1], base + NOTCH_THICKNESS / 2]
        plate.apply_transform(R)
        pieces.append(plate)
    merged = trimesh.util.concatenate(pieces)
    assert isinstance(merged, trimesh.Trimesh)  # of meshes: a mesh (its return type is any geometry)
    return merged
