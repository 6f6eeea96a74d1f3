"""Finding every marker of a box wherever it stands on the table, and measuring each pose well enough
to grasp by.

The overview camera sees the whole box only near the spot it hangs over; elsewhere it misses part of
the lid or sees markers at a grazing angle, where a 36 mm marker's pose is ill-conditioned. So a
survey (:meth:`SceneSurvey.locate`):

1. reads the markers the overview camera poses within the perception bounds (reprojection error,
   viewing angle: :class:`skills.perception.PerceptionConfig`);
2. searches for the missing ones with the wrist camera from a few viewpoints around what was found
   (or over the whole workspace when nothing was);
3. measures close up every marker not posed by the overview: the wrist camera straight above the
   marker, where its pose is best conditioned (REALITY_NOTES.md §4: ~1 mm at 0.3 m);
4. reports what is still missing (:class:`skills.errors.MarkersNotFound`) — it never invents a pose.

Arm-camera poses compose the calibrated hand-eye transform with the TCP pose the arm reports at
capture; the arm holds still while capturing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.cell_config import CellConfig
from puzzlebox.models.reach import MIN_REACH
from puzzlebox.models.robot import Robot
from puzzlebox.skills.errors import ForceLimitExceeded, IKFailure, MarkersNotFound
from puzzlebox.skills.kinematics import ArmKinematics, top_down
from puzzlebox.skills.perception import MarkerDetection, MarkerDetector, lid_height, select_markers
from puzzlebox.skills.primitives import Toggler

OVERVIEW_CAMERA = "overview"
WRIST_CAMERA = "xarm7/gripper/wrist_camera"
CAMERA_YAWS = (0.0, math.pi / 2, -math.pi / 2, math.pi)
"""Yaws the wrist camera is turned to, in order, looking down from above a point [rad]."""


@dataclass(frozen=True)
class SurveyConfig:
    """Where the wrist camera looks from, and how hard to try."""

    close_up_height: float = 0.25
    """Height of the wrist camera above a marker it measures close up [m] (the TCP is then ~12 cm above
    the lid, clear of the 3.5 cm handles)."""
    search_height: float = 0.40
    """Height of the wrist camera above the markers while searching for missing ones [m]."""
    search_offsets: tuple[tuple[float, float], ...] = ((0.0, 0.0), (0.12, 0.0), (-0.12, 0.0), (0.0, 0.12),
                                                       (0.0, -0.12), (0.2, 0.2), (0.2, -0.2), (-0.2, 0.2),
                                                       (-0.2, -0.2))  # fmt: skip
    """Search viewpoints relative to the centre of the markers found so far [m]."""
    workspace_viewpoints: tuple[tuple[float, float], ...] = ((0.45, 0.0), (0.35, 0.25), (0.35, -0.25), (0.55, 0.2),
                                                             (0.55, -0.2), (0.3, 0.0))  # fmt: skip
    """Search viewpoints in the base frame when nothing was found at all [m]."""
    table_height: float = 0.08
    """Assumed marker height when nothing was found yet [m] (the paper boxes' lid)."""
    search_rounds: int = 2
    """Searches for missing markers, each round around the markers the last one found (the first around all found
    so far): a box of eight parts standing past the overview's view spans ~0.4 m, and the viewpoints around the centre
    of the markers the overview saw did not reach its far corner (hard-chain8-s36007 at (0.371, 0.162, 2.50 rad):
    markers 1 and 2 found, 0 beside them not, ``MarkersNotFound`` before the first action)."""
    move_time: float = 1.2
    """Time for each move between viewpoints [s]."""
    capture_attempts: int = 3
    """Frames tried before a camera counts as giving nothing (a camera drops frames now and then)."""
    lid_tolerance: float = 0.01
    """An overview marker posed farther than this from the lid's plane (the median marker height) is
    measured again close up [m]: sub-millimetre in height when the pose is right, centimetres when a
    corner is hidden."""
    close_up_all: bool = True
    """Measure every marker close up, even those the overview posed within bounds: under a realistic
    calibration (intrinsics 1-2 % off) the overview's depth along its line of sight is off by 5-11 mm, up to
    5.4 mm across the lid at a 24 deg view; close up the same markers are posed within 0.2 mm. It costs
    ~15 s of simulated time (~4 s of wall time) per trial. The overview still tells moved from stayed."""
    overview_camera: str = OVERVIEW_CAMERA
    """The cell's fixed camera over the workspace (a :class:`models.cell_config.CellConfig` names it)."""
    wrist_camera: str = WRIST_CAMERA
    """The cell's camera on the gripper (a :class:`models.cell_config.CellConfig` names it)."""

    @classmethod
    def for_cell(cls, cell: CellConfig, **overrides: Any) -> SurveyConfig:
        """The survey of a cell: its cameras (the rest as given, or the defaults)."""
        return cls(**{"overview_camera": cell.overview_camera, "wrist_camera": cell.wrist_camera, **overrides})


class SceneSurvey:
    """See the module docstring."""

    def __init__(
        self,
        robot: Robot,
        calibration: CellCalibration,
        toggler: Toggler,
        detector: MarkerDetector | None = None,
        config: SurveyConfig | None = None,
        marker_lifts: dict[int, float] | None = None,
    ) -> None:
        self.robot, self.calibration, self.toggler = robot, calibration, toggler
        self.marker_lifts = dict(marker_lifts or {})
        """Marker id -> how far above the lid's marker plane its part holds it, closed [m] (its kind's
        ``KindTemplate.lift``; 0 for parts lying on the lid)."""
        self.detector = detector or MarkerDetector()
        self.config = config or SurveyConfig()
        self.last_close_up_reached = False
        self._planner = ArmKinematics()
        """IK of its own to check a viewpoint before going there (the toggler's holds the arm's warm start)."""
        """Whether the last close-up look got the wrist camera above its marker."""
        self.overview_trusted: set[int] = set()
        """Markers the overview camera posed within bounds and on the lid's plane in :meth:`locate`
        (whether or not they were then measured again close up): the ones it can tell moved from stayed."""

    # -- single looks ------------------------------------------------------------------------------
    def look(self, camera: str) -> list[MarkerDetection]:
        """Trusted detections from one camera, with a few tries if frames are dropped."""
        calibration = self.calibration.camera(camera)
        for _ in range(self.config.capture_attempts):
            image = self.robot.capture(camera)
            if image is None:
                self.robot.wait(0.05)
                continue
            T_base_tcp = self.robot.tcp_pose_in_base() if calibration.on_arm else None
            return self.detector.detect(image, calibration, T_base_tcp)
        return []

    def overview(self) -> list[MarkerDetection]:
        return self.look(self.config.overview_camera)

    def _wrist_from_above(self, point: np.ndarray, height: float, yaws: tuple[float, ...] = CAMERA_YAWS) -> bool:
        """Put the wrist camera ``height`` above ``point`` looking down, arriving through the toggler's
        transit waypoint high above the workspace, the camera turned (the first of ``yaws`` [rad] that works)
        so the TCP stays at least ``MIN_REACH`` from the base axis; False if the arm cannot, or if the force
        limit stopped it (it then withdraws)."""
        T_tcp_camera = self.calibration.camera(self.config.wrist_camera).T_tcp_camera
        assert T_tcp_camera is not None  # the wrist camera is on the arm
        for yaw in yaws:
            target = top_down(np.zeros(3), yaw)
            target[:3, 3] = np.asarray(point, float) + (0.0, 0.0, height) - target[:3, :3] @ T_tcp_camera[:3, 3]
            if np.hypot(*target[:2, 3]) < MIN_REACH:
                continue  # the camera's offset puts the gripper over the base: it meets the arm's link 2
            if not self._reachable(target):
                continue
            try:
                self.toggler.travel_to(target, self.config.move_time)
                return True
            except IKFailure:
                continue
            except ForceLimitExceeded:
                self.toggler.withdraw()
                return False
        return False

    def _reachable(self, target: np.ndarray) -> bool:
        """Whether the IK reaches ``target`` (4x4, base frame) from the rest posture, without moving the arm.

        A viewpoint out of reach is left alone rather than tried: the arm stopped stretched where the IK gave up,
        and the next yaw set out from there, the wrist's last joint winding ~1.6 rad further each time; at its
        limit the IK folded the forearm onto the gripper (hard-chain8-s91002 at world seed 91101: a finger pad on
        link 4 at 388 N true, before the first action)."""
        try:
            self._planner.solve(target, np.asarray(self.toggler.rest_posture, float))
        except IKFailure:
            return False
        return True

    def close_up(self, marker: int, planar_pose: np.ndarray, height: float | None = None) -> MarkerDetection | None:
        """``marker`` measured from straight above its believed ``[x, y, yaw]`` at marker ``height`` [m],
        the arm back at rest after; None if not seen (:attr:`last_close_up_reached` tells whether the
        camera got there)."""
        found = self._measure_from_above(marker, planar_pose, height)
        self.toggler.go_rest()
        return found

    def close_up_turning(self, marker: int, xy: np.ndarray, height: float | None = None) -> MarkerDetection | None:
        """As :meth:`close_up` from above ``xy``, turning the camera to the next yaw while the marker is not
        seen: looking at a point beside the marker, the marker is off the image's centre, where the gripper's
        own fingers may hide it (they fill one side of the wrist image)."""
        found = None
        for yaw in CAMERA_YAWS:
            found = self._measure_from_above(marker, xy, height, yaws=(yaw,))
            if found is not None:
                break
        self.toggler.go_rest()
        return found

    def _measure_from_above(
        self, marker: int, xy: np.ndarray, height: float | None, yaws: tuple[float, ...] = CAMERA_YAWS
    ) -> MarkerDetection | None:
        z = (height if height is not None else self.config.table_height) + self.marker_lifts.get(marker, 0.0)
        self.last_close_up_reached = self._wrist_from_above(
            np.array([xy[0], xy[1], z]), self.config.close_up_height, yaws
        )
        if not self.last_close_up_reached:
            return None
        seen = [d for d in self.look(self.config.wrist_camera) if d.marker_id == marker]
        return min(seen, key=lambda d: d.view_angle) if seen else None

    # -- the survey --------------------------------------------------------------------------------
    def locate(self, expected: set[int]) -> dict[int, MarkerDetection]:
        """One detection per expected marker id (see the module docstring), the arm back at rest."""
        found = self._unique(self.overview(), expected)
        off_the_lid = set(self._off_the_lid(found))
        self.overview_trusted = set(found) - off_the_lid
        if not self.config.close_up_all and set(found) == expected and not off_the_lid:
            return found
        moved_arm = False
        try:
            missing = expected - set(found)
            around = found  # the markers a search round is centred on
            for _ in range(self.config.search_rounds if missing else 0):
                moved_arm = True
                new = {d.marker_id: d for d in self._search(around, missing) if d.marker_id not in found}
                found.update(new)
                missing = expected - set(found)
                if not missing or not new:
                    break
                around = new  # nearer the missing ones than the first centre
            # close up: what the search found from afar, then (with the lid height those give) every
            # overview pose off the lid's plane — a marker partly hidden by its own handle post in an
            # oblique view reprojects well but is posed centimetres deep along the line of sight
            overview = self.config.overview_camera
            from_afar = [m for m, d in found.items() if d.camera != overview or self.config.close_up_all]
            moved_arm |= self._refine(found, from_afar)
            moved_arm |= self._refine(found, self._off_the_lid(found))
        finally:
            if moved_arm:
                self.toggler.go_rest()
        missing = expected - set(found)
        if missing:
            raise MarkersNotFound(missing, (), (self.config.overview_camera, self.config.wrist_camera))
        return found

    def _refine(self, found: dict[int, MarkerDetection], markers: list[int]) -> bool:
        """Replace ``markers`` in ``found`` by close-up measurements where seen; True if the arm moved."""
        height = lid_height(found, self.marker_lifts) if found else None
        for marker in sorted(markers):
            closer = self._measure_from_above(marker, found[marker].T_base_marker[:2, 3], height)
            if closer is not None:
                found[marker] = closer
        return bool(markers)

    def _off_the_lid(self, found: dict[int, MarkerDetection]) -> list[int]:
        """Overview markers posed off the plane of the others by more than ``lid_tolerance`` (all
        markers of a closed box lie on its lid)."""
        if len(found) < 2:
            return []
        height = lid_height(found, self.marker_lifts)
        return [
            m
            for m, d in found.items()
            if d.camera == self.config.overview_camera
            and abs(d.T_base_marker[2, 3] - self.marker_lifts.get(m, 0.0) - height) > self.config.lid_tolerance
        ]

    def _search(self, found: dict[int, MarkerDetection], missing: set[int]) -> list[MarkerDetection]:
        c = self.config
        if found:
            centre = np.mean([d.T_base_marker[:3, 3] for d in found.values()], axis=0)
            points = [centre + (dx, dy, 0.0) for dx, dy in c.search_offsets]
        else:
            points = [np.array([x, y, c.table_height]) for x, y in c.workspace_viewpoints]
        seen: dict[int, MarkerDetection] = {}
        for point in points:
            if not self._wrist_from_above(point, c.search_height):
                continue
            for d in self.look(self.config.wrist_camera):
                if d.marker_id in missing and (d.marker_id not in seen or d.view_angle < seen[d.marker_id].view_angle):
                    seen[d.marker_id] = d
            if missing <= set(seen):
                break
        return list(seen.values())

    def _unique(self, detections: list[MarkerDetection], expected: set[int]) -> dict[int, MarkerDetection]:
        """Expected ids seen exactly once (an id seen twice in one image is ambiguous: dropped)."""
        try:
            return select_markers(detections, expected, (self.config.overview_camera,))
        except MarkersNotFound as err:
            ambiguous = set(err.duplicated)
            return {d.marker_id: d for d in detections if d.marker_id in expected and d.marker_id not in ambiguous}
