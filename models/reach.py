"""Which box poses put every handle within the robot's reach (pure geometry: no MuJoCo).

The xArm-7 grasps handles top-down; a handle is reachable when its horizontal distance from the base
axis lies in ``[MIN_REACH, MAX_REACH]`` (DESIGN.md). :func:`unreachable_handles` names the handles a
box pose leaves out; :func:`fitting_box_pose` finds a pose that leaves none, searching a fixed grid
from the generators' default pose outwards (deterministic: a generated spec stays a pure function of
its seed).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from puzzlebox.models.kinds import get_kind
from puzzlebox.models.spec import PuzzleSpec

MIN_REACH = 0.20
"""Closest a handle may be to the robot's base axis, horizontally [m]."""
MAX_REACH = 0.62
"""Farthest a handle may be from the robot's base axis, horizontally [m] (top-down grasps)."""
DEFAULT_BOX_POSE = (0.45, 0.0, 0.0)
"""Where generated boxes stand unless that leaves a handle out of reach ``[x, y, yaw]`` [m, m, rad]."""


def handles_in_lid(spec: PuzzleSpec) -> np.ndarray:
    """``(N, 2)`` handle centres of the components in the lid frame [m]."""
    out = np.empty((len(spec.components), 2))
    for k, c in enumerate(spec.components):
        hx, hy = get_kind(c.kind).handle_xy
        x, y, yaw = c.pose
        out[k] = (x + math.cos(yaw) * hx - math.sin(yaw) * hy, y + math.sin(yaw) * hx + math.cos(yaw) * hy)
    return out


def unreachable_handles(
    spec: PuzzleSpec,
    box_pose: tuple[float, float, float],
    min_reach: float = MIN_REACH,
    max_reach: float = MAX_REACH,
) -> list[str]:
    """The components whose handle lies outside ``[min_reach, max_reach]`` of the base axis with the box
    at ``box_pose`` ``[x, y, yaw]`` [m, m, rad], each as ``'name' handle at R m`` (empty: reachable)."""
    radii = _handle_radii(handles_in_lid(spec), box_pose)
    return [
        f"{c.name!r} handle at {r:.3f} m"
        for c, r in zip(spec.components, radii, strict=True)
        if not min_reach <= r <= max_reach
    ]


def _handle_radii(handles: np.ndarray, box_pose: tuple[float, float, float]) -> np.ndarray:
    x, y, yaw = box_pose
    c, s = math.cos(yaw), math.sin(yaw)
    wx = x + c * handles[:, 0] - s * handles[:, 1]
    wy = y + s * handles[:, 0] + c * handles[:, 1]
    return np.hypot(wx, wy)


def _grid(start: tuple[float, float, float]) -> Iterator[tuple[float, float, float]]:
    """Candidate poses over x 0.30-0.60 m, |y| <= 0.30 m (2.5 cm steps) and yaw in 15 deg steps, nearest
    ``start`` first (position, then yaw)."""
    xs = np.round(np.arange(0.30, 0.6001, 0.025), 4)
    ys = np.round(np.arange(-0.30, 0.3001, 0.025), 4)
    yaws = np.radians(np.arange(-180, 180, 15))
    positions = sorted(
        ((x, y) for x in xs for y in ys), key=lambda p: (math.hypot(p[0] - start[0], p[1] - start[1]), p)
    )
    turns = sorted(yaws, key=lambda a: (abs(math.remainder(a - start[2], 2 * math.pi)), a))
    for x, y in positions:
        for yaw in turns:
            yield float(x), float(y), float(math.remainder(yaw, 2 * math.pi))


def fitting_box_pose(
    spec: PuzzleSpec,
    start: tuple[float, float, float] = DEFAULT_BOX_POSE,
    min_reach: float = MIN_REACH,
    max_reach: float = MAX_REACH,
) -> tuple[float, float, float] | None:
    """``start`` if it puts every handle of ``spec`` within reach, else the nearest grid pose that does
    (see :func:`_grid`), else None: the layout is too large for the robot's reach."""
    handles = handles_in_lid(spec)
    if len(handles) == 0:
        return start
    spread = np.ptp(handles, axis=0)
    if math.hypot(*spread) > 2 * max_reach:  # farther apart than the reach's diameter: no pose can do
        return None
    for pose in (start, *_grid(start)):
        radii = _handle_radii(handles, pose)
        if radii.min() >= min_reach and radii.max() <= max_reach:
            return pose
    return None
