"""The puzzle box of a spec as an MJCF model: a box whose lid carries doors, slides and wheels.

Frames (see :mod:`models.kinds`): the model's root body ``lid`` sits at the lid frame (lid centre on
its top face, x along the length, z up); each component body sits at its spec pose in that frame,
so its body frame is the component frame. Per component ``<c>``: body ``<c>``, joint ``<c>:joint``
with its range the two states (0 and ``travel``), geoms ``<c>:plate`` (or ``:disc``),
``<c>:marker`` (the ArUco texture, visual only) and ``<c>:handle`` (the grasped post), site
``<c>:handle_site`` at the handle's top, and the latch ``<c>:latch``: a joint equality constraint,
inactive at start, that the twin engages while a lock rule holds the component (DESIGN.md: held a
door, slide and wheel to < 0.05 deg / 0.4 mm under a 50 N push with no MuJoCo warnings).

MJCF names may not contain '/' (dm_control's scope separator) and ':' separates a component's
elements, so a component's MJCF name is its spec name with every character outside
``[A-Za-z0-9_.-]`` replaced by '_' (made unique if needed): :func:`component_prefixes`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from dm_control import mjcf

from models.geometry import upright_pose
from models.kinds import (
    DOOR_HALF,
    HANDLE_HEIGHT,
    HANDLE_MARGIN,
    HANDLE_SIZE,
    SLIDE_BACK,
    SLIDE_HALF,
    WHEEL_RADIUS,
    get_kind,
)
from models.markers import add_marker_geom
from models.spec import PuzzleSpec

PLATE_THICKNESS = 0.006
"""Thickness of door flaps, slide plates and wheel discs [m]."""
MARKER_Z = PLATE_THICKNESS + 0.0005
"""Height of the marker's top face above the lid [m] (just proud of the plate so it never z-fights)."""
LATCH_SOLREF = (0.002, 1.0)
"""Latch stiffness (time constant [s], damping ratio), measured stiff and warning-free (DESIGN.md)."""
LATCH_SOLIMP = (0.95, 0.99, 0.001)


@dataclass(frozen=True)
class JointDynamics:
    """Passive joint properties of a kind (realistic for small plastic parts on metal pins/rails)."""

    damping: float
    """Viscous damping [N·m·s/rad or N·s/m]."""
    frictionloss: float
    """Dry friction [N·m or N]: keeps a released component where the robot left it."""
    armature: float = 1e-4
    """Reflected inertia [kg·m² or kg], for numerical stability of light parts."""


DYNAMICS = {
    "door": JointDynamics(damping=0.02, frictionloss=0.02),
    "slide": JointDynamics(damping=1.0, frictionloss=0.3),
    "wheel": JointDynamics(damping=0.02, frictionloss=0.02),
}
COLOURS = {"door": (0.30, 0.45, 0.70, 1), "slide": (0.85, 0.52, 0.32, 1), "wheel": (0.33, 0.66, 0.41, 1)}
HANDLE_COLOUR = (0.15, 0.15, 0.15, 1)


def component_prefixes(spec: PuzzleSpec) -> dict[str, str]:
    """MJCF name of every component, by spec name (safe characters, unique)."""
    out: dict[str, str] = {}
    used: set[str] = set()
    for c in spec.components:
        base = re.sub(r"[^A-Za-z0-9_.-]", "_", c.name) or "component"
        name, k = base, 1
        while name in used:
            k += 1
            name = f"{base}_{k}"
        used.add(name)
        out[c.name] = name
    return out


def _handle_geom_defaults() -> dict[str, object]:
    # DESIGN.md, grasping: priority 2 so the handle's friction wins, friction 1, condim 4 (torsional).
    # Torsional friction 2 mm: a door handle pivots between the pads as the door swings; at 1 cm the
    # pads' grip resisted that pivot with ~1 N·m, which the wrist felt as a latch.
    return {"priority": 2, "friction": [1.0, 0.002, 0.0001], "condim": 4, "rgba": HANDLE_COLOUR}


def build_puzzle_box(spec: PuzzleSpec, with_markers: bool = True) -> mjcf.RootElement:
    """The box model of a puzzle-box spec (see the module docstring). Attach it at the lid frame."""
    if spec.box is None:
        raise ValueError(f"spec {spec.name!r} has no box: not a puzzle box")
    length, width, height = spec.box.size
    root = mjcf.RootElement(model="box")
    root.default.geom.solref = [0.004, 1]
    box = root.worldbody.add("body", name="lid")
    box.add(
        "geom",
        name="shell",
        type="box",
        size=[length / 2, width / 2, height / 2],
        pos=[0, 0, -height / 2],
        rgba=[0.76, 0.64, 0.48, 1],
    )
    prefixes = component_prefixes(spec)
    for component in spec.components:
        name = prefixes[component.name]
        x, y, yaw = component.pose
        body = box.add("body", name=name, pos=[x, y, 0.0], quat=yaw_quat(yaw))
        builder = {"door": _door, "slide": _slide, "wheel": _wheel}[component.kind]
        joint = builder(body, name)
        template = get_kind(component.kind)
        hx, hy = template.handle_xy
        body.add("site", name=f"{name}:handle_site", pos=[hx, hy, PLATE_THICKNESS + HANDLE_HEIGHT], size=[0.003])
        body.add("site", name=f"{name}:frame", pos=[0, 0, PLATE_THICKNESS], size=[0.002], group=4)
        if with_markers:  # the marker frame is the component frame, on the plate's top face
            add_marker_geom(body, component.marker, f"{name}:marker", template.marker_size, pos=(0, 0, MARKER_Z))
        root.equality.add(
            "joint",
            name=f"{name}:latch",
            joint1=joint,
            polycoef=[0, 0, 0, 0, 0],
            active=False,
            solref=list(LATCH_SOLREF),
            solimp=list(LATCH_SOLIMP),
        )
        # the parts rest on the lid: contacts with the shell would only cost time (limits hold them)
        root.contact.add("exclude", name=f"{name}:on_lid", body1=box, body2=body)
    return root


def _add_joint(body: mjcf.Element, name: str, kind: str) -> mjcf.Element:
    template = get_kind(kind)
    dynamics = DYNAMICS[kind]
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


def _handle(body: mjcf.Element, name: str, kind: str) -> None:
    hx, hy = get_kind(kind).handle_xy
    body.add(
        "geom",
        name=f"{name}:handle",
        type="box",
        size=[HANDLE_SIZE / 2, HANDLE_SIZE / 2, HANDLE_HEIGHT / 2],
        pos=[hx, hy, PLATE_THICKNESS + HANDLE_HEIGHT / 2],
        density=700,
        **_handle_geom_defaults(),
    )


def _plate(body: mjcf.Element, name: str, kind: str, x_min: float, x_max: float, half_width: float) -> None:
    body.add(
        "geom",
        name=f"{name}:plate",
        type="box",
        size=[(x_max - x_min) / 2, half_width, PLATE_THICKNESS / 2],
        pos=[(x_max + x_min) / 2, 0, PLATE_THICKNESS / 2],
        density=700,
        rgba=COLOURS[kind],
    )


def _door(body: mjcf.Element, name: str) -> mjcf.Element:
    _plate(body, name, "door", -DOOR_HALF, DOOR_HALF + HANDLE_MARGIN, DOOR_HALF)
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
    _handle(body, name, "door")
    return _add_joint(body, name, "door")


def _slide(body: mjcf.Element, name: str) -> mjcf.Element:
    _plate(body, name, "slide", -SLIDE_BACK, SLIDE_HALF, SLIDE_HALF)
    _handle(body, name, "slide")
    return _add_joint(body, name, "slide")


def _wheel(body: mjcf.Element, name: str) -> mjcf.Element:
    body.add(
        "geom",
        name=f"{name}:disc",
        type="cylinder",
        size=[WHEEL_RADIUS, PLATE_THICKNESS / 2],
        pos=[0, 0, PLATE_THICKNESS / 2],
        density=700,
        rgba=COLOURS["wheel"],
    )
    _handle(body, name, "wheel")
    return _add_joint(body, name, "wheel")


def yaw_quat(yaw: float) -> list[float]:
    """Quaternion (w, x, y, z) of a rotation by ``yaw`` [rad] about z (MJCF euler is in degrees)."""
    return [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]


def lid_to_world(box_pose: tuple[float, float, float], height: float) -> np.ndarray:
    """4x4 transform of the lid frame in the world frame for a box at ``box_pose`` ``[x, y, yaw]``."""
    return upright_pose(*box_pose, height)
