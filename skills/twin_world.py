"""``TwinWorld``: the ``World`` protocol over the robot — perception in, primitives out.

``observe()`` gives the components as the overview camera sees them at the start (markers it misses
are looked for again from the wrist camera; any still missing raise ``MarkersNotFound``) (kind from the
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

from models import ComponentObservation, SceneObservation, TryResult
from skills.errors import IKFailure, MarkersNotFound
from skills.joint_model import JointModel, joint_model
from skills.kinematics import top_down
from skills.perception import MarkerDetection, MarkerDetector, kind_of, lid_height, select_markers, upright_pose
from skills.primitives import Toggler, ToggleResult

WRIST_CAMERA = "xarm7/gripper/wrist_camera"
WRIST_VIEW_HEIGHT = 0.30
"""Height of the TCP above the markers when looking from the wrist camera [m]."""
WRIST_VIEW_OFFSETS = ((0.0, 0.0), (0.0, 0.15), (0.0, -0.15), (0.15, 0.0), (-0.15, 0.0))
"""Where the wrist camera looks from, relative to the markers seen so far [m]."""
TABLE_VIEW_HEIGHT = 0.40
"""TCP height when sweeping the workspace for a box the overview camera does not see [m]."""
WORKSPACE_VIEWPOINTS = ((0.40, 0.0), (0.30, 0.30), (0.30, -0.30), (0.50, 0.20), (0.50, -0.20), (0.25, 0.45),
                        (0.25, -0.45))  # fmt: skip
"""Where the wrist camera looks when no marker was seen at all, in the base frame [m]."""
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
        """Markers from the overview camera; if some are missing or ambiguous, look again from the wrist
        camera held above the markers seen so far, then report what is still missing."""
        expected = set(self.marker_map)
        seen = self.detector.detect(self.robot.capture("overview"))
        try:
            return select_markers(seen, expected, ("overview",))
        except MarkersNotFound:
            pass
        wrist = self._look_from_wrist(seen)
        return select_markers([d for d in seen if d.marker_id not in {w.marker_id for w in wrist}] + wrist,
                              expected, ("overview", WRIST_CAMERA))  # fmt: skip

    def _look_from_wrist(self, seen: list[MarkerDetection]) -> list[MarkerDetection]:
        if seen:  # a few viewpoints around the markers seen so far
            centre = np.mean([d.T_base_marker[:3, 3] for d in seen], axis=0)
            viewpoints = [centre + (dx, dy, WRIST_VIEW_HEIGHT) for dx, dy in WRIST_VIEW_OFFSETS]
        else:  # nothing seen: sweep the workspace
            viewpoints = [np.array([x, y, TABLE_VIEW_HEIGHT]) for x, y in WORKSPACE_VIEWPOINTS]
        found: list[MarkerDetection] = []
        for point in viewpoints:  # until every id is seen
            view = top_down(point, 0.0)
            try:
                self.toggler.move_to(view, 1.5)
            except IKFailure:
                continue
            found += [d for d in self.detector.detect(self.robot.capture(WRIST_CAMERA))
                      if d.marker_id not in {f.marker_id for f in found}]  # fmt: skip
            if set(self.marker_map) <= {d.marker_id for d in found} | {d.marker_id for d in seen}:
                break
        self.toggler.go_rest()
        return found

    def observe(self) -> SceneObservation:
        components = tuple(
            ComponentObservation(kind_of(self.marker_map, m), self.closed_poses[m].copy(), int(s))
            for m, s in zip(self.markers, self.states, strict=True)
        )
        return SceneObservation(components, goal_index=self.markers.index(self.goal_marker), goal_state=1)

    def try_toggle(self, index: int) -> TryResult:
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
        if moved:
            return TryResult("moved")
        return TryResult("failed" if result.outcome == "failed" else "blocked", result.reason)

    def _sensed_moved(self, result: ToggleResult, marker: int, opening: bool) -> bool:
        if result.outcome == "blocked":
            return False
        seen = self.detector.detect(self.robot.capture("overview"))
        poses = [d.planar_pose for d in seen if d.marker_id == marker]
        if not poses:
            if opening and kind_of(self.marker_map, marker) == "door":
                return True  # a door standing open shows its marker edge-on: it left its closed pose
            return result.outcome == "moved"  # otherwise hidden (the arm?): trust the F/T verdict
        else:
            delta = poses[0] - self.closed_poses[marker]
            turn = abs((delta[2] + math.pi) % (2 * math.pi) - math.pi)
            away = bool(np.linalg.norm(delta[:2]) > MOVED_DISTANCE or turn > MOVED_ANGLE)
        return away if opening else not away

    def ground_truth_name(self, index: int) -> str:
        """For logs: the spec name of component ``index`` when given, else its marker id."""
        marker = self.markers[index]
        return self.names[marker] if self.names else f"marker-{marker}"
