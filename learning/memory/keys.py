"""Memory keys: the pose of component j in component i's frame, as a full rigid transform (SE(3)).

The paper keys memories by world-frame differences (dx, dy, dsin, dcos); those change when the whole
box is moved or turned on the table. Expressing j in i's frame does not: a box anywhere on the table
— or a computer case turned any way in 3-D — recalls the same memories.

A key (:data:`SE3_KEY_SIZE` = 12 numbers) is ``[p / position_scale, rotation_weight / sqrt(2) * R]``:
``p`` (3) is j's origin in i's frame [m] and ``R`` (3 x 3, row-major) j's orientation in i's frame,
``R_i^T R_j``. Keys are compared by Euclidean distance, so

    d^2 = |p_a - p_b|^2 / position_scale^2 + rotation_weight^2 * (2 sin(theta / 2))^2

with ``theta`` the angle of the rotation between the two keys' orientations: ``|R_a - R_b|_F^2 / 2 = 8
sin^2(theta/2) / 2`` is the squared chord of ``theta`` on the unit circle. The **rotation weight** is the
number of key units one unit of chord weighs (about one per radian for small angles); at the default 1.0
a planar pose — a rotation about z by the yaw — gives exactly the distance of the paper-era planar key
``(x, y, sin yaw, cos yaw)``, so one memory holds puzzle boxes and 6-DOF disassembly scenes and recalls
planar boxes as before. ``position_scale`` [m] is the length that weighs like one key unit.

:func:`relative_pose_keys` is the compact form the graph network's edge features use (planar:
``x, y, sin, cos``; 6-DOF: ``x, y, z``, sin and cos of the relative roll, pitch, yaw); memories stored
before schema 4 hold those and are converted with :func:`se3_key_from_legacy`.
"""

from __future__ import annotations

import math

import numpy as np

PLANAR_KEY_SIZE = 4
"""Compact planar key: (x, y) of j in i's frame / scale, sin and cos of the relative yaw."""
SPATIAL_KEY_SIZE = 9
"""Compact 6-DOF key: (x, y, z) of j in i's frame / scale, sin and cos of relative roll, pitch, yaw."""
SE3_KEY_SIZE = 12
"""Memory key: (x, y, z) of j in i's frame / scale, then the relative rotation matrix (row-major) times
``rotation_weight / sqrt(2)``."""
DEFAULT_ROTATION_WEIGHT = 1.0
"""Key units per unit of chord ``2 sin(theta / 2)`` of a relative rotation: 1.0 keeps planar distances
identical to the (x, y, sin, cos) keys of memories before SE(3) keys."""


def key_size(pose_size: int) -> int:
    """Size of a compact key (:func:`relative_pose_keys`) for poses of ``pose_size`` numbers (3 or 6)."""
    return PLANAR_KEY_SIZE if pose_size == 3 else SPATIAL_KEY_SIZE


def relative_pose_keys(poses: np.ndarray, position_scale: float) -> np.ndarray:
    """``(N, N, K)`` compact keys (the graph network's edge features): ``[i, j]`` is j seen from i.

    ``poses`` is ``(N, 3)`` planar ``[x, y, yaw]`` or ``(N, 6)`` ``[x, y, z, roll, pitch, yaw]``
    [m, rad] in any common frame.
    """
    poses = np.asarray(poses, dtype=np.float64)
    if poses.shape[1] == 3:
        return _planar_keys(poses, position_scale)
    return _spatial_keys(poses, position_scale)


def se3_pose_keys(
    poses: np.ndarray, position_scale: float, rotation_weight: float = DEFAULT_ROTATION_WEIGHT
) -> np.ndarray:
    """``(N, N, 12)`` memory keys (see the module docstring): ``[i, j]`` is j's pose in i's frame.

    Args:
        poses: ``(N, 3)`` planar ``[x, y, yaw]`` (z = 0, rotation about z) or ``(N, 6)``
            ``[x, y, z, roll, pitch, yaw]`` (extrinsic x-y-z Euler angles) [m, rad] in any common frame.
        position_scale: length that weighs like one key unit [m].
        rotation_weight: key units per unit of rotation chord (about per radian).
    """
    from scipy.spatial.transform import Rotation  # scipy on first use: ~0.24 s off every start-up

    poses = np.asarray(poses, dtype=np.float64)
    n = poses.shape[0]
    if poses.shape[1] == 3:
        positions = np.column_stack([poses[:, :2], np.zeros(n)])
        matrices = Rotation.from_euler("z", poses[:, 2:3]).as_matrix()  # R_world_i
    else:
        positions = poses[:, :3]
        matrices = Rotation.from_euler("xyz", poses[:, 3:6]).as_matrix()
    delta = positions[None, :, :] - positions[:, None, :]  # [i, j] = p_j - p_i in the common frame
    p_in_i = np.einsum("iab,ija->ijb", matrices, delta)  # R_i^T (p_j - p_i)
    relative = np.einsum("iab,jac->ijbc", matrices, matrices)  # R_i^T R_j
    scale = rotation_weight / math.sqrt(2.0)
    return np.concatenate([p_in_i / position_scale, scale * relative.reshape(n, n, 9)], axis=-1)


def se3_key_from_legacy(key: np.ndarray, rotation_weight: float = DEFAULT_ROTATION_WEIGHT) -> np.ndarray:
    """The SE(3) key of a compact key stored before schema 4: planar ``(x, y, sin, cos)`` (a rotation about z,
    z = 0) or 6-DOF ``(x, y, z, sin r, sin p, sin y, cos r, cos p, cos y)``. Positions keep their scale."""
    from scipy.spatial.transform import Rotation  # scipy on first use: ~0.24 s off every start-up

    key = np.asarray(key, dtype=np.float64)
    if key.size == PLANAR_KEY_SIZE:
        x, y, s, c = key
        norm = math.hypot(s, c)  # stored sin/cos are of one angle: exact up to rounding
        if not norm > 0.5:  # NaN too
            raise ValueError(f"a planar key's (sin, cos) = ({s}, {c}) is not an angle")
        s, c = s / norm, c / norm
        matrix = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        position = np.array([x, y, 0.0])
    elif key.size == SPATIAL_KEY_SIZE:
        angles = np.arctan2(key[3:6], key[6:9])
        matrix = Rotation.from_euler("xyz", angles).as_matrix()
        position = key[:3]
    else:
        raise ValueError(f"a legacy memory key has {PLANAR_KEY_SIZE} or {SPATIAL_KEY_SIZE} numbers, got {key.size}")
    return np.concatenate([position, rotation_weight / math.sqrt(2.0) * matrix.reshape(9)])


def _planar_keys(poses: np.ndarray, scale: float) -> np.ndarray:
    xy, yaw = poses[:, :2], poses[:, 2]
    delta = xy[None, :, :] - xy[:, None, :]  # [i, j] = p_j - p_i in the common frame
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    x_in_i = c * delta[..., 0] + s * delta[..., 1]
    y_in_i = -s * delta[..., 0] + c * delta[..., 1]
    dyaw = yaw[None, :] - yaw[:, None]
    return np.stack([x_in_i / scale, y_in_i / scale, np.sin(dyaw), np.cos(dyaw)], axis=-1)


def _spatial_keys(poses: np.ndarray, scale: float) -> np.ndarray:
    n = poses.shape[0]
    from scipy.spatial.transform import Rotation  # scipy on first use: ~0.24 s off every start-up

    rotations = Rotation.from_euler("xyz", poses[:, 3:6])
    matrices = rotations.as_matrix()  # R_world_i
    keys = np.zeros((n, n, SPATIAL_KEY_SIZE))
    for i in range(n):
        p_in_i = (poses[:, :3] - poses[i, :3]) @ matrices[i]  # R_i^T (p_j - p_i)
        relative = (rotations[i].inv() * rotations).as_euler("xyz")  # R_i^T R_j
        keys[i] = np.concatenate([p_in_i / scale, np.sin(relative), np.cos(relative)], axis=1)
    return keys
