"""The lock mechanisms of a spec (:mod:`models.lock_mechanisms`) as MJCF geoms on the components' moving bodies.

Each one-way latch is a sprung pawl body ``<A>:latch:<B>:pawl`` (slide joint ``...:spring`` along its e3, a row of
convex mesh teeth ``...:tooth:<k>`` along the locker's path) on the locker's moving body and a convex mesh
lug ``<A>:latch:<B>:lug`` on the locked part's.
Each interlock's wall is a chain of capsules in the locker's moving body, its rod a chain in the locked part's,
named ``<A>:interlock:<B>:wall:<k>`` and ``<A>:interlock:<B>:rod:<k>`` (MJCF component names). They collide
with each other only: both have the contact bit of their interlock alone (``contype = conaffinity = 2**k``,
``k`` in 1..30; every other geom of the scene has bit 0), so the robot, the table, the lid and other interlocks
pass them. They sit in geom group 3, which MuJoCo does not draw by default: the cameras see the box as before
(the mechanisms lie under the lid but for a door's hook, in the open state).
"""

from __future__ import annotations

import dataclasses
import functools
from typing import TYPE_CHECKING, Any, Literal

import mujoco
import numpy as np

from puzzlebox.models.joint_motion import JointMotion
from puzzlebox.models.kinds.parts import PART_DENSITY
from puzzlebox.models.kinds.registry import get_kind
from puzzlebox.models.lock_mechanisms import (
    TOOTH_RISE,
    Interlock,
    MechanismLayout,
    OneWayLatch,
    design_mechanisms,
)
from puzzlebox.models.spec import PuzzleSpec

if TYPE_CHECKING:
    from dm_control import mjcf

__all__ = ["LOCK_MODES", "MECHANISM_GROUP", "LockMode", "add_mechanisms", "mechanism_layout"]

LockMode = Literal["contact", "latch"]
"""How a model holds its lock rules: ``contact`` (mechanisms, latches only for what they do not realize) or
``latch`` (rule-driven joint equalities only, as before mechanisms existed)."""
LOCK_MODES: tuple[str, ...] = ("contact", "latch")
MECHANISM_GROUP = 3
"""Geom group of the mechanisms (not drawn by MuJoCo's default visual options)."""
MECHANISM_RGBA = (0.72, 0.72, 0.75, 1.0)
"""Steel grey."""
MECHANISM_SOLIMP = (0.95, 0.99, 0.001)
"""Stiff contacts (as the latches' constraint, DESIGN.md): a bolt gives < 1 mm under the robot's push."""
LATCH_CONTACT_SOLIMP = (0.99, 0.999, 0.001)
"""Stiffer still for a one-way latch's tooth and lug. MuJoCo softens a contact by ``(1 - d) / d`` times an
estimate of its inverse effective mass taken from each body's mobility averaged over directions
(``body_invweight0``): a pawl (its own spring joint) on a light slide is estimated ~13x more mobile than it is
along the tooth's normal, across both joints, so with ``d = 0.99`` a wheel's lug 12 mm from its axis, pushed with
1.5 N m, sank through the tooth (``random-n8-s32``); ``d = 0.999`` holds it within 6 % of its travel."""
MECHANISM_SOLREF = (0.004, 1.0)
"""Time constant [s] (twice the 2 ms timestep, MuJoCo's stiffest stable value) and damping ratio."""
MECHANISM_FRICTION = (0.1, 0.005, 0.0001)
"""Greased steel on steel: little sliding friction, so a blocked push does not drag the part it meets."""
PAWL_STIFFNESS = 100.0
"""Spring of a one-way latch's pawl [N/m]."""
PAWL_PRELOAD = 0.01
"""Where the pawl's spring would rest, past its stop [m]: it presses the pawl on its stop with 1 N, and a lug
pressing its bevel down meets at most 1.3 N (nothing beside the 25 N a robot's push gives)."""
PAWL_PLAY = 0.0005
"""How far the pawl may retract past the tooth's rise [m]."""
PAWL_DAMPING = 0.05
"""Damping of the pawl's slide [N·s/m]: it springs back in a few milliseconds, without ringing."""
PAWL_ARMATURE = 0.02
"""Reflected mass of the pawl's slide [kg] (its spring's and guide's): a bare 0.6 g tooth pressed by 1 N sank 8 mm
into its stop's soft limit; with it, < 0.5 mm."""
STEEL_DENSITY = 7800
"""Density of the pawl's tooth [kg/m³]."""
CONTACT_BITS = 30
"""Contact bits 1..30 available to interlocks (bit 0 is every other geom's)."""


def mechanism_layout(spec: PuzzleSpec) -> MechanismLayout:
    """:func:`models.lock_mechanisms.design_mechanisms`, cached per spec wherever its box stands (the design is
    in the lid frame and takes about a second; a trial under a profile that places boxes places each anew)."""
    unplaced = spec if spec.box is None else dataclasses.replace(spec, box=dataclasses.replace(spec.box, pose=None))
    return _layout(unplaced)


@functools.lru_cache(maxsize=64)
def _layout(spec: PuzzleSpec) -> MechanismLayout:
    return design_mechanisms(spec)


def add_mechanisms(
    root: mjcf.RootElement, spec: PuzzleSpec, bodies: dict[str, mjcf.Element], prefixes: dict[str, str]
) -> MechanismLayout:
    """Add every interlock of the spec's mechanism layout to ``root``: walls and rods as capsule chains in the
    moving bodies ``bodies`` (by spec name) of the locker and the locked part. Returns the layout."""
    layout = mechanism_layout(spec)
    by_name = {c.name: c for c in spec.components}
    for k, interlock in enumerate(layout.interlocks):
        bit = 1 << (1 + k % CONTACT_BITS)
        base = f"{prefixes[interlock.locker]}:interlock:{prefixes[interlock.locked]}"
        for role, owner, polyline in (
            ("wall", interlock.locker, interlock.wall),
            ("rod", interlock.locked, interlock.rod),
        ):
            component = by_name[owner]
            motion = JointMotion.of(get_kind(component.kind), tuple(component.pose))
            chains = [motion.to_body(chain, 0.0) for chain in polyline]
            _add_chain(bodies[owner], f"{base}:{role}", chains, interlock, bit)
    for k, latch in enumerate(layout.latches, start=len(layout.interlocks)):
        bit = 1 << (1 + k % CONTACT_BITS)
        _add_latch(root, latch, bodies, prefixes, by_name, bit)
    return layout


def _carried(part: mjcf.Element, name: str, **attributes: Any) -> mjcf.Element:
    """A body ``name`` on a part's moving body ``part``, balanced as that body is (its ``gravcomp``): a lever's arm is
    balanced on its pin (``models.kinds.lever``), and the walls, rods, lugs and pawls it carries unbalanced turned it
    (0.06-0.5 g each, 0.2-0.9 mN·m in all, 2-8 % of its weight's moment, past MuJoCo's soft dry friction: a free lever
    of a hard box crept open at 0.14-0.32 % of its travel per second, up to its stop in a training episode, where a
    grasp aimed at its closed handle closed on nothing above it)."""
    if part.gravcomp is not None:
        attributes["gravcomp"] = part.gravcomp
    return part.add("body", name=name, **attributes)


def _quat(rotation: np.ndarray) -> list[float]:
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(rotation).ravel())
    return quat.tolist()


def _add_latch(root, latch: OneWayLatch, bodies, prefixes, by_name, bit: int) -> None:
    """A one-way latch: the sprung pawl (a body on the locker's moving body, sliding along e3 with its tooth) and
    the lug (a box on the locked part's moving body), both posed from the design state (A at a, B at b)."""
    base = f"{prefixes[latch.locker]}:latch:{prefixes[latch.locked]}"
    locker, locked = by_name[latch.locker], by_name[latch.locked]
    a = JointMotion.of(get_kind(locker.kind), tuple(locker.pose))
    b = JointMotion.of(get_kind(locked.kind), tuple(locked.pose))
    q_a, q_b = a.q(latch.locker_state), b.q(latch.locked_state)
    contact = {
        "contype": bit, "conaffinity": bit, "group": MECHANISM_GROUP, "rgba": list(MECHANISM_RGBA),
        "friction": list(MECHANISM_FRICTION), "solref": list(MECHANISM_SOLREF),
        "solimp": list(LATCH_CONTACT_SOLIMP),
    }  # fmt: skip
    # the pawl: its frame is (e1, e2, e3) at X, written in the locker's moving body frame
    rotation_a = np.column_stack([a.direction_to_body(latch.frame[:, i], q_a) for i in range(3)])
    pawl = _carried(
        bodies[latch.locker],
        f"{base}:pawl",
        pos=a.to_body(latch.crossing[None], q_a)[0].tolist(),
        quat=_quat(rotation_a),
    )
    pawl.add(
        "joint", name=f"{base}:spring", type="slide", axis=[0, 0, 1], range=[-(TOOTH_RISE + PAWL_PLAY), 0.0],
        limited=True, stiffness=PAWL_STIFFNESS, springref=PAWL_PRELOAD, damping=PAWL_DAMPING, armature=PAWL_ARMATURE,
        solreflimit=list(MECHANISM_SOLREF), solimplimit=list(MECHANISM_SOLIMP),
    )  # fmt: skip
    for k, vertices in enumerate(latch.tooth_vertices(a)):  # the row of teeth along A's path
        mesh = root.asset.add("mesh", name=f"{base}:tooth:{k}", vertex=np.asarray(vertices).ravel().tolist())
        pawl.add("geom", name=f"{base}:tooth:{k}", type="mesh", mesh=mesh, density=STEEL_DENSITY, **contact)
    # the lug, on the locked part
    lug_world = latch.crossing + latch.lug_vertices() @ latch.frame.T
    mesh = root.asset.add("mesh", name=f"{base}:lug", vertex=b.to_body(lug_world, q_b).ravel().tolist())
    _carried(bodies[latch.locked], f"{base}:lug").add(
        "geom", name=f"{base}:lug", type="mesh", mesh=mesh, density=PART_DENSITY, **contact
    )


def _add_chain(body: mjcf.Element, name: str, chains: list[np.ndarray], interlock: Interlock, bit: int) -> None:
    """The capsules of a wall's or rod's chains, numbered ``<name>:<k>`` across all of them."""
    segments = [(p, q) for points in chains for p, q in zip(points[:-1], points[1:], strict=True)]
    # a body of its own, fixed to the part: its contact bit alone, so MuJoCo's broad phase pairs it with its
    # partner and nothing else (in the part's own body, the part's plate bit let every neighbour's geoms through:
    # a paper scene stepped 1.7x slower)
    body = _carried(body, name)
    for k, (p, q) in enumerate(segments):
        body.add(
            "geom",
            name=f"{name}:{k}",
            type="capsule",
            fromto=[*map(float, p), *map(float, q)],
            size=[interlock.radius],
            contype=bit,
            conaffinity=bit,
            group=MECHANISM_GROUP,
            rgba=list(MECHANISM_RGBA),
            density=PART_DENSITY,
            friction=list(MECHANISM_FRICTION),
            solref=list(MECHANISM_SOLREF),
            solimp=list(MECHANISM_SOLIMP),
        )
