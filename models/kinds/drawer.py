"""The ``drawer`` kind: a tray pulled out of the box's side wall along +x by ``travel`` [m] to open.

A drawer is mounted at the lid's edge (:attr:`models.kinds.template.KindTemplate.edge_x`): its +x points out
of the lid, perpendicular to that edge, and the front face of its closed tray (x = ``DRAWER_FRONT`` in its
frame) is flush with the box's side wall, i.e. on the lid edge in plan, so pulling it slides the tray out past
the box's side. The housing behind the tray stays on the lid, and the tray's top is at lid level with its
marker on top, where the overview camera reads it.

Frame origin: the marker centre when closed, on the tray's top face; +x points out of the housing and out of
the lid, toward the handle at the tray's front (the robot pulls it, where a slide's knob behind its marker is
pushed). Travel 45 mm. Parts: a fixed housing (a back block the tray comes out of and two side rails ending
at the front face, in the component body on the lid) and the tray, its handle and marker in the child body
``<name>:tray``. Footprint: housing, rails and the tray's swept area,
``[-DRAWER_BACK - HOUSING_DEPTH, DRAWER_FRONT + travel] x [-RAIL_OUTER, RAIL_OUTER]``; the part at
x <= ``DRAWER_FRONT`` lies on the lid, the part beyond is swept outside the lid, past its edge.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from puzzlebox.models.geometry import rectangle
from puzzlebox.models.kinds.kind import Handling, JointDynamics, Kind
from puzzlebox.models.kinds.parts import PART_DENSITY, add_handle, add_joint, add_plate
from puzzlebox.models.kinds.template import HANDLE_MARGIN, HANDLE_OFFSET, MARKER_SIZE, KindTemplate

if TYPE_CHECKING:
    from dm_control import mjcf

DRAWER_HALF = 0.026
"""Half the width of the tray [m]: the marker's quiet zone (24 mm) with 2 mm to spare."""
DRAWER_BACK = 0.026
"""Extent of the tray behind its marker centre [m]."""
DRAWER_FRONT = HANDLE_OFFSET + HANDLE_MARGIN
"""Extent of the tray ahead of its marker centre, carrying the handle [m]."""
TRAVEL = 0.045
"""How far the tray is pulled out [m]."""
HOUSING_DEPTH = 0.012
"""Length of the housing block behind the tray [m]."""
HOUSING_HEIGHT = 0.014
"""Height of the housing block and of the rails above the lid [m] (the tray is 6 mm thick)."""
RAIL_WIDTH = 0.004
"""Width of a side rail [m]."""
RAIL_OUTER = DRAWER_HALF + 0.001 + RAIL_WIDTH
"""Outer face of a side rail from the tray's centre line [m] (1 mm of play beside the tray)."""

DRAWER = KindTemplate(
    name="drawer",
    joint="slide",
    joint_axis=(1.0, 0.0, 0.0),
    joint_origin=(0.0, 0.0, 0.0),
    travel=TRAVEL,
    marker_size=MARKER_SIZE,
    handle_xy=(HANDLE_OFFSET, 0.0),
    footprint=rectangle(-DRAWER_BACK - HOUSING_DEPTH, DRAWER_FRONT + TRAVEL, -RAIL_OUTER, RAIL_OUTER),
    edge_x=DRAWER_FRONT,
)
DYNAMICS = JointDynamics(damping=1.0, frictionloss=0.3)
"""A tray in rails: as a slide's plate."""
COLOUR = (0.80, 0.72, 0.30, 1)
"""RGBA of the tray (ochre)."""
HOUSING_COLOUR = (0.45, 0.36, 0.25, 1)
"""RGBA of the housing and rails (dark brown)."""


def build(body: mjcf.Element, name: str) -> mjcf.Element:
    """Housing and rails (fixed, on the lid), tray, handle and prismatic joint of a drawer; returns the joint."""
    fixed = {"type": "box", "density": PART_DENSITY, "rgba": HOUSING_COLOUR}
    body.add(
        "geom",
        name=f"{name}:housing",
        size=[HOUSING_DEPTH / 2, RAIL_OUTER, HOUSING_HEIGHT / 2],
        pos=[-DRAWER_BACK - HOUSING_DEPTH / 2, 0, HOUSING_HEIGHT / 2],
        **fixed,
    )
    rail_length = DRAWER_BACK + DRAWER_FRONT
    for side, sign in (("left", 1), ("right", -1)):
        body.add(
            "geom",
            name=f"{name}:rail_{side}",
            size=[rail_length / 2, RAIL_WIDTH / 2, HOUSING_HEIGHT / 2],
            pos=[(DRAWER_FRONT - DRAWER_BACK) / 2, sign * (RAIL_OUTER - RAIL_WIDTH / 2), HOUSING_HEIGHT / 2],
            **fixed,
        )
    tray = body.add("body", name=f"{name}:tray")
    add_plate(tray, name, COLOUR, -DRAWER_BACK, DRAWER_FRONT, DRAWER_HALF)
    add_handle(tray, name, DRAWER)
    return add_joint(tray, name, DRAWER, DYNAMICS)


KIND = Kind(
    template=DRAWER,
    dynamics=DYNAMICS,
    colour=COLOUR,
    build=build,
    glyph="#CCB974",
    sweep_effort=3.0,
    neighbours=("door", "lever", "wheel"),
    handling=Handling(),
)
"""The drawer, as registered (:mod:`models.kinds.registry`)."""
