"""The geometry template of a component kind, and the dimensions every kind shares.

Every component has a *component frame*: its pose ``[x, y, yaw]`` in a spec is this frame in the lid
frame (origin at the lid centre on its top face, x along the lid length, z up). For every kind the
component frame is where the component's ArUco marker centre sits in state 0 (closed), with z up and
x along the component's direction of motion, so that a marker seen by a camera gives the component
pose directly. Each kind's module (:mod:`models.kinds.door`, ``slide``, ``wheel``) describes its frame.

Every marker is ``MARKER_SIZE`` wide (black square) inside a one-bit white quiet zone; every handle
is a 12 mm square post ``HANDLE_HEIGHT`` tall, clear of the quiet zone, so the overview camera reads
every marker and the gripper closes on every handle (DESIGN.md: 12 mm square handles at least 3 cm
above the surface were grasped in every randomized run).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from puzzlebox.models.geometry import clip_below_x, transform_points

MARKER_SIZE = 0.036
"""Side of every component's ArUco marker (black square) [m]: ~38 px from the overview camera."""
HANDLE_SIZE = 0.012
"""Side of the square handle posts [m]."""
HANDLE_HEIGHT = 0.035
"""Height of the handle posts above the component's top face [m]."""
HANDLE_MARGIN = 0.011
"""Extra flap/plate length beyond the half-width that carries the handle clear of the marker [m]."""
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
    lift: float = 0.0
    """Height of the moving plate's bottom above the lid, state 0 [m]: 0 for parts lying on the lid; a part
    raised on fixed supports (a lever on its bracket) has its marker, handle and joint this much higher,
    and its builder puts the moving parts in a child body at this height."""
    edge_x: float | None = None
    """For a kind mounted at the lid's edge, the x [m] in the component frame of its front face in state 0
    (closed); None (the default) for a kind that stands anywhere on the lid. An edge-mounted component sits
    with this front face on a lid edge (flush with the box's side wall, in plan) and its +x pointing out of the
    lid, perpendicular to that edge: the part of its footprint at x <= ``edge_x`` lies on the lid, the part
    beyond is swept outside the lid, past the box's side, as it opens."""

    @property
    def at_edge(self) -> bool:
        """Whether the kind is mounted at the lid's edge (:attr:`edge_x` is set)."""
        return self.edge_x is not None

    def on_lid_footprint(self) -> np.ndarray:
        """The part of :attr:`footprint` on the lid, in the component frame [m]: all of it for a kind that
        stands anywhere on the lid, the part at x <= :attr:`edge_x` for an edge-mounted one."""
        if self.edge_x is None:
            return self.footprint
        return clip_below_x(self.footprint, self.edge_x)

    def front_in_lid(self, pose: Sequence[float]) -> tuple[tuple[float, float], float] | None:
        """For an edge-mounted kind at ``pose`` ``[x, y, yaw]`` (yaw taken to the nearest multiple of 90
        degrees): the lid axis its +x points along, ``(±1, 0)`` or ``(0, ±1)``, and its front face's
        coordinate along that axis [m]; None for a kind that stands anywhere on the lid."""
        if self.edge_x is None:
            return None
        x, y, yaw = pose
        axis = (float(round(math.cos(yaw))), float(round(math.sin(yaw))))
        return axis, axis[0] * x + axis[1] * y + self.edge_x

    def on_lid_footprint_in_lid(self, pose: Sequence[float]) -> np.ndarray:
        """:meth:`on_lid_footprint` in the lid frame for a component at ``pose`` ``[x, y, yaw]``."""
        return transform_points(pose, self.on_lid_footprint())

    def footprint_in_lid(self, pose: Sequence[float]) -> np.ndarray:
        """The footprint polygon in the lid frame for a component at ``pose`` ``[x, y, yaw]``."""
        return transform_points(pose, self.footprint)
