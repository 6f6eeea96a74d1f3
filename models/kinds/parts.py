"""MJCF parts every kind is made of: plate, handle post and joint, in the component frame.

The component body's frame is the component frame (:mod:`models.kinds.template`); parts stand on the
lid (z = 0) and the plate's top face is at ``PLATE_THICKNESS``. dm_control is only used through the
``body`` argument, so importing this module does not import MuJoCo.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from puzzlebox.models.kinds.kind import JointDynamics
from puzzlebox.models.kinds.template import HANDLE_HEIGHT, HANDLE_SIZE, KindTemplate

if TYPE_CHECKING:
    from dm_control import mjcf

PLATE_THICKNESS = 0.006
"""Thickness of door flaps, slide plates and wheel discs [m]."""
HANDLE_COLOUR = (0.15, 0.15, 0.15, 1)
"""RGBA of every handle post."""
PART_DENSITY = 700
"""Density of plates, discs and handles [kg/m³] (plastic-like: light parts the gripper moves easily)."""


def handle_geom_defaults() -> dict[str, object]:
    """Contact attributes of a handle geom."""
    # DESIGN.md, grasping: priority 2 so the handle's friction wins, friction 1, condim 4 (torsional).
    # Torsional friction 2 mm: a door handle pivots between the pads as the door swings; at 1 cm the
    # pads' grip resisted that pivot with ~1 N·m, which the wrist felt as a latch.
    return {"priority": 2, "friction": [1.0, 0.002, 0.0001], "condim": 4, "rgba": HANDLE_COLOUR}


def add_joint(body: mjcf.Element, name: str, template: KindTemplate, dynamics: JointDynamics) -> mjcf.Element:
    """The joint ``<name>:joint`` of the template, at mid-plate height, range ``[0, travel]``."""
    return body.add(
        "joint",
        name=f"{name}:joint",
        type=template.joint,
        axis=list(template.joint_axis),
        pos=[template.joint_origin[0], template.joint_origin[1], PLATE_THICKNESS / 2],
        range=[0.0, template.travel],
        limited=True,
        damping=dynamics.damping,
        frictionloss=dynamics.frictionloss,
        armature=dynamics.armature,
        solreflimit=[0.004, 1.0],  # stiffer end stops: a door resting on its limit sags < 0.1 deg
        solreffriction=[0.002, 1.0],  # stiff dry friction: an open door stays open (default 0.02 creeps)
    )


def add_handle(body: mjcf.Element, name: str, template: KindTemplate) -> None:
    """The handle post ``<name>:handle`` at the template's ``handle_xy``, standing on the plate."""
    hx, hy = template.handle_xy
    body.add(
        "geom",
        name=f"{name}:handle",
        type="box",
        size=[HANDLE_SIZE / 2, HANDLE_SIZE / 2, HANDLE_HEIGHT / 2],
        pos=[hx, hy, PLATE_THICKNESS + HANDLE_HEIGHT / 2],
        density=PART_DENSITY,
        **handle_geom_defaults(),
    )


def add_plate(
    body: mjcf.Element,
    name: str,
    colour: tuple[float, float, float, float],
    x_min: float,
    x_max: float,
    half_width: float,
) -> None:
    """The flat plate ``<name>:plate`` spanning ``[x_min, x_max] x [-half_width, half_width]`` [m]."""
    body.add(
        "geom",
        name=f"{name}:plate",
        type="box",
        size=[(x_max - x_min) / 2, half_width, PLATE_THICKNESS / 2],
        pos=[(x_max + x_min) / 2, 0, PLATE_THICKNESS / 2],
        density=PART_DENSITY,
        rgba=colour,
    )
