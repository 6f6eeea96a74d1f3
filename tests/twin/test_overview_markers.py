"""cv2.aruco finds every component's marker in the overview image with the right id, where the
component is (the cell's nominal calibration, exact in the ideal twin, turns pixels into base-frame positions)."""

from dataclasses import replace

import cv2
import numpy as np
import pytest

from puzzlebox.models.generator import paper_family
from puzzlebox.models.markers import aruco_dictionary
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.session import TwinSession


def detect(rgb: np.ndarray) -> dict[int, np.ndarray]:
    parameters = cv2.aruco.DetectorParameters()
    parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    detector = cv2.aruco.ArucoDetector(aruco_dictionary(), parameters)
    corners, ids, _ = detector.detectMarkers(cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY))
    return {} if ids is None else {int(i): c.reshape(4, 2) for i, c in zip(ids.ravel(), corners, strict=True)}


def pixel_to_table(K: np.ndarray, T_base_camera: np.ndarray, pixel: np.ndarray, z: float) -> np.ndarray:
    """Intersect the ray through ``pixel`` with the plane at height ``z`` in the base frame."""
    ray_camera = np.linalg.solve(K, np.array([pixel[0], pixel[1], 1.0]))
    ray_base = T_base_camera[:3, :3] @ ray_camera
    origin = T_base_camera[:3, 3]
    return origin + ray_base * (z - origin[2]) / ray_base[2]


@pytest.mark.parametrize("box_pose", [None, (0.40, 0.08, 0.9)], ids=["default", "moved-and-turned"])
@pytest.mark.parametrize("index", [0, 1, 2])
def test_overview_camera_reads_every_marker_with_its_id_where_the_component_is(index, box_pose):
    spec = paper_family("test")[index]
    if box_pose is not None:
        spec = replace(spec, box=replace(spec.box, pose=box_pose))
    with TwinSession(spec, seed=0) as session:
        image = session.robot.capture("overview")
        calibration = nominal_calibration(session).camera("overview")
        found = detect(image.rgb)
        assert sorted(found) == sorted(c.marker for c in spec.components)
        for c in spec.components:
            centre = found[c.marker].mean(axis=0)
            truth = session.data.site(session.scene.names.components[c.name].frame_site).xpos
            seen = pixel_to_table(calibration.K, calibration.T_base_camera, centre, truth[2])
            assert np.linalg.norm(seen[:2] - truth[:2]) < 0.003, c.name
