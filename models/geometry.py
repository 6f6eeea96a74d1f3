"""Planar geometry helpers: SE(2) poses and convex-polygon tests used for footprints on the lid.

Poses are ``(x, y, yaw)`` [m, m, rad]; ``compose(T_a_b, T_b_c) = T_a_c``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import overload

import numpy as np


@overload
def wrap_angle(angle: float) -> float: ...
@overload
def wrap_angle(angle: np.ndarray) -> np.ndarray: ...
def wrap_angle(angle: float | np.ndarray) -> float | np.ndarray:
    """Wrap an angle [rad] (or each of an array of them) into [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def upright_pose(x: float, y: float, yaw: float, height: float) -> np.ndarray:
    """4x4 pose with z up at ``(x, y, height)`` [m], turned by ``yaw`` [rad] about z."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, height], [0, 0, 0, 1]], dtype=float)


def compose(T_a_b: tuple[float, float, float], T_b_c: tuple[float, float, float]) -> tuple[float, float, float]:
    """Compose two SE(2) poses: the pose of frame c in frame a."""
    xa, ya, ta = T_a_b
    xb, yb, tb = T_b_c
    c, s = math.cos(ta), math.sin(ta)
    return (xa + c * xb - s * yb, ya + s * xb + c * yb, wrap_angle(ta + tb))


def inverse(T_a_b: tuple[float, float, float]) -> tuple[float, float, float]:
    """Inverse of an SE(2) pose: ``T_b_a``."""
    x, y, t = T_a_b
    c, s = math.cos(t), math.sin(t)
    return (-c * x - s * y, s * x - c * y, wrap_angle(-t))


def transform_points(T_a_b: Sequence[float], points_in_b: np.ndarray) -> np.ndarray:
    """Express points given in frame b (shape ``(n, 2)`` [m]) in frame a."""
    x, y, t = T_a_b
    c, s = math.cos(t), math.sin(t)
    rotation = np.array([[c, -s], [s, c]])
    return points_in_b @ rotation.T + np.array([x, y])


def _axes(polygon: np.ndarray) -> np.ndarray:
    edges = np.roll(polygon, -1, axis=0) - polygon
    normals = np.stack([-edges[:, 1], edges[:, 0]], axis=1)
    return normals / np.linalg.norm(normals, axis=1, keepdims=True)


def _axis_gaps(a: np.ndarray, b: np.ndarray):
    """The separation of two convex polygons along each edge normal of ``a``, then of ``b`` [m] (Python floats:
    the same values as numpy's, min/max on a handful of them faster)."""
    for polygon in (a, b):
        for axis in _axes(polygon):
            pa, pb = (a @ axis).tolist(), (b @ axis).tolist()
            yield max(min(pb) - max(pa), min(pa) - max(pb))


def polygon_gap(a: np.ndarray, b: np.ndarray) -> float:
    """Separation of two convex polygons along their best separating axis [m].

    Positive: the polygons are apart by at least this much (a lower bound on their distance, exact
    for the axis-aligned rectangles and near-circles used here). Zero or negative: they touch or
    overlap (the magnitude is the smallest penetration along the polygons' edge normals).
    """
    return float(max(_axis_gaps(a, b)))


def polygons_clear(a: np.ndarray, b: np.ndarray, clearance: float) -> bool:
    """Whether ``polygon_gap(a, b) >= clearance`` [m], decided at the first axis that shows it (the same
    comparisons, so the same answer, in a fraction of the time for polygons far apart)."""
    return any(gap >= clearance for gap in _axis_gaps(a, b))


def clip_below_x(polygon: np.ndarray, x_max: float) -> np.ndarray:
    """The part of a convex polygon ``(n, 2)`` [m] at ``x <= x_max``, a convex polygon ``(m, 2)`` in the
    same order (empty ``(0, 2)`` if none of it is there)."""
    kept: list[np.ndarray] = []
    for k in range(len(polygon)):
        a, b = polygon[k], polygon[(k + 1) % len(polygon)]
        if a[0] <= x_max:
            kept.append(a)
        if (a[0] - x_max) * (b[0] - x_max) < 0.0:  # the edge crosses x = x_max
            t = (x_max - a[0]) / (b[0] - a[0])
            kept.append(np.array([x_max, a[1] + t * (b[1] - a[1])]))
    return np.array(kept, dtype=float).reshape(-1, 2)


def rectangle(x_min: float, x_max: float, y_min: float, y_max: float) -> np.ndarray:
    """Counter-clockwise corners of an axis-aligned rectangle, shape ``(4, 2)`` [m]."""
    return np.array([[x_min, y_min], [x_max, y_min], [x_max, y_max], [x_min, y_max]], dtype=float)


def circle_polygon(radius: float, sides: int = 16) -> np.ndarray:
    """A regular polygon that contains the circle of ``radius`` [m] (circumscribed), ``(sides, 2)``."""
    outer = radius / math.cos(math.pi / sides)
    angles = (np.arange(sides) + 0.5) * 2.0 * math.pi / sides
    return outer * np.stack([np.cos(angles), np.sin(angles)], axis=1)
