"""ArUco perception: marker detections in camera images -> component poses in the robot base frame.

Detection uses OpenCV's ArUco detector with sub-pixel corner refinement; each marker's pose comes from
``solvePnP`` with ``SOLVEPNP_IPPE_SQUARE`` and the *calibrated* intrinsics and distortion
(:class:`models.calibration.CameraCalibration`, never the camera's truth), and goes to the base frame
with the calibrated extrinsics — for the wrist camera composed with the TCP pose the arm reported at
capture (DESIGN.md: 0.7-2 mm error at 0.3-0.6 m). A pose is only trusted when the marker's corners
reproject within ``max_reprojection_error_px`` and the camera sees the marker no more obliquely than
``max_view_angle``: a grazing view gives a foreshortened, ill-conditioned pose. A marker map — as a
real cell has — gives each id's kind. By construction of the puzzle box (``models.kinds``), a
component's frame is its marker's frame in state 0, so a marker seen on a closed component gives the
component pose directly.

Only the robot interface's images and calibrations are used: never simulator ground truth.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from puzzlebox.models import geometry
from puzzlebox.models.calibration import CameraCalibration
from puzzlebox.models.cell_config import CellConfig, aruco_dictionary_name
from puzzlebox.models.kinds import MARKER_SIZE
from puzzlebox.models.markers import ARUCO_DICTIONARY, aruco_dictionary
from puzzlebox.models.robot import CameraImage
from puzzlebox.skills.errors import MarkersNotFound, UnknownMarker


@dataclass(frozen=True)
class PerceptionConfig:
    """How markers are read."""

    marker_size: float = MARKER_SIZE
    """Side of the markers' black square [m]."""
    min_marker_pixels: float = 12.0
    """Smaller detections (side in pixels) are ignored: too few pixels per bit to trust the id."""
    max_reprojection_error_px: float = 1.5
    """RMS corner reprojection error above which a marker's pose is not trusted [px] (sub-pixel corners
    reproject within ~0.3 px; a marker half occluded, blurred or mis-decoded does not)."""
    max_view_angle_deg: float = 55.0
    """Largest angle between the marker's normal and the line of sight for a trusted pose [deg]."""
    dictionary: str = aruco_dictionary_name(ARUCO_DICTIONARY)
    """OpenCV's name of the markers' ArUco dictionary (default the project's, ``DICT_4X4_250``): a marker of
    another dictionary is not read."""

    @classmethod
    def for_cell(cls, cell: CellConfig, **overrides: Any) -> PerceptionConfig:
        """How a cell's markers are read: its dictionary and marker size (the rest as given, or the defaults)."""
        return cls(**{"dictionary": cell.aruco_dictionary, "marker_size": cell.marker_size, **overrides})


@dataclass(frozen=True)
class MarkerDetection:
    """One marker seen by one camera.

    Attributes:
        marker_id: ArUco id.
        camera: the camera that saw it.
        corners_px: ``(4, 2)`` image corners [px], OpenCV order (top-left, clockwise in the marker).
        T_base_marker: 4x4 pose of the marker frame (x right, y up on the marker, z out of it) in the
            robot base frame [m].
    """

    marker_id: int
    camera: str
    corners_px: np.ndarray
    T_base_marker: np.ndarray
    reprojection_error_px: float = 0.0
    """RMS reprojection error of the four corners [px]."""
    view_angle: float = 0.0
    """Angle between the marker's normal and the line of sight [rad]."""

    @property
    def planar_pose(self) -> np.ndarray:
        """``[x, y, yaw]`` of the marker in the base frame [m, m, rad] (yaw of its x axis about z)."""
        T = self.T_base_marker
        return np.array([T[0, 3], T[1, 3], math.atan2(T[1, 0], T[0, 0])])


def upright_pose(planar_pose: np.ndarray, height: float) -> np.ndarray:
    """4x4 pose with z up at ``[x, y, yaw]`` and ``height`` [m].

    Seen from above, a small marker's tilt is ill-conditioned (the two IPPE solutions differ by
    several degrees) while its position and yaw are accurate; a box on a level table has its lid
    level, so components are placed upright."""
    x, y, yaw = planar_pose
    return geometry.upright_pose(x, y, yaw, height)


def lid_height(detections: dict[int, MarkerDetection], lifts: dict[int, float] | None = None) -> float:
    """Height of the markers' plane [m]: the median of their heights (all lie on the lid, state 0), each
    less its part's ``lifts[marker]`` (a kind's ``KindTemplate.lift``: a lever's marker stands on its arm
    30 mm above the others; with two markers the median is their mean)."""
    lifts = lifts or {}
    return float(np.median([d.T_base_marker[2, 3] - lifts.get(m, 0.0) for m, d in detections.items()]))


class MarkerDetector:
    """Finds markers in a camera image and estimates their poses in the base frame."""

    def __init__(self, config: PerceptionConfig | None = None) -> None:
        self.config = config or PerceptionConfig()
        parameters = cv2.aruco.DetectorParameters()
        parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
        dictionary = aruco_dictionary(getattr(cv2.aruco, self.config.dictionary))
        self._detector = cv2.aruco.ArucoDetector(dictionary, parameters)
        half = self.config.marker_size / 2
        # marker corners in the marker frame, in the order IPPE_SQUARE expects
        self._object_points = np.array([[-half, half, 0], [half, half, 0], [half, -half, 0], [-half, -half, 0]])

    def detect_pixels(self, rgb: np.ndarray) -> list[tuple[np.ndarray, int]]:
        """Image corners ``(4, 2)`` [px] and id of every marker in an RGB image (no pose)."""
        corners, ids, _ = self._detector.detectMarkers(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
        if ids is None:
            return []
        return [(c.reshape(4, 2), int(i)) for c, i in zip(corners, ids.ravel(), strict=True)]

    def detect(
        self, image: CameraImage | None, camera: CameraCalibration, T_base_tcp: np.ndarray | None = None
    ) -> list[MarkerDetection]:
        """The trusted markers in ``image`` (see the module docstring), posed with the calibration
        ``camera``; an arm camera needs ``T_base_tcp``, the TCP pose the arm reported at capture [m].
        A dropped frame (``None``) has no markers."""
        return [d for d in self.detect_all(image, camera, T_base_tcp) if self.trusted(d)]

    def trusted(self, detection: MarkerDetection) -> bool:
        """Whether a detection's pose may be used (reprojection error and viewing angle in bounds)."""
        return (
            detection.reprojection_error_px <= self.config.max_reprojection_error_px
            and detection.view_angle <= math.radians(self.config.max_view_angle_deg)
        )

    def detect_all(
        self, image: CameraImage | None, camera: CameraCalibration, T_base_tcp: np.ndarray | None = None
    ) -> list[MarkerDetection]:
        """Every marker in ``image`` with its pose, reprojection error and viewing angle, trusted or not."""
        if image is None:
            return []
        T_base_camera = camera.pose_in_base(T_base_tcp)
        gray = cv2.cvtColor(image.rgb, cv2.COLOR_RGB2GRAY)
        corners, ids, _ = self._detector.detectMarkers(gray)
        if ids is None:
            return []
        detections = []
        for marker_id, c in zip(ids.ravel(), corners, strict=True):
            c = c.reshape(4, 2).astype(np.float64)
            if np.linalg.norm(c[0] - c[1]) < self.config.min_marker_pixels:
                continue
            ok, rvec, tvec = cv2.solvePnP(self._object_points, c, camera.K, camera.dist, flags=cv2.SOLVEPNP_IPPE_SQUARE)
            if not ok:
                continue
            projected, _ = cv2.projectPoints(self._object_points, rvec, tvec, camera.K, camera.dist)
            error = float(np.sqrt(np.mean(np.sum((projected.reshape(4, 2) - c) ** 2, axis=1))))
            T_camera_marker = np.eye(4)
            T_camera_marker[:3, :3] = cv2.Rodrigues(rvec)[0]
            T_camera_marker[:3, 3] = tvec.ravel()
            sight = T_camera_marker[:3, 3] / np.linalg.norm(T_camera_marker[:3, 3])
            angle = math.acos(min(1.0, abs(float(np.dot(sight, T_camera_marker[:3, 2])))))
            detections.append(
                MarkerDetection(int(marker_id), image.camera, c, T_base_camera @ T_camera_marker, error, angle)
            )
        return detections


def select_markers(
    detections: list[MarkerDetection], expected: set[int], cameras: tuple[str, ...]
) -> dict[int, MarkerDetection]:
    """One detection per expected id; raises :class:`MarkersNotFound` for missing or duplicated ids
    (within one camera: two markers with the same id) — never guesses."""
    by_camera: dict[str, Counter] = {}
    for d in detections:
        by_camera.setdefault(d.camera, Counter())[d.marker_id] += 1
    duplicated = {i for counts in by_camera.values() for i, n in counts.items() if n > 1 and i in expected}
    chosen: dict[int, MarkerDetection] = {}
    for d in detections:  # the first camera that saw an id unambiguously wins
        if d.marker_id in expected and d.marker_id not in duplicated and d.marker_id not in chosen:
            chosen[d.marker_id] = d
    missing = expected - set(chosen) - duplicated
    if missing or duplicated:
        raise MarkersNotFound(missing, duplicated, cameras)
    return chosen


def kind_of(marker_map: dict[int, str], marker_id: int) -> str:
    try:
        return marker_map[marker_id]
    except KeyError:
        raise UnknownMarker(
            f"marker id {marker_id} is not in the marker map; known ids: {sorted(marker_map)}"
        ) from None
