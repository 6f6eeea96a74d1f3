"""Memory keys: the pose of component j in component i's frame.

The paper keys memories by world-frame differences (dx, dy, dsin, dcos); those change when the whole
box is moved or turned on the table. Expressing j in i's frame does not: a box anywhere on the table
recalls the same memories. Positions are divided by ``position_scale`` so that metres and the
sin/cos of angles weigh comparably in the Euclidean nearest-neighbour search.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

PLANAR_KEY_SIZE = 4
"""(x, y) of j in i's frame / scale, sin and cos of the relative yaw."""
SPATIAL_KEY_SIZE = 9
"""(x, y, z) of j in i's frame / scale, sin and cos of relative roll, pitch, yaw."""


def key_size(pose_size: int) -> int:
    return PLANAR_KEY_SIZE if pose_size == 3 else SPATIAL_KEY_SIZE


def relative_pose_keys(poses: np.ndarray, position_scale: float) -> np.ndarray:
    """``(N, N, K)`` keys: entry ``[i, j]`` describes component j seen from component i.

    ``poses`` is ``(N, 3)`` planar ``[x, y, yaw]`` or ``(N, 6)`` ``[x, y, z, roll, pitch, yaw]``
    [m, rad] in any common frame.
    """
    poses = np.asarray(poses, dtype=np.float64)
    if poses.shape[1] == 3:
        return _planar_keys(poses, position_scale)
    return _spatial_keys(poses, position_scale)


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
    rotations = Rotation.from_euler("xyz", poses[:, 3:6])
    matrices = rotations.as_matrix()  # R_world_i
    keys = np.zeros((n, n, SPATIAL_KEY_SIZE))
    for i in range(n):
        p_in_i = (poses[:, :3] - poses[i, :3]) @ matrices[i]  # R_i^T (p_j - p_i)
        relative = (rotations[i].inv() * rotations).as_euler("xyz")  # R_i^T R_j
        keys[i] = np.concatenate([p_in_i / scale, np.sin(relative), np.cos(relative)], axis=1)
    return keys
