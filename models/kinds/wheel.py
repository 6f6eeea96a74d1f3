"""The ``wheel`` kind: a disc that turns in the lid plane about the z axis through its centre.

Opening turns it by ``travel`` [rad] (85 deg, as measured on this stack in DESIGN.md) counter-clockwise.
Frame origin: the disc centre (the marker centre); +x points at the handle knob when closed.
Footprint: the disc (a circumscribed 16-gon for overlap tests).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from puzzlebox.models.geometry import circle_polygon
from puzzlebox.models.kinds.kind import Handling, JointDynamics, Kind
from puzzlebox.models.kinds.parts import PART_DENSITY, PLATE_THICKNESS, add_handle, add_joint
from puzzlebox.models.kinds.template import HANDLE_OFFSET, MARKER_SIZE, KindTemplate

if TYPE_CHECKING:
    from dm_control import mjcf

WHEEL_RADIUS = 0.045
"""Radius of the wheel disc [m]."""

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
DYNAMICS = JointDynamics(damping=0.02, frictionloss=0.02)
"""A light disc on a metal pin: little damping, enough dry friction to stay where it was left."""
COLOUR = (0.33, 0.66, 0.41, 1)
"""RGBA of the disc (green)."""


def build(body: mjcf.Element, name: str) -> mjcf.Element:
    """Disc, knob and vertical hinge of a wheel; returns the hinge."""
    body.add(
        "geom",
        name=f"{name}:disc",
        type="cylinder",
        size=[WHEEL_RADIUS, PLATE_THICKNESS / 2],
        pos=[0, 0, PLATE_THICKNESS / 2],
        density=PART_DENSITY,
        rgba=COLOUR,
    )
    add_handle(body, name, WHEEL)
    return add_joint(body, name, WHEEL, DYNAMICS)


KIND = Kind(
    template=WHEEL,
    dynamics=DYNAMICS,
    colour=COLOUR,
    build=build,
    glyph="#55A868",
    sweep_effort=0.3,
    neighbours=("slide",),
    handling=Handling(yields_across=True, axis_yield=0.3),
)
"""The wheel, as registered (:mod:`models.kinds.registry`)."""
