"""Joint models from perception: what a primitive needs to move a component, derived from the marker
pose and the kind's geometry template (``models.kinds``) — as a real robot would, with no access to
the simulator's joints.

All vectors are in the robot base frame [m]. For a hinge the motion is a rotation by up to ``travel``
[rad] about ``axis`` through ``origin``; for a slide a translation by ``travel`` [m] along ``axis``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from puzzlebox.models.kinds import HANDLE_HEIGHT, Handling, get_kind, registered_kind
from puzzlebox.models.puzzle_box import PLATE_THICKNESS


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``np.cross`` of two 3-vectors, bit for bit, without its ~15 us of generality (primitives call it
    every control tick)."""
    a0, a1, a2 = a.tolist()
    b0, b1, b2 = b.tolist()
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


@dataclass(frozen=True)
class JointModel:
    """A component's joint as the robot believes it to be."""

    kind: str
    joint: str
    """``hinge`` or ``slide``."""
    axis: np.ndarray
    """Unit joint axis in the base frame (positive motion opens the component)."""
    origin: np.ndarray
    """A point on the joint axis [m] (for slides: the grasp point at state 0)."""
    grasp_point: np.ndarray
    """Where the fingers close on the handle, state 0 [m]: the handle's upper half."""
    travel: float
    """Motion from state 0 to state 1 [rad or m]."""

    @property
    def handling(self) -> Handling:
        """How the kind is grasped and moved, and how its marker shows a move (the kind module's)."""
        return registered_kind(self.kind).handling

    def grasp_point_at(self, fraction: float) -> np.ndarray:
        """The grasp point after moving ``fraction`` (0..1, negative to close) of the travel [m]."""
        amount = fraction * self.travel
        if self.joint == "slide":
            return self.grasp_point + amount * self.axis
        r = self.grasp_point - self.origin
        k = self.axis
        rotated = r * np.cos(amount) + cross(k, r) * np.sin(amount) + k * np.dot(k, r) * (1 - np.cos(amount))
        return self.origin + rotated

    def fraction_between(self, before: np.ndarray, after: np.ndarray) -> float:
        """Fraction of the travel (signed: positive opens) that carries a point of the part from ``before``
        to ``after`` [m]: the displacement along a slide's axis, the turn about a hinge's axis."""
        if self.joint == "slide":
            return float(np.dot(after - before, self.axis) / self.travel)
        a, b = before - self.origin, after - self.origin
        a -= np.dot(a, self.axis) * self.axis
        b -= np.dot(b, self.axis) * self.axis
        return float(np.arctan2(np.dot(self.axis, cross(a, b)), np.dot(a, b)) / self.travel)

    def motion_direction(self, fraction: float) -> np.ndarray:
        """Unit direction in which the grasp point moves when opening, at ``fraction`` of the travel."""
        if self.joint == "slide":
            return self.axis.copy()
        tangent = cross(self.axis, self.grasp_point_at(fraction) - self.origin)
        return tangent / np.linalg.norm(tangent)


GRASP_DEPTH = 0.012
"""How far below the handle's top the finger pads close [m] (the pads are 19 mm tall)."""


def joint_model(kind: str, T_base_component: np.ndarray) -> JointModel:
    """The joint model of a component of ``kind`` whose frame (= its marker frame, state 0) is
    ``T_base_component`` (4x4; the marker sits on the plate's top face). Give it an upright pose
    (``skills.perception.upright_pose``): a marker's perceived tilt is not to be trusted."""
    template = get_kind(kind)
    R, p = T_base_component[:3, :3], T_base_component[:3, 3]
    # the marker frame is on the top face; the joint origin and handle are given from the plate bottom. The
    # pose is the marker's in the lid's plane (perception's upright pose): a raised part's plate sits ``lift`` higher
    plate_bottom = p - R[:, 2] * (PLATE_THICKNESS + 0.0005 - template.lift)

    def to_base(point: tuple[float, float, float]) -> np.ndarray:
        return plate_bottom + R @ np.asarray(point, dtype=float)

    hx, hy = template.handle_xy
    grasp = to_base((hx, hy, PLATE_THICKNESS + HANDLE_HEIGHT - GRASP_DEPTH))
    axis = R @ np.asarray(template.joint_axis, dtype=float)
    ox, oy, _ = template.joint_origin
    origin = to_base((ox, oy, PLATE_THICKNESS / 2)) if template.joint == "hinge" else grasp.copy()
    return JointModel(kind, template.joint, axis / np.linalg.norm(axis), origin, grasp, template.travel)
