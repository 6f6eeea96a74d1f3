"""The ``door`` kind: a flap lying in the lid plane, hinged along one edge.

Frame origin: the marker centre. +x points from the hinge edge to the free edge, where the handle
stands. The hinge axis is the line ``x = -DOOR_HALF`` parallel to y; opening (state 1) turns the free
edge up, out of the lid plane, by ``travel`` [rad] (85 deg, as measured on this stack in DESIGN.md).
Footprint: the flap, ``[-DOOR_HALF, DOOR_HALF + HANDLE_MARGIN] x [-DOOR_HALF, DOOR_HALF]``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from puzzlebox.models.geometry import rectangle
from puzzlebox.models.kinds.kind import Handling, JointDynamics, Kind
from puzzlebox.models.kinds.parts import PLATE_THICKNESS, add_handle, add_joint, add_plate
from puzzlebox.models.kinds.template import HANDLE_MARGIN, HANDLE_OFFSET, MARKER_SIZE, KindTemplate

if TYPE_CHECKING:
    from dm_control import mjcf

DOOR_HALF = 0.035
"""Half the width of the door flap, and its extent behind the marker centre to the hinge [m]."""

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
DYNAMICS = JointDynamics(damping=0.02, frictionloss=0.02)
"""A light flap on a metal pin: little damping, enough dry friction to stay where it was left."""
COLOUR = (0.30, 0.45, 0.70, 1)
"""RGBA of the flap (blue)."""


def build(body: mjcf.Element, name: str) -> mjcf.Element:
    """Flap, hinge pin (visual), handle and hinge of a door; returns the hinge."""
    # gravcomp: the flap is balanced on its hinge (a lid stay, as a lever's counter-spring), so it stays where it is
    # left: unbalanced, its weight turned it shut past MuJoCo's soft dry friction (a door left at 98 % of its travel
    # sank 5-7 % of it in 60 s, one left at 80 % 28 %), below the open band within a trial while the world believed
    # it open. The rods and lugs it carries are balanced with it (``models.mechanism_mjcf._carried``).
    body.gravcomp = 1
    add_plate(body, name, COLOUR, -DOOR_HALF, DOOR_HALF + HANDLE_MARGIN, DOOR_HALF)
    body.add(  # the hinge pin, for the eye
        "geom",
        name=f"{name}:hinge_pin",
        type="cylinder",
        size=[0.003, DOOR_HALF],
        pos=[-DOOR_HALF, 0, PLATE_THICKNESS / 2],
        quat=[math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0],  # cylinder axis along y
        rgba=[0.6, 0.6, 0.6, 1],
        contype=0,
        conaffinity=0,
        mass=0,
    )
    add_handle(body, name, DOOR)
    return add_joint(body, name, DOOR, DYNAMICS)


KIND = Kind(
    template=DOOR,
    dynamics=DYNAMICS,
    colour=COLOUR,
    build=build,
    glyph="#4C72B0",
    sweep_effort=0.3,
    neighbours=("slide",),
    handling=Handling(grasp="along_axis", verdict="arc", swings_up=True, yields_across=True),
)
"""The door, as registered (:mod:`models.kinds.registry`)."""
