"""The puzzle box of a spec as an MJCF model: a box whose lid carries doors, slides and wheels.

Frames (see :mod:`models.kinds`): the model's root body ``lid`` sits at the lid frame (lid centre on
its top face, x along the length, z up); each component body sits at its spec pose in that frame,
so its body frame is the component frame. Per component ``<c>``: body ``<c>``, joint ``<c>:joint``
with its range the two states (0 and ``travel``), geoms ``<c>:plate`` (or ``:disc``),
``<c>:marker`` (the ArUco texture, visual only) and ``<c>:handle`` (the grasped post), site
``<c>:handle_site`` at the handle's top, and the latch ``<c>:latch``: a joint equality constraint,
inactive at start, that the twin engages while a lock rule holds the component (DESIGN.md: held a
door, slide and wheel to < 0.05 deg / 0.4 mm under a 50 N push with no MuJoCo warnings).

Each component's parts (plate or disc, handle, joint) come from its registered kind
(:func:`models.kinds.registry.registered_kind`); this module holds no per-kind knowledge. A kind with
fixed parts (a lever's bracket, a drawer's rails) builds them in the component body and its moving
parts and joint in a child body: the marker and the sites go on the body the joint moves.

MJCF names may not contain '/' (dm_control's scope separator) and ':' separates a component's
elements, so a component's MJCF name is its spec name with every character outside
``[A-Za-z0-9_.-]`` replaced by '_' (made unique if needed): :func:`component_prefixes`.
"""

from __future__ import annotations

import math
import re

import numpy as np
from dm_control import mjcf

from puzzlebox.models.geometry import upright_pose
from puzzlebox.models.kinds.parts import PLATE_THICKNESS
from puzzlebox.models.kinds.registry import registered_kind
from puzzlebox.models.kinds.template import HANDLE_HEIGHT
from puzzlebox.models.markers import add_marker_geom
from puzzlebox.models.mechanism_mjcf import LOCK_MODES, LockMode, add_mechanisms
from puzzlebox.models.spec import PuzzleSpec

MARKER_Z = PLATE_THICKNESS + 0.0005
"""Height of the marker's top face above the lid [m] (just proud of the plate so it never z-fights)."""
LATCH_SOLREF = (0.002, 1.0)
"""Latch stiffness (time constant [s], damping ratio), measured stiff and warning-free (DESIGN.md)."""
LATCH_SOLIMP = (0.95, 0.99, 0.001)

__all__ = [  # PLATE_THICKNESS lives with the kinds' parts (models.kinds.parts); importers find it here too
    "LATCH_SOLIMP",
    "LOCK_MODES",
    "LockMode",
    "LATCH_SOLREF",
    "MARKER_Z",
    "PLATE_THICKNESS",
    "build_puzzle_box",
    "component_prefixes",
    "lid_to_world",
    "yaw_quat",
]


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


def build_puzzle_box(
    spec: PuzzleSpec, with_markers: bool = True, lock_features: bool = False, locks: LockMode = "contact"
) -> mjcf.RootElement:
    """The box model of a puzzle-box spec (see the module docstring). Attach it at the lid frame.

    With ``locks="contact"`` (the default) the spec's lock rules are mechanisms that block by contact
    (:mod:`models.lock_mechanisms`, :func:`add_mechanisms`): the model alone behaves as the spec says, in plain
    MuJoCo; rules no mechanism realizes are left to the latches (inactive in the model; the twin engages them).
    With ``locks="latch"`` the model has no mechanism: exactly the model built before mechanisms existed.

    With ``lock_features``, every visible lock feature of :func:`models.lock_features.lock_features` is added
    to its locker's body (so it moves with the locker's joint) as a visual-only mesh geom
    ``<locker>:lock:<locked>`` (mesh asset of the same name, vertices in the body frame [m]): no contacts
    (``contype = conaffinity = 0``), no mass, ``group`` 2. Without it (the default) the model is exactly the one
    built before lock features existed."""
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
    bodies: dict[str, mjcf.Element] = {}
    for component in spec.components:
        name = prefixes[component.name]
        x, y, yaw = component.pose
        body = box.add("body", name=name, pos=[x, y, 0.0], quat=yaw_quat(yaw))
        kind = registered_kind(component.kind)  # UnknownKindError lists the registered kinds
        joint = kind.build(body, name)
        moving = joint.parent  # the body the joint moves: the component's (or a child above fixed parts)
        template = kind.template
        hx, hy = template.handle_xy
        moving.add("site", name=f"{name}:handle_site", pos=[hx, hy, PLATE_THICKNESS + HANDLE_HEIGHT], size=[0.003])
        moving.add("site", name=f"{name}:frame", pos=[0, 0, PLATE_THICKNESS], size=[0.002], group=4)
        if with_markers:  # the marker frame is the component frame, on the plate's top face
            add_marker_geom(moving, component.marker, f"{name}:marker", template.marker_size, pos=(0, 0, MARKER_Z))
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
        if moving is not body:
            # a drawer's tray (a child body) rests on the shell's top face, touching it: with that contact a tray
            # pulled at 15 mm/s was pressed up by the lid with 20 N and held by as much friction (MuJoCo's
            # pyramidal cone couples the contact's damping to the sliding speed), which the hand read as a lock
            root.contact.add("exclude", name=f"{name}:moving_on_lid", body1=box, body2=moving)
        bodies[component.name] = moving
    if lock_features:
        _add_lock_features(root, spec, bodies, prefixes)
    if locks == "contact":
        add_mechanisms(root, spec, bodies, prefixes)
    elif locks != "latch":
        raise ValueError(f"locks must be one of {LOCK_MODES}, got {locks!r}")
    return root


def _add_lock_features(
    root: mjcf.RootElement, spec: PuzzleSpec, bodies: dict[str, mjcf.Element], prefixes: dict[str, str]
) -> None:
    """Each lock feature as a visual-only mesh geom in its locker's body (see :func:`build_puzzle_box`)."""
    from puzzlebox.models.lock_features import lock_features as features_of  # imports trimesh only when asked

    poses = {c.name: c.pose for c in spec.components}
    for feature in features_of(spec):
        x, y, yaw = poses[feature.locker]
        c, s = math.cos(yaw), math.sin(yaw)
        body = bodies[feature.locker]  # the body the locker's joint moves (a child above its fixed parts)
        raised = 0.0 if body.pos is None else float(body.pos[2])  # a child body stands at its kind's lift
        shifted = np.asarray(feature.mesh.vertices, dtype=float) - [x, y, raised]
        local = np.column_stack(
            [c * shifted[:, 0] + s * shifted[:, 1], -s * shifted[:, 0] + c * shifted[:, 1], shifted[:, 2]]
        )
        name = f"{prefixes[feature.locker]}:lock:{prefixes[feature.locked]}"
        mesh = root.asset.add(
            "mesh", name=name, vertex=local.ravel().tolist(), face=np.asarray(feature.mesh.faces).ravel().tolist()
        )
        body.add(
            "geom",
            name=name,
            type="mesh",
            mesh=mesh,
            rgba=list(feature.rgba),
            contype=0,
            conaffinity=0,
            group=2,
            mass=0,
        )


def yaw_quat(yaw: float) -> list[float]:
    """Quaternion (w, x, y, z) of a rotation by ``yaw`` [rad] about z (MJCF euler is in degrees)."""
    return [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]


def lid_to_world(box_pose: tuple[float, float, float], height: float) -> np.ndarray:
    """4x4 transform of the lid frame in the world frame for a box at ``box_pose`` ``[x, y, yaw]``."""
    return upright_pose(*box_pose, height)
