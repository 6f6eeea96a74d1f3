"""The ``slide`` kind: a plate that slides in the lid plane along +x by ``travel`` [m] to open.

Frame origin: the marker centre when closed; the knob stands behind the marker (-x). Travel 50 mm, as
measured on this stack in DESIGN.md. Footprint: the plate's swept area,
``[-SLIDE_BACK, SLIDE_HALF + travel] x [-SLIDE_HALF, SLIDE_HALF]``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from puzzlebox.models.geometry import rectangle
from puzzlebox.models.kinds.kind import JointDynamics, Kind
from puzzlebox.models.kinds.parts import add_handle, add_joint, add_plate
from puzzlebox.models.kinds.template import HANDLE_MARGIN, HANDLE_OFFSET, MARKER_SIZE, KindTemplate

if TYPE_CHECKING:
    from dm_control import mjcf

SLIDE_HALF = 0.025
"""Half the width of the slide plate, and its extent ahead of the marker centre [m]."""
SLIDE_BACK = SLIDE_HALF + HANDLE_MARGIN + 0.005
"""Extent of the slide plate behind its marker centre, carrying the knob [m]."""

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
DYNAMICS = JointDynamics(damping=1.0, frictionloss=0.3)
"""A plate in a rail: more damping and dry friction than the pinned door and wheel."""
COLOUR = (0.85, 0.52, 0.32, 1)
"""RGBA of the plate (orange)."""


def build(body: mjcf.Element, name: str) -> mjcf.Element:
    """Plate, knob and prismatic joint of a slide; returns the joint."""
    add_plate(body, name, COLOUR, -SLIDE_BACK, SLIDE_HALF, SLIDE_HALF)
    add_handle(body, name, SLIDE)
    return add_joint(body, name, SLIDE, DYNAMICS)


KIND = Kind(
    template=SLIDE,
    dynamics=DYNAMICS,
    colour=COLOUR,
    build=build,
    glyph="#DD8452",
    sweep_effort=3.0,
    neighbours=("door", "wheel"),
)
"""The slide, as registered (:mod:`models.kinds.registry`)."""
