"""The ``lever`` kind: a flat arm on a bracket, hinged about a horizontal axis in the lid plane, pressed
down to open.

Frame origin: the marker centre when closed, in the lid plane (the arm itself stands ``LEVER_LIFT`` above
it). +x points from the pivot to the free end, where the handle stands. The pivot is the line
``x = -LEVER_BACK`` parallel to y, at the arm's mid-thickness; opening (state 1) presses the free end down
toward the lid by ``travel`` (19 deg: the arm's tip stops 3.6 mm above the lid). The marker centre turns
with the arm, 12 mm about the pivot: a try's outcome is read from it as a door's, as the fraction of the
travel it turned (``Handling.verdict = "arc"``), always from the wrist camera close up (``read_close_up``):
an overview's depth is off by more than that under a realistic calibration. The marker's tilt (19 deg) was
tried and dropped: posed close up, it read a lever left at 2 deg at 5 deg. The fingers close along the
pivot axis, as on a door: the handle turns between the pads as the arm goes down.

Parts: a fixed bracket, two cheeks beside the arm up to the pivot pin (the component body, on the lid), and
the arm, its handle and marker in the child body ``<name>:arm`` at ``LEVER_LIFT``. Footprint: the bracket
and the arm and room for fingers ahead of its handle,
``[-LEVER_BACK - BRACKET_DEPTH / 2, LEVER_BACK + HANDLE_MARGIN + FINGER_ROOM] x [-OUTER_HALF, OUTER_HALF]``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from puzzlebox.models.geometry import rectangle
from puzzlebox.models.kinds.kind import Handling, JointDynamics, Kind
from puzzlebox.models.kinds.parts import PART_DENSITY, PLATE_THICKNESS, add_handle, add_joint, add_plate
from puzzlebox.models.kinds.template import HANDLE_MARGIN, HANDLE_OFFSET, MARKER_SIZE, KindTemplate

if TYPE_CHECKING:
    from dm_control import mjcf

LEVER_HALF = 0.028
"""Half the width of the arm [m]: the marker's quiet zone (24 mm) with 4 mm to spare."""
LEVER_BACK = 0.035
"""Distance of the pivot behind the marker centre [m] (as a door's hinge)."""
LEVER_LIFT = 0.030
"""Height of the arm's underside above the lid, closed [m]: room for the pressed arm's tip."""
BRACKET_DEPTH = 0.012
"""Length of the bracket's cheeks along x [m], centred on the pivot."""
CHEEK_WIDTH = 0.004
"""Width of each of the bracket's two cheeks [m], beside the arm."""
CHEEK_GAP = 0.001
"""Play between the arm and a cheek [m]."""
OUTER_HALF = LEVER_HALF + CHEEK_GAP + CHEEK_WIDTH
"""Half the width of the lever across its cheeks [m]."""
ARM_LENGTH = LEVER_BACK + LEVER_BACK + HANDLE_MARGIN
"""From the pivot to the arm's free end [m]."""
FINGER_ROOM = 0.015
"""Room kept free ahead of the free end [m]: the handle stands 30 mm higher than a door's (71 mm above the lid),
so a neighbour's fingers coming down beside it need more than the layouts' 15 mm clearance (a slide's knob 32 mm
from a lever's handle had its finger land on it at 62 N)."""

LEVER = KindTemplate(
    name="lever",
    joint="hinge",
    joint_axis=(0.0, 1.0, 0.0),  # right-handed about +y takes the +x (free) end down
    joint_origin=(-LEVER_BACK, 0.0, 0.0),
    travel=math.radians(19.0),  # sin(19 deg) * 81 mm = 26.4 mm of the 30 mm to the lid
    marker_size=MARKER_SIZE,
    handle_xy=(HANDLE_OFFSET, 0.0),
    footprint=rectangle(
        -LEVER_BACK - BRACKET_DEPTH / 2, LEVER_BACK + HANDLE_MARGIN + FINGER_ROOM, -OUTER_HALF, OUTER_HALF
    ),
    lift=LEVER_LIFT,
)
DYNAMICS = JointDynamics(damping=0.02, frictionloss=0.03)
"""A light, balanced arm on a metal pin: little damping, dry friction that holds it where it was left."""
COLOUR = (0.55, 0.42, 0.72, 1)
"""RGBA of the arm (purple)."""
BRACKET_COLOUR = (0.6, 0.6, 0.6, 1)
"""RGBA of the fixed bracket (grey)."""


def build(body: mjcf.Element, name: str) -> mjcf.Element:
    """Bracket (fixed, on the lid), arm, handle and pivot of a lever; returns the pivot joint."""
    cheek_height = LEVER_LIFT + PLATE_THICKNESS  # up to the pin, beside the arm: the arm turns between them
    for side, sign in (("left", 1), ("right", -1)):
        body.add(
            "geom",
            name=f"{name}:bracket_{side}",
            type="box",
            size=[BRACKET_DEPTH / 2, CHEEK_WIDTH / 2, cheek_height / 2],
            pos=[-LEVER_BACK, sign * (LEVER_HALF + CHEEK_GAP + CHEEK_WIDTH / 2), cheek_height / 2],
            density=PART_DENSITY,
            rgba=BRACKET_COLOUR,
        )
    body.add(  # the pivot pin, for the eye
        "geom",
        name=f"{name}:pin",
        type="cylinder",
        size=[0.002, LEVER_HALF + CHEEK_GAP + CHEEK_WIDTH],
        pos=[-LEVER_BACK, 0, LEVER_LIFT + PLATE_THICKNESS / 2],
        quat=[math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0],  # cylinder axis along y
        rgba=BRACKET_COLOUR,
        contype=0,
        conaffinity=0,
        mass=0,
    )
    # gravcomp: the arm is balanced on its pin (a real lever's counter-spring), so it stays where it is left in
    # either state: unbalanced, its weight turned it open past MuJoCo's soft dry friction (8 deg in 25 s)
    arm = body.add("body", name=f"{name}:arm", pos=[0, 0, LEVER_LIFT], gravcomp=1)
    add_plate(arm, name, COLOUR, -LEVER_BACK, LEVER_BACK + HANDLE_MARGIN, LEVER_HALF)
    add_handle(arm, name, LEVER)
    return add_joint(arm, name, LEVER, DYNAMICS)


KIND = Kind(
    template=LEVER,
    dynamics=DYNAMICS,
    colour=COLOUR,
    build=build,
    glyph="#8172B3",
    sweep_effort=0.3,
    neighbours=("door", "slide", "wheel"),
    handling=Handling(grasp="along_axis", verdict="arc", read_close_up=True),
)
"""The lever, as registered (:mod:`models.kinds.registry`)."""
