"""Random reachable placements of a puzzle box on the table: the held-out poses a pipeline must
survive (issue "reality gap": x 0.30 to 0.60 m, |y| <= 0.30 m, any yaw, every handle within reach)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from puzzlebox.models.scene import SceneConfig, SceneError, unreachable_handles
from puzzlebox.models.spec import PuzzleSpec


@dataclass(frozen=True)
class PlacementRange:
    """Where a box may be placed, in the robot base frame."""

    x: tuple[float, float] = (0.30, 0.60)
    """Range of the box centre's x [m]."""
    y: tuple[float, float] = (-0.30, 0.30)
    """Range of the box centre's y [m]."""
    yaw: tuple[float, float] = (-math.pi, math.pi)
    """Range of the box's yaw [rad]."""
    max_draws: int = 2000
    """Rejection-sampling budget before giving up."""

    def __post_init__(self) -> None:
        for name in ("x", "y", "yaw"):
            low, high = getattr(self, name)
            if not (math.isfinite(low) and math.isfinite(high) and low <= high):
                raise ValueError(f"placement range {name} must be finite with low <= high, got {(low, high)}")


def sample_reachable_pose(
    spec: PuzzleSpec,
    rng: np.random.Generator,
    placement: PlacementRange | None = None,
    scene: SceneConfig | None = None,
) -> tuple[float, float, float]:
    """A box pose ``(x, y, yaw)`` [m, m, rad] drawn uniformly from ``placement`` among those that put
    every handle of ``spec`` within the robot's reach (rejection sampling).

    Raises:
        SceneError: no reachable pose was found in ``placement.max_draws`` draws.
    """
    placement = placement or PlacementRange()
    scene = scene or SceneConfig()
    if spec.box is None:
        raise SceneError(f"spec {spec.name!r} has no box to place")
    for _ in range(placement.max_draws):
        pose = (
            float(rng.uniform(*placement.x)),
            float(rng.uniform(*placement.y)),
            float(rng.uniform(*placement.yaw)),
        )
        if not unreachable_handles(spec, pose, scene):
            return pose
    raise SceneError(f"no reachable pose for {spec.name!r} in {placement} after {placement.max_draws} draws")


def placed(spec: PuzzleSpec, pose: tuple[float, float, float]) -> PuzzleSpec:
    """``spec`` with its box at ``pose`` [m, m, rad] (everything else unchanged)."""
    if spec.box is None:
        raise SceneError(f"spec {spec.name!r} has no box to place")
    return replace(spec, box=replace(spec.box, pose=tuple(float(v) for v in pose)))


__all__ = ["PlacementRange", "placed", "sample_reachable_pose"]
