"""SE(2) placement of components on the lid so that each locker sits next to what it locks.

A new component is attached to an already placed *anchor*: its yaw is the anchor's yaw turned by a
multiple of 90 degrees, and it stands straight ahead along its own +x, as close to the anchor as the
footprints allow plus a clearance. So a locker and what it locks are always neighbours, and the pose
of one in the other's frame takes few values per kind pair — which is what lets a memory of past
boxes transfer to new ones.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from models.geometry import compose, polygon_gap
from models.kinds import get_kind

TURNS = (-math.pi / 2.0, 0.0, math.pi / 2.0)
"""Yaw of a new component relative to its anchor [rad]."""


@dataclass(frozen=True)
class LayoutConfig:
    """How components are spaced on the lid."""

    clearance: float = 0.015
    """Smallest gap between the footprints of any two components [m] (room for the gripper fingers)."""
    neighbour_gap: float = 0.03
    """A component counts as next to another when their footprints are at most this far apart [m]."""
    margin: float = 0.02
    """Gap between the outermost footprints and the lid edge [m]."""
    distance_step: float = 0.005
    """Resolution of the anchor-to-component distance search [m]."""
    compactness_slack: float = 0.1
    """A turn is a candidate when its layout's bounding-box span is within this fraction of the best."""


class Layout:
    """Components placed so far: kinds and poses ``(x, y, yaw)`` in a working frame [m, rad]."""

    def __init__(self, config: LayoutConfig) -> None:
        self.config = config
        self.kinds: list[str] = []
        self.poses: list[tuple[float, float, float]] = []
        self._footprints: list[np.ndarray] = []

    def __len__(self) -> int:
        return len(self.kinds)

    def place_first(self, kind: str) -> None:
        self._add(kind, (0.0, 0.0, 0.0))

    def _add(self, kind: str, pose: tuple[float, float, float]) -> None:
        self.kinds.append(kind)
        self.poses.append(pose)
        self._footprints.append(get_kind(kind).footprint_in_lid(pose))

    def candidate(self, anchor: int, kind: str, turn: float) -> tuple[float, float, float] | None:
        """Pose of a ``kind`` attached to ``anchor`` with ``turn``, or None if it would crowd others."""
        template = get_kind(kind)
        ax, ay, ayaw = self.poses[anchor]
        yaw = ayaw + turn
        step = self.config.distance_step

        def at(distance: float) -> tuple[tuple[float, float, float], np.ndarray]:
            pose = compose((ax, ay, 0.0), (distance * math.cos(yaw), distance * math.sin(yaw), yaw))
            return pose, template.footprint_in_lid(pose)

        def clears(distance: float) -> bool:
            return polygon_gap(at(distance)[1], self._footprints[anchor]) >= self.config.clearance

        # The first distance on the grid step, 2 step, ... at which the footprint clears the anchor.
        # The gap is convex in the distance (a max of functions linear in it), so "clears" is false
        # then true along the grid: an exponential then binary search finds the same grid point as
        # walking outwards one step at a time, in O(log) gap evaluations. The grid is accumulated
        # (distance += step) exactly as that walk did, so layouts are unchanged to the bit.
        grid = [step]
        probe = 0
        while not clears(grid[probe]):
            while len(grid) <= 2 * probe + 1:
                grid.append(grid[-1] + step)
            probe = 2 * probe + 1
        low, high = (probe - 1) // 2, probe  # clears(grid[low]) is false (or low < 0), clears(grid[high])
        while high - low > 1:
            middle = (low + high) // 2
            low, high = (low, middle) if clears(grid[middle]) else (middle, high)
        pose, polygon = at(grid[high])
        for other, footprint in enumerate(self._footprints):
            if other != anchor and polygon_gap(polygon, footprint) < self.config.clearance:
                return None
        return pose

    def attach(self, anchor: int, kind: str, rng: np.random.Generator) -> bool:
        """Attach a ``kind`` to ``anchor`` with a turn drawn among the compact ones; False if none fits."""
        options = []
        for turn in TURNS:
            pose = self.candidate(anchor, kind, turn)
            if pose is not None:
                options.append((self._span_with(kind, pose), pose))
        if not options:
            return False
        best = min(span for span, _ in options)
        compact = [pose for span, pose in options if span <= best * (1.0 + self.config.compactness_slack)]
        self._add(kind, compact[int(rng.integers(len(compact)))])
        return True

    def _span_with(self, kind: str, pose: tuple[float, float, float]) -> float:
        """Longer side of the bounding box if ``kind`` were placed at ``pose`` [m]."""
        points = np.concatenate([*self._footprints, get_kind(kind).footprint_in_lid(pose)])
        return float((points.max(axis=0) - points.min(axis=0)).max())

    def are_neighbours(self, a: int, b: int) -> bool:
        return polygon_gap(self._footprints[a], self._footprints[b]) <= self.config.neighbour_gap

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners of the bounding box of all footprints [m]."""
        points = np.concatenate(self._footprints)
        return points.min(axis=0), points.max(axis=0)

    def lid_size(self) -> tuple[float, float]:
        """Smallest lid (length, width) that holds the layout with the margin, rounded up to 5 mm."""
        low, high = self.bounds()
        extent = high - low + 2.0 * self.config.margin
        return (_round_up(extent[0], 0.005), _round_up(extent[1], 0.005))

    def poses_in_lid(self) -> list[tuple[float, float, float]]:
        """Poses shifted so the layout's bounding box is centred on the lid origin."""
        low, high = self.bounds()
        cx, cy = (low + high) / 2.0
        return [(x - cx, y - cy, yaw) for x, y, yaw in self.poses]

    def turn_lengthwise(self) -> None:
        """Turn the whole layout by 90 degrees if it is wider than long, so its long side lies along
        the lid's x. Relative poses between components are unchanged."""
        low, high = self.bounds()
        if high[1] - low[1] <= high[0] - low[0]:
            return
        turned = [compose((0.0, 0.0, math.pi / 2.0), pose) for pose in self.poses]
        kinds = self.kinds
        self.kinds, self.poses, self._footprints = [], [], []
        for kind, pose in zip(kinds, turned, strict=True):
            self._add(kind, pose)


def _round_up(value: float, step: float) -> float:
    """``value`` rounded up to a multiple of ``step``, printed without float noise."""
    return round(math.ceil(value / step - 1e-9) * step, 6)
