"""The cell's fixed imperfections: drawn once from the profile's ``cell_seed`` and built into the
session's model, as a real cell is built (and calibrated) once.

- each camera's true intrinsics (focal and principal point errors) and lens distortion;
- each camera's mounting error, in ``model.cam_pos`` / ``model.cam_quat`` (relative to the body it is
  fixed to: the world for the overview camera, the gripper for the wrist camera);
- the TCP bias: the physical gripper shifted on the flange (the gripper's mount body moved in the
  flange frame) while the arm's kinematics keep reporting the nominal TCP;
- the box's hardware per component kind: one joint damping, one joint friction (frictionloss) and one
  latch compliance (``solref[0]``) factor per kind, in the order of ``models.kinds.KIND_NAMES`` (door,
  slide, wheel). The session multiplies each component's per-trial factors
  (:mod:`twin.physics_draws`) by its kind's: a real cell's hinges, slides and bearings have the friction
  they have, trial after trial, and differ from the CAD-nominal model systematically per kind.

Draws are made in a fixed order (cameras in the order given, then the TCP bias, then the kind factors:
damping, friction, latch compliance, each for every kind) and always, even for zero magnitudes or identity
ranges, so one error's draw does not depend on whether another is zero. The kind factors come after
everything drawn before them existed, which therefore stays bit-identical.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass

import mujoco
import numpy as np

from puzzlebox.models.kinds import KIND_NAMES, registered_kinds
from puzzlebox.twin.reality import RealityProfile
from puzzlebox.twin.sensors.random_vectors import random_vector


@dataclass(frozen=True)
class CameraErrors:
    """One camera's fixed errors."""

    focal: np.ndarray
    """Relative errors of ``(fx, fy)`` [-]."""
    principal: np.ndarray
    """Errors of ``(cx, cy)`` [px]."""
    dist: np.ndarray
    """True lens distortion ``[k1, k2, p1, p2, k3]`` (k3 = 0)."""
    mount_translation: np.ndarray
    """Position error in the camera's body frame [m]."""
    mount_rotation: np.ndarray
    """Orientation error, a rotation vector in the camera's own frame [rad]."""

    def true_K(self, K_nominal: np.ndarray) -> np.ndarray:
        K = np.array(K_nominal, dtype=float)
        K[0, 0] *= 1.0 + self.focal[0]
        K[1, 1] *= 1.0 + self.focal[1]
        K[0, 2] += self.principal[0]
        K[1, 2] += self.principal[1]
        return K


@dataclass(frozen=True)
class KindFactors:
    """One cell's box hardware: a factor per component kind (``models.kinds.KIND_NAMES``) [-]."""

    joint_damping: dict[str, float]
    """Multiplier of the joint damping of every component of a kind."""
    joint_friction: dict[str, float]
    """Multiplier of the joint dry friction (frictionloss) of every component of a kind."""
    latch_compliance: dict[str, float]
    """Multiplier of the latch time constant (``solref[0]``) of every component of a kind."""

    def per_component(self, kinds: list[str] | tuple[str, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(damping, friction, latch)`` factors of components of ``kinds``, in that order [-]."""

        def column(table: dict[str, float]) -> np.ndarray:
            return np.array([table[k] for k in kinds], dtype=float)

        return column(self.joint_damping), column(self.joint_friction), column(self.latch_compliance)

    def to_dict(self) -> dict[str, dict[str, float]]:
        """Plain JSON-ready dict (for reports: the truth a system identification is scored against)."""
        return {
            "joint_damping": dict(self.joint_damping),
            "joint_friction": dict(self.joint_friction),
            "latch_compliance": dict(self.latch_compliance),
        }


@dataclass(frozen=True)
class CellImperfections:
    """Everything fixed about one cell."""

    cameras: dict[str, CameraErrors]
    tcp_bias: np.ndarray
    """Offset of the physical gripper from the nominal one, in the flange frame [m]."""
    kinds: KindFactors
    """The box hardware's per-kind physics factors (evaluation only: never for skills)."""


def draw_cell(profile: RealityProfile, camera_names: tuple[str, ...]) -> CellImperfections:
    """The cell of ``profile`` (its ``cell_seed``), with cameras ``camera_names`` (see the module docstring)."""
    rng = np.random.default_rng(np.random.SeedSequence(profile.cell_seed))
    c = profile.camera
    cameras = {}
    for name in camera_names:
        focal = rng.uniform(-c.focal_error, c.focal_error, 2)
        principal = rng.uniform(-c.principal_error, c.principal_error, 2)
        k1, k2 = rng.uniform(-c.k1, c.k1), rng.uniform(-c.k2, c.k2)
        p1, p2 = rng.uniform(-c.p, c.p, 2)
        translation = random_vector(rng, c.mount_translation)
        rotation = random_vector(rng, math.radians(c.mount_rotation))
        cameras[name] = CameraErrors(focal, principal, np.array([k1, k2, p1, p2, 0.0]), translation, rotation)
    tcp_bias = random_vector(rng, profile.arm.tcp_bias)
    physics = profile.physics
    tables = []
    for scale in (physics.kind_joint_damping_scale, physics.kind_joint_friction_scale,
                  physics.kind_latch_compliance_scale):  # fmt: skip
        factors = np.asarray(scale.draw(rng, len(KIND_NAMES)), dtype=float)
        tables.append({kind: float(f) for kind, f in zip(KIND_NAMES, factors, strict=True)})
    for kind in registered_kinds():  # kinds beyond the paper's: a stream of their own per name, so that
        if kind in KIND_NAMES:  # registering a kind changes no other kind's hardware
            continue
        kind_rng = np.random.default_rng(np.random.SeedSequence([profile.cell_seed, zlib.crc32(kind.encode())]))
        for table, scale in zip(tables, (physics.kind_joint_damping_scale, physics.kind_joint_friction_scale,
                                         physics.kind_latch_compliance_scale), strict=True):  # fmt: skip
            table[kind] = float(np.asarray(scale.draw(kind_rng, 1), dtype=float)[0])
    return CellImperfections(cameras, tcp_bias, KindFactors(*tables))


def apply_cell(model: mujoco.MjModel, cell: CellImperfections, gripper_body: int) -> bool:
    """Build the cell's mounting errors and TCP bias into ``model``; True if anything changed."""
    changed = False
    for name, errors in cell.cameras.items():
        cam = model.camera(name).id
        if errors.mount_translation.any():
            model.cam_pos[cam] += errors.mount_translation
            changed = True
        if errors.mount_rotation.any():
            # the rotation vector is in the camera's own frame: q <- q ⊗ exp(rotvec / 2)
            quat = model.cam_quat[cam].copy()
            mujoco.mju_quatIntegrate(quat, errors.mount_rotation, 1.0)
            model.cam_quat[cam] = quat
            changed = True
    if cell.tcp_bias.any():
        model.body_pos[gripper_body] += cell.tcp_bias  # body_pos is in the parent (flange) frame
        changed = True
    return changed
