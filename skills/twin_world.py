"""``TwinWorld``: the ``World`` protocol over the robot — perception in, primitives out.

``observe()`` gives the components as the overview camera sees them at the start (kind from the
cell's marker map, planar pose of each component frame in the base frame), in an order shuffled by
the seed, with states the world tracks from its own outcomes. ``try_toggle(i)`` runs the toggle
primitive on component ``i`` and decides "moved" from what the robot sensed: the primitive's
measured progress and F/T (``moved`` / ``blocked``), checked against the marker re-observed by the
overview camera afterwards (a marker that left its closed pose — or vanished, as a door's does when
it stands open — moved).

Everything it uses comes through the robot interface; :attr:`TwinWorld.log` records each action's
sensed outcome, and — only when an evaluator passes ``ground_truth`` — the simulator's truth beside
it, for scoring.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from models import ComponentObservation, SceneObservation
from skills.joint_model import JointModel, joint_model
from skills.perception import MarkerDetection, MarkerDetector, kind_of, lid_height, select_markers, upright_pose
from skills.primitives import Toggler, ToggleResult

MOVED_DISTANCE = 0.01
"""A re-observed marker this far from its closed pose has moved [m]..."""
MOVED_ANGLE = math.radians(20)
"""... or turned this much [rad]."""


@dataclass
class ActionLog:
    """One try as the robot sensed it (and, for evaluation, the truth)."""

    index: int
    marker: int
    kind: str
    outcome: str
    reason: str
    moved: bool
    progress: float
    peak_force: float
    sim_time: float
    wall_time: float
    true_moved: bool | None = None


@dataclass
class TwinWorld:
    """See the module docstring. ``robot`` is a robot interface; ``marker_map`` maps marker ids to
    kinds; ``goal_marker`` is the id on the component to open."""

    robot: object
    marker_map: dict[int, str]
    goal_marker: int
    seed: int = 0
    ground_truth: Callable[[int], int] | None = None
    """Evaluation only: marker id -> the simulator's state of that component (never used to decide)."""
    names: dict[int, str] | None = None
    """Evaluation only: marker id -> the spec's component name, for result files."""
    log: list[ActionLog] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.detector = MarkerDetector()
        self.toggler = Toggler(self.robot)
        detections = self._look()
        height = lid_height(detections)
        order = np.random.default_rng(self.seed).permutation(sorted(self.marker_map))
        self.markers = [int(m) for m in order]
        self.closed_poses = {m: detections[m].planar_pose for m in self.markers}
        self.joint_models: dict[int, JointModel] = {
            m: joint_model(kind_of(self.marker_map, m), upright_pose(self.closed_poses[m], height))
            for m in self.markers
        }
        self.states = np.zeros(len(self.markers), dtype=np.int64)

    def _look(self) -> dict[int, MarkerDetection]:
        image = self.robot.capture("overview")
        return select_markers(self.detector.detect(image), set(self.marker_map), ("overview",))

    def observe(self) -> SceneObservation:
        components = tuple(
            ComponentObservation(kind_of(self.marker_map, m), self.closed_poses[m].copy(), int(s))
            for m, s in zip(self.markers, self.states, strict=True)
        )
        return SceneObservation(components, goal_index=self.markers.index(self.goal_marker), goal_state=1)

    def try_toggle(self, index: int) -> bool:
        marker = self.markers[index]
        opening = self.states[index] == 0
        before = self.ground_truth(marker) if self.ground_truth else None
        result: ToggleResult = self.toggler.toggle(self.joint_models[marker], opening=opening)
        moved = self._sensed_moved(result, marker, opening)
        if moved:
            self.states[index] ^= 1
        after = self.ground_truth(marker) if self.ground_truth else None
        self.log.append(
            ActionLog(
                index, marker, kind_of(self.marker_map, marker), result.outcome, result.reason, moved,
                result.progress, result.peak_opposing_force, result.sim_time, result.wall_time,
                None if before is None else bool(before != after),
            )
        )  # fmt: skip
        return moved

    def _sensed_moved(self, result: ToggleResult, marker: int, opening: bool) -> bool:
        if result.outcome == "blocked":
            return False
        seen = self.detector.detect(self.robot.capture("overview"))
        poses = [d.planar_pose for d in seen if d.marker_id == marker]
        if not poses:  # a door standing open shows its marker edge-on; otherwise trust the F/T verdict
            return result.outcome == "moved" if kind_of(self.marker_map, marker) != "door" or not opening else True
        else:
            delta = poses[0] - self.closed_poses[marker]
            turn = abs((delta[2] + math.pi) % (2 * math.pi) - math.pi)
            away = bool(np.linalg.norm(delta[:2]) > MOVED_DISTANCE or turn > MOVED_ANGLE)
        return away if opening else not away

    def ground_truth_name(self, index: int) -> str:
        """For logs: the spec name of component ``index`` when given, else its marker id."""
        marker = self.markers[index]
        return self.names[marker] if self.names else f"marker-{marker}"
