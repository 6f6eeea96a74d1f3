"""Component kinds of the puzzle box and their geometry templates.

Every component has a *component frame*: its pose ``[x, y, yaw]`` in a spec is this frame in the lid
frame (origin at the lid centre on its top face, x along the lid length, z up). For every kind the
component frame is where the component's ArUco marker centre sits in state 0 (closed), with z up and
x along the component's direction of motion, so that a marker seen by a camera gives the component
pose directly. Per kind:

``door``
    A flap lying in the lid plane, hinged along one edge. Frame origin: the marker centre.
    +x points from the hinge edge to the free edge, where the handle stands. The hinge axis is the
    line ``x = -DOOR_HALF`` parallel to y; opening (state 1) turns the free edge up, out of the lid
    plane, by ``travel`` [rad]. Footprint: the flap, ``[-DOOR_HALF, DOOR_HALF + HANDLE_MARGIN] x
    [-DOOR_HALF, DOOR_HALF]``.
``slide``
    A plate that slides in the lid plane along +x by ``travel`` [m] to open. Frame origin: the
    marker centre when closed; the knob stands behind the marker (-x). Footprint: the plate's swept
    area, ``[-p - HANDLE_MARGIN, p + travel] x [-p, p]`` with ``p = SLIDE_HALF``.
``wheel``
    A disc that turns in the lid plane about the z axis through its centre, by ``travel`` [rad]
    counter-clockwise to open. Frame origin: the disc centre (the marker centre); +x points at the
    handle knob when closed. Footprint: the disc (a circumscribed 16-gon for overlap tests).

Every marker is ``MARKER_SIZE`` wide (black square) inside a one-bit white quiet zone; every handle
is a 12 mm square post ``HANDLE_HEIGHT`` tall, clear of the quiet zone, so the overview camera reads
every marker and the gripper closes on every handle (DESIGN.md: 12 mm square handles at least 3 cm
above the surface were grasped in every randomized run).

Dimensions are chosen for the xArm-7's gripper and for markers an overview camera reads reliably;
travels follow the motions measured on this stack in DESIGN.md (door 85 deg, slide 50 mm, wheel 85 deg).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from models.errors import UnknownKindError
from models.geometry import circle_polygon, rectangle, transform_points

DOOR_HALF = 0.035
"""Half the width of the door flap, and its extent behind the marker centre to the hinge [m]."""
SLIDE_HALF = 0.025
"""Half the width of the slide plate, and its extent ahead of the marker centre [m]."""
WHEEL_RADIUS = 0.045
"""Radius of the wheel disc [m]."""
MARKER_SIZE = 0.036
"""Side of every component's ArUco marker (black square) [m]: ~38 px from the overview camera."""
HANDLE_SIZE = 0.012
"""Side of the square handle posts [m]."""
HANDLE_HEIGHT = 0.035
"""Height of the handle posts above the component's top face [m]."""
HANDLE_MARGIN = 0.011
"""Extra flap/plate length beyond the half-width that carries the handle clear of the marker [m]."""
SLIDE_BACK = SLIDE_HALF + HANDLE_MARGIN + 0.005
"""Extent of the slide plate behind its marker centre, carrying the knob [m]."""
HANDLE_OFFSET = 0.035
"""Distance of the handle centre from the marker centre along the component's x [m]: clear of the
marker's quiet zone (MARKER_SIZE / 2 * 4 / 3 = 24 mm) by 5 mm."""


@dataclass(frozen=True)
class KindTemplate:
    """What the project knows about a component kind: its joint, travel and footprint on the lid."""

    name: str
    """Kind name as written in specs."""
    joint: Literal["hinge", "slide"]
    """Joint type: ``hinge`` (revolute) or ``slide`` (prismatic)."""
    joint_axis: tuple[float, float, float]
    """Joint axis in the component frame (unit vector)."""
    joint_origin: tuple[float, float, float]
    """A point on the joint axis in the component frame [m]."""
    travel: float
    """Joint travel from state 0 to state 1 [rad for hinges, m for slides]."""
    marker_size: float
    """Side of the ArUco marker's black square [m]."""
    handle_xy: tuple[float, float]
    """Centre of the handle post in the component frame, state 0 [m]."""
    footprint: np.ndarray = field(repr=False, compare=False)
    """Convex polygon ``(n, 2)`` [m] in the component frame that the component occupies on the lid."""

    def footprint_in_lid(self, pose: tuple[float, float, float]) -> np.ndarray:
        """The footprint polygon in the lid frame for a component at ``pose`` ``[x, y, yaw]``."""
        return transform_points(pose, self.footprint)


DOOR = KindTemplate(
    name="door",
    joint="hinge",
    joint_axis=(0.0, -1.0, 0.0),  # right-handed about -y lifts the +x (free) edge
    joint_origin=(-DOOR_HALF, 0.0, 0.0),
    travel=math.radians(85.0),
    marker_size=MARKER_SIZE,
    handle_xy=(HANDLE_OFFSET, 0.0),
    footprint=rectangle(-DOOR_HALF, DOOR_HALF + HANDLE_MARGIN, -DOOR_HALF, DOOR_HALF),
)
SLIDE = KindTemplate(
    name="slide",
    joint="slide",
    joint_axis=(1.0, 0.0, 0.0),
    joint_origin=(0.0, 0.0, 0.0),
    travel=0.05,
    marker_size=MARKER_SIZE,
    handle_xy=(-HANDLE_OFFSET, 0.0),
    footprint=rectangle(-SLIDE_BACK, SLIDE_HALF + 0.05, -SLIDE_HALF, SLIDE_HALF),
)
WHEEL = KindTemplate(
    name="wheel",
    joint="hinge",
    joint_axis=(0.0, 0.0, 1.0),
    joint_origin=(0.0, 0.0, 0.0),
    travel=math.radians(85.0),
    marker_size=MARKER_SIZE,
    handle_xy=(HANDLE_OFFSET, 0.0),
    footprint=circle_polygon(WHEEL_RADIUS),
)

PUZZLE_KINDS: dict[str, KindTemplate] = {k.name: k for k in (DOOR, SLIDE, WHEEL)}
"""The puzzle-box kinds, by name."""

KIND_NAMES: tuple[str, ...] = ("door", "slide", "wheel")
"""Every kind the project knows, in a fixed order: the integer code of a kind is its index here."""

ALLOWED_NEIGHBOURS: frozenset[frozenset[str]] = frozenset({frozenset({"door", "slide"}), frozenset({"slide", "wheel"})})
"""Kind pairs that may lock each other (the paper: doors and wheels never interact, nor do two
components of the same kind)."""


def get_kind(name: str) -> KindTemplate:
    """The template of a puzzle-box kind; :class:`UnknownKindError` lists the known ones."""
    try:
        return PUZZLE_KINDS[name]
    except KeyError:
        raise UnknownKindError(name, PUZZLE_KINDS) from None


def kind_code(name: str) -> int:
    """Integer code of a kind (its index in :data:`KIND_NAMES`)."""
    try:
        return KIND_NAMES.index(name)
    except ValueError:
        raise UnknownKindError(name, KIND_NAMES) from None


def may_neighbour(kind_a: str, kind_b: str) -> bool:
    """Whether components of these two kinds may lock each other."""
    return frozenset({kind_a, kind_b}) in ALLOWED_NEIGHBOURS
