"""The lock mechanisms of a spec (:mod:`models.lock_mechanisms`) as MJCF geoms on the components' moving bodies.

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
from typing import TYPE_CHECKING, Literal

import numpy as np

from models.joint_motion import JointMotion
from models.kinds.parts import PART_DENSITY
from models.kinds.registry import get_kind
from models.lock_mechanisms import Interlock, MechanismLayout, design_mechanisms
from models.spec import PuzzleSpec

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
MECHANISM_SOLREF = (0.004, 1.0)
"""Time constant [s] (twice the 2 ms timestep, MuJoCo's stiffest stable value) and damping ratio."""
MECHANISM_FRICTION = (0.1, 0.005, 0.0001)
"""Greased steel on steel: little sliding friction, so a blocked push does not drag the part it meets."""
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
            _add_chain(bodies[owner], f"{base}:{role}", motion.to_body(polyline, 0.0), interlock, bit)
    return layout


def _add_chain(body: mjcf.Element, name: str, points: np.ndarray, interlock: Interlock, bit: int) -> None:
    for k, (p, q) in enumerate(zip(points[:-1], points[1:], strict=True)):
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
