"""The cell's fixed imperfections: drawn once from the profile's ``cell_seed`` and built into the
session's model, as a real cell is built (and calibrated) once.

- each camera's true intrinsics (focal and principal point errors) and lens distortion;
- each camera's mounting error, in ``model.cam_pos`` / ``model.cam_quat`` (relative to the body it is
  fixed to: the world for the overview camera, the gripper for the wrist camera);
- the TCP bias: the physical gripper shifted on the flange (the gripper's mount body moved in the
  flange frame) while the arm's kinematics keep reporting the nominal TCP.

Draws are made in a fixed order (cameras in the order given, then the TCP bias) and always, even for
zero magnitudes, so one error's draw does not depend on whether another is zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from twin.reality import RealityProfile
from twin.sensors.random_vectors import random_vector


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
class CellImperfections:
    """Everything fixed about one cell."""

    cameras: dict[str, CameraErrors]
    tcp_bias: np.ndarray
    """Offset of the physical gripper from the nominal one, in the flange frame [m]."""


def draw_cell(profile: RealityProfile, camera_names: tuple[str, ...]) -> CellImperfections:
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
    return CellImperfections(cameras, random_vector(rng, profile.arm.tcp_bias))


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
