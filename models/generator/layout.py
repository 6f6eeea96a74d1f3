"""SE(2) placement of components on the lid so that each locker sits next to what it locks.

A new component is attached to an already placed *anchor*: its yaw is the anchor's yaw turned by a
multiple of 90 degrees, and it stands straight ahead along its own +x, as close to the anchor as the
footprints allow plus a clearance. So a locker and what it locks are always neighbours, and the pose
of one in the other's frame takes few values per kind pair — which is what lets a memory of past
boxes transfer to new ones.

A kind mounted at the lid's edge (:attr:`models.kinds.template.KindTemplate.edge_x`) must end with its front
face on a lid edge, its +x pointing out: it is placed only where nothing else reaches past its front line in
its +x direction, nothing placed later may reach past that line, and the lid is cut with its edge on that
line (no margin on that side). Yaws stay multiples of 90 degrees, so every front is parallel to a lid edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from puzzlebox.models.errors import GeneratorError
from puzzlebox.models.geometry import compose, polygon_gap, polygons_clear
from puzzlebox.models.kinds import get_kind

TURNS = (-math.pi / 2.0, 0.0, math.pi / 2.0)
"""Yaw of a new component relative to its anchor [rad]."""
FRONT_TOLERANCE = 1e-9
"""How far a footprint may reach past an edge-mounted component's front line [m] (float noise only)."""


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
        self._on_lid: list[np.ndarray] = []
        self._fronts: list[tuple[int, np.ndarray, float]] = []
        """Edge-mounted components: (index, outward unit axis, front line's coordinate along it [m])."""

    def __len__(self) -> int:
        return len(self.kinds)

    def place_first(self, kind: str) -> None:
        self._add(kind, (0.0, 0.0, 0.0))

    def _add(self, kind: str, pose: tuple[float, float, float]) -> None:
        template = get_kind(kind)
        front = template.front_in_lid(pose)
        if front is not None:
            self._fronts.append((len(self.kinds), np.array(front[0]), front[1]))
        self.kinds.append(kind)
        self.poses.append(pose)
        self._footprints.append(template.footprint_in_lid(pose))
        self._on_lid.append(template.on_lid_footprint_in_lid(pose))

    def _respects_edges(self, kind: str, pose: tuple[float, float, float]) -> bool:
        """Whether a ``kind`` at ``pose`` keeps every edge-mounted component's front line outermost in its +x
        direction and, if it is edge-mounted itself, has its own front line outermost in its +x direction."""
        template = get_kind(kind)
        footprint, on_lid = template.footprint_in_lid(pose), template.on_lid_footprint_in_lid(pose)
        front = template.front_in_lid(pose)
        for _, axis, line in self._fronts:
            # an edge-mounted component on the same side sweeps past the shared line: only its part on the lid counts
            same_side = front is not None and np.array_equal(front[0], axis)
            if float(((on_lid if same_side else footprint) @ axis).max()) > line + FRONT_TOLERANCE:
                return False
        if front is not None:
            axis, line = front
            same_side = {i for i, other, _ in self._fronts if np.array_equal(other, axis)}
            for i in range(len(self.kinds)):
                polygon = self._on_lid[i] if i in same_side else self._footprints[i]
                if float((polygon @ axis).max()) > line + FRONT_TOLERANCE:
                    return False
        return True

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
            return polygons_clear(at(distance)[1], self._footprints[anchor], self.config.clearance)

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
            if other != anchor and not polygons_clear(polygon, footprint, self.config.clearance):
                return None
        if not self._respects_edges(kind, pose):
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
        points = np.concatenate([*self._on_lid, get_kind(kind).on_lid_footprint_in_lid(pose)])
        return float((points.max(axis=0) - points.min(axis=0)).max())

    def are_neighbours(self, a: int, b: int) -> bool:
        return polygon_gap(self._footprints[a], self._footprints[b]) <= self.config.neighbour_gap

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners of the bounding box of all footprints' parts on the lid [m] (the whole
        footprint but for an edge-mounted component's part swept beyond its front)."""
        points = np.concatenate(self._on_lid)
        return points.min(axis=0), points.max(axis=0)

    def _lid_box(self, lid: tuple[float, float] | None) -> list[tuple[float, float]]:
        """Per lid axis (x, y), the lid's size and centre in the working frame [m]: of ``lid`` (length,
        width) if given, else the smallest that holds the layout, rounded up to 5 mm. Along an axis with no
        edge-mounted component, the bounding box plus the margin on both sides, centred on the bounding box
        (the rounding shared by both sides). Where edge-mounted components point out along the axis, the lid
        edge on that side is their front line (no margin there); fronts on both sides fix the size to their
        distance apart, so a given ``lid`` must match it (:class:`GeneratorError` otherwise)."""
        low, high = self.bounds()
        margin = self.config.margin
        box = []
        for a in range(2):
            upper = [line for _, axis, line in self._fronts if axis[a] > 0]
            lower = [-line for _, axis, line in self._fronts if axis[a] < 0]
            if not upper and not lower:
                size = lid[a] if lid is not None else _round_up((high - low + 2.0 * margin)[a], 0.005)
                box.append((size, (low[a] + high[a]) / 2.0))
            elif upper and lower:
                size = max(upper) - min(lower)
                if lid is not None and abs(lid[a] - size) > 1e-6:
                    raise GeneratorError(
                        f"a lid {lid[a]:.3f} m along its {'xy'[a]} cannot hold this layout: it has edge-mounted "
                        f"components on both sides of that axis, whose fronts are {size:.6f} m apart"
                    )
                box.append((size, (max(upper) + min(lower)) / 2.0))
            elif upper:
                edge = max(upper)
                size = lid[a] if lid is not None else _round_up(edge - (low[a] - margin), 0.005)
                box.append((size, edge - size / 2.0))
            else:
                edge = min(lower)
                size = lid[a] if lid is not None else _round_up(high[a] + margin - edge, 0.005)
                box.append((size, edge + size / 2.0))
        return box

    def lid_size(self) -> tuple[float, float]:
        """Smallest lid (length, width) that holds the layout with the margin, rounded up to 5 mm, with its
        edge on every edge-mounted component's front (see :meth:`_lid_box`)."""
        (length, _), (width, _) = self._lid_box(None)
        return (length, width)

    def poses_in_lid(self, lid: tuple[float, float] | None = None) -> list[tuple[float, float, float]]:
        """Poses shifted into the lid frame: the layout's bounding box centred on the lid origin, but where
        edge-mounted components are, their front on the lid edge. ``lid``: the lid (length, width) [m] if not
        :meth:`lid_size`."""
        (_, cx), (_, cy) = self._lid_box(lid)
        return [(x - cx, y - cy, yaw) for x, y, yaw in self.poses]

    def turn_lengthwise(self) -> None:
        """Turn the whole layout by 90 degrees if it is wider than long, so its long side lies along
        the lid's x. Relative poses between components are unchanged."""
        low, high = self.bounds()
        if high[1] - low[1] <= high[0] - low[0]:
            return
        turned = [compose((0.0, 0.0, math.pi / 2.0), pose) for pose in self.poses]
        kinds = self.kinds
        self.kinds, self.poses, self._footprints, self._on_lid, self._fronts = [], [], [], [], []
        for kind, pose in zip(kinds, turned, strict=True):
            self._add(kind, pose)


def _round_up(value: float, step: float) -> float:
    """``value`` rounded up to a multiple of ``step``, printed without float noise."""
    return round(math.ceil(value / step - 1e-9) * step, 6)
