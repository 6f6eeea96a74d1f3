"""ArUco marker images, and marker geoms that a rendered camera reads back at their true pose."""

from __future__ import annotations

import math
import os

# The project's rendering default, before dm_control is imported (an explicit MUJOCO_GL wins): unset,
# dm_control would pick GLFW and warn that there is no display.
os.environ.setdefault("MUJOCO_GL", "egl")

import cv2  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from dm_control import mjcf  # noqa: E402

from puzzlebox.models.errors import ModelsError  # noqa: E402
from puzzlebox.models.markers import (  # noqa: E402
    MARKER_BITS,
    MAX_MARKER_ID,
    MarkerError,
    add_marker_geom,
    add_marker_material,
    aruco_dictionary,
    marker_geom_size,
    marker_image,
)
from puzzlebox.twin.rendering import RenderConfig, Renderer  # noqa: E402

MARKER_SIZE = 0.04
"""Black square side of the markers in the rendered scene [m]."""
CAMERA_HEIGHT = 0.35
"""Height of the downward camera above the markers' top faces [m]."""


def detector() -> cv2.aruco.ArucoDetector:
    parameters = cv2.aruco.DetectorParameters()
    parameters.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    return cv2.aruco.ArucoDetector(aruco_dictionary(), parameters)


def detect(gray: np.ndarray) -> dict[int, np.ndarray]:
    corners, ids, _ = detector().detectMarkers(gray)
    return {} if ids is None else {int(i): c.reshape(4, 2) for i, c in zip(ids.ravel(), corners, strict=True)}


@pytest.mark.parametrize("marker_id", [0, 1, 17, 100, MAX_MARKER_ID])
def test_marker_image_is_detected_with_its_id(marker_id):
    image = marker_image(marker_id)
    # A detector needs white around the quiet zone's outside edge too, as on a real surface.
    found = detect(np.pad(image, 16, constant_values=255))
    assert list(found) == [marker_id]


def test_marker_image_has_black_square_of_six_bits_inside_the_quiet_zone():
    image = marker_image(5, pixels_per_bit=10, quiet_zone_bits=2)
    assert image.shape == (100, 100) and image.dtype == np.uint8
    assert (image[:20] == 255).all() and (image[:, -20:] == 255).all()  # quiet zone
    assert (image[20:30, 20:80] == 0).all() and (image[20:80, 70:80] == 0).all()  # black border bits
    assert set(np.unique(image)) == {0, 255}  # crisp bits, no interpolation
    found = detect(np.pad(marker_image(5, pixels_per_bit=10, quiet_zone_bits=2), 10, constant_values=255))
    assert list(found) == [5]


@pytest.mark.parametrize("bad_id", [-1, MAX_MARKER_ID + 1, 1000])
def test_marker_id_outside_the_dictionary_is_rejected_naming_the_valid_range(bad_id):
    with pytest.raises(MarkerError, match=r"0\.\.249"):
        marker_image(bad_id)
    with pytest.raises(ModelsError):
        add_marker_material(mjcf.RootElement(), bad_id, "marker")


def test_marker_geom_size_makes_the_black_square_the_requested_size():
    half = marker_geom_size(0.036)
    # The face is 8 bits wide (6 marker bits + 1 quiet bit each side), the black square 6 of them.
    assert 2 * half * MARKER_BITS / (MARKER_BITS + 2) == pytest.approx(0.036)
    assert marker_geom_size(0.036, quiet_zone_bits=0) == pytest.approx(0.018)


def test_marker_material_names_texture_and_material_after_the_given_name():
    root = mjcf.RootElement()
    material = add_marker_material(root, 3, "door_marker")
    assert material.name == "door_marker"
    assert material.texture.name == "door_marker_texture" and material.texture.type == "2d"
    assert root.find("texture", "door_marker_texture") is not None


# (id, position of the top-face centre [m], yaw [deg]): yaws in all four quadrants, so that a texture
# turned by 90 or 180 degrees, or mirrored (which decodes no id or a wrong one), cannot pass.
MARKERS = [
    (0, (-0.06, 0.045, 0.012), 0.0),
    (7, (0.06, 0.045, 0.012), 35.0),
    (42, (-0.06, -0.045, 0.012), 120.0),
    (249, (0.06, -0.045, 0.012), -150.0),
]


@pytest.fixture(scope="module")
def marker_scene():
    """Markers on a slab, a light and a camera looking straight down, compiled and forwarded."""
    root = mjcf.RootElement()
    root.worldbody.add("light", pos=[0.2, -0.3, 1.5], dir=[-0.1, 0.2, -1])
    root.worldbody.add("geom", type="plane", size=[1, 1, 0.05], rgba=[0.35, 0.35, 0.4, 1])
    root.worldbody.add("camera", name="down", pos=[0.0, 0.0, 0.012 + CAMERA_HEIGHT], fovy=50)
    slab = root.worldbody.add("body", name="slab", pos=[0, 0, 0.006])
    slab.add("geom", type="box", size=[0.15, 0.12, 0.006], rgba=[0.55, 0.4, 0.25, 1])
    for marker_id, (x, y, z), yaw in MARKERS:
        add_marker_geom(
            slab, marker_id, f"marker_{marker_id}", MARKER_SIZE, pos=(x, y, z - 0.006), yaw=math.radians(yaw)
        )
    model = mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def test_rendered_marker_geoms_are_read_at_their_true_position_and_yaw(marker_scene):
    model, data = marker_scene
    with Renderer(model, RenderConfig(width=640, height=480)) as renderer:
        image = renderer.render(data, "down")
        K = renderer.camera_intrinsics("down")
        T_world_camera = renderer.camera_pose_in_world(data, "down")

    found = detect(cv2.cvtColor(image, cv2.COLOR_RGB2GRAY))
    assert sorted(found) == sorted(m[0] for m in MARKERS)

    h = MARKER_SIZE / 2
    # OpenCV's square-marker object points: top-left, top-right, bottom-right, bottom-left, z out.
    object_points = np.array([[-h, h, 0], [h, h, 0], [h, -h, 0], [-h, -h, 0]])
    for marker_id, position, yaw in MARKERS:
        ok, rvec, tvec = cv2.solvePnP(object_points, found[marker_id], K, None, flags=cv2.SOLVEPNP_IPPE_SQUARE)
        assert ok
        T_camera_marker = np.eye(4)
        T_camera_marker[:3, :3] = cv2.Rodrigues(rvec)[0]
        T_camera_marker[:3, 3] = tvec.ravel()
        T_world_marker = T_world_camera @ T_camera_marker

        position_error = np.linalg.norm(T_world_marker[:3, 3] - np.array(position))
        assert position_error < 0.003, f"marker {marker_id} off by {position_error * 1000:.2f} mm"
        measured_yaw = math.degrees(math.atan2(T_world_marker[1, 0], T_world_marker[0, 0]))
        yaw_error = (measured_yaw - yaw + 180.0) % 360.0 - 180.0
        assert abs(yaw_error) < 2.0, f"marker {marker_id} seen at yaw {measured_yaw:.1f} deg, placed at {yaw} deg"
        assert T_world_marker[2, 2] > math.cos(math.radians(5))  # z out of the marker, towards the camera
