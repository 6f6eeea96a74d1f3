"""Calibration recovers a known camera: intrinsics and distortion from synthetic board views (a view
with misplaced corners dropped), a fixed camera's pose from a board at a known place, an arm camera's
hand-eye pose from exact arm poses; too few views, inputs that do not go together, corrupted calibration
files and a calibration made for another cell are clear errors."""

from __future__ import annotations

import re

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from puzzlebox.models.calibration import CALIBRATION_FORMAT, CalibrationError, CameraCalibration, CellCalibration
from puzzlebox.models.charuco import DEFAULT_BOARD
from puzzlebox.skills.calibration import (
    BoardView,
    calibrate_intrinsics,
    detect_board,
    fixed_camera_pose,
    hand_eye,
    pose_error,
    solve_hand_eye_closed_form,
)
from puzzlebox.skills.errors import BoardNotFound, CalibrationFailed, InconsistentViews, TooFewViews

SIZE = (640, 480)
# A D435-like camera with a visible lens distortion (REALITY_NOTES.md §3, pessimistic k1).
K_TRUE = np.array([[612.4, 0.0, 314.3], [0.0, 610.6, 237.8], [0.0, 0.0, 1.0]])
DIST_TRUE = np.array([0.08, -0.15, 0.002, -0.001, 0.0])


def pose(rotvec, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    T[:3, 3] = t
    return T


def random_board_pose_in_camera(rng: np.random.Generator) -> np.ndarray:
    """The board 0.3-0.5 m ahead, tilted up to ~35 deg, turned about its normal, centred anywhere near the axis."""
    R = Rotation.from_euler("xyz", [rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6), rng.uniform(-np.pi, np.pi)])
    distance = rng.uniform(0.3, 0.5)
    centre = np.array([rng.uniform(-0.08, 0.08), rng.uniform(-0.06, 0.06), distance])
    T = np.eye(4)
    T[:3, :3] = R.as_matrix()
    T[:3, 3] = centre - R.as_matrix() @ DEFAULT_BOARD.center_in_board
    return T


def project_view(T_camera_board: np.ndarray, K=K_TRUE, dist=DIST_TRUE, noise_px: float = 0.0, rng=None) -> BoardView:
    """The board corners a camera would detect: exact projections (plus noise), those inside the image."""
    obj = DEFAULT_BOARD.corners_in_board()
    rvec = cv2.Rodrigues(T_camera_board[:3, :3])[0]
    points, _ = cv2.projectPoints(obj, rvec, T_camera_board[:3, 3], K, dist)
    points = points.reshape(-1, 2)
    if noise_px:
        points = points + rng.normal(0.0, noise_px, points.shape)
    inside = (points[:, 0] > 2) & (points[:, 0] < SIZE[0] - 3) & (points[:, 1] > 2) & (points[:, 1] < SIZE[1] - 3)
    ids = np.flatnonzero(inside)
    return BoardView(ids=ids, image_points=points[ids], object_points=obj[ids], image_size=SIZE)


def render_board(T_camera_board: np.ndarray, K=K_TRUE, dist=DIST_TRUE, pixels_per_square: int = 60) -> np.ndarray:
    """A synthetic image of the board (gray): each pixel's ray, undistorted, meets the board plane and
    reads the print there (bilinear)."""
    texture = DEFAULT_BOARD.image(pixels_per_square).astype(np.float32)
    u, v = np.meshgrid(np.arange(SIZE[0], dtype=np.float64), np.arange(SIZE[1], dtype=np.float64))
    pixels = np.stack([u.ravel(), v.ravel()], axis=1).reshape(-1, 1, 2)
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 20, 1e-9)
    rays = cv2.undistortPoints(pixels, K, dist, R=None, P=None, criteria=criteria)
    rays = np.concatenate([rays.reshape(-1, 2), np.ones((rays.shape[0], 1))], axis=1)
    R, t = T_camera_board[:3, :3], T_camera_board[:3, 3]
    # Board plane z_board = 0: points s * ray with R^T (s ray - t) having zero z.
    normal = R[:, 2]
    s = (normal @ t) / (rays @ normal)
    board_points = (s[:, None] * rays - t) @ R  # rows: R^T (p - t)
    scale = pixels_per_square / DEFAULT_BOARD.square_size
    margin = DEFAULT_BOARD.margin_pixels(pixels_per_square)
    map_x = (board_points[:, 0] * scale + margin - 0.5).reshape(SIZE[1], SIZE[0]).astype(np.float32)
    map_y = (board_points[:, 1] * scale + margin - 0.5).reshape(SIZE[1], SIZE[0]).astype(np.float32)
    image = cv2.remap(texture, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=200)
    return np.clip(image, 0, 255).astype(np.uint8)


def test_intrinsics_recover_a_known_camera_from_exact_projections():
    rng = np.random.default_rng(0)
    views = [project_view(random_board_pose_in_camera(rng), noise_px=0.1, rng=rng) for _ in range(15)]
    result = calibrate_intrinsics(views)
    assert np.allclose(np.diag(result.K)[:2], np.diag(K_TRUE)[:2], rtol=0.005)
    assert np.allclose(result.K[:2, 2], K_TRUE[:2, 2], atol=2.0)
    assert abs(result.dist[0] - DIST_TRUE[0]) < 0.02
    assert result.rms_px < 0.2
    assert len(result.views_used) == 15


def test_a_view_with_misplaced_corners_is_dropped_and_the_camera_still_recovered():
    rng = np.random.default_rng(10)
    views = [project_view(random_board_pose_in_camera(rng), noise_px=0.1, rng=rng) for _ in range(12)]
    bad = views[4]
    # A few pixels of error on every corner of one view (a misdetection, motion blur).
    views[4] = BoardView(
        bad.ids, bad.image_points + rng.normal(0.0, 3.0, bad.image_points.shape), bad.object_points, SIZE
    )
    result = calibrate_intrinsics(views)
    assert result.views_dropped == (4,)
    assert 4 not in result.views_used and len(result.views_used) == 11
    assert np.allclose(np.diag(result.K)[:2], np.diag(K_TRUE)[:2], rtol=0.005)
    assert result.rms_px < 0.2


def test_intrinsics_recover_a_known_camera_from_synthetic_images():
    rng = np.random.default_rng(1)
    images = [render_board(random_board_pose_in_camera(rng)) for _ in range(10)]
    result = calibrate_intrinsics(images)
    assert np.allclose(np.diag(result.K)[:2], np.diag(K_TRUE)[:2], rtol=0.005)
    assert np.allclose(result.K[:2, 2], K_TRUE[:2, 2], atol=3.0)
    assert result.rms_px < 0.5


def test_detected_corners_match_their_projections_in_a_synthetic_image():
    T = random_board_pose_in_camera(np.random.default_rng(2))
    view = detect_board(render_board(T))
    assert view is not None and len(view.ids) >= 20
    exact = project_view(T)
    expected = {i: p for i, p in zip(exact.ids, exact.image_points, strict=True)}
    errors = [np.linalg.norm(p - expected[i]) for i, p in zip(view.ids, view.image_points, strict=True)]
    assert np.median(errors) < 0.15


def test_too_few_views_is_a_clear_error():
    rng = np.random.default_rng(3)
    views = [project_view(random_board_pose_in_camera(rng)) for _ in range(3)]
    blank = np.full((SIZE[1], SIZE[0], 3), 255, np.uint8)
    with pytest.raises(TooFewViews, match=r"at least 6 views .* 3 of the 5 images"):
        calibrate_intrinsics([*views, blank, blank])


def test_a_fixed_camera_pose_comes_from_the_board_at_a_known_place():
    rng = np.random.default_rng(4)
    T_base_camera = pose([np.pi, 0.02, -0.01], [0.45, 0.0, 0.58])  # looking down, slightly off
    T_base_board = pose([np.pi, 0.0, 0.1], [0.33, -0.08, 0.16])  # print up
    # eight frames of the still board, 0.1 px corner noise each (subpixel saddle points): pooled, as the
    # calibration script does
    views = [project_view(_inverse(T_base_camera) @ T_base_board, noise_px=0.1, rng=rng) for _ in range(8)]
    result = fixed_camera_pose(views, K_TRUE, DIST_TRUE, T_base_board)
    position, angle = pose_error(result.T_base_camera, T_base_camera)
    assert position < 0.002 and np.degrees(angle) < 0.2  # the target
    assert result.rms_px < 0.35
    exact = fixed_camera_pose(project_view(_inverse(T_base_camera) @ T_base_board), K_TRUE, DIST_TRUE, T_base_board)
    position, angle = pose_error(exact.T_base_camera, T_base_camera)
    assert position < 1e-6 and angle < 1e-6


def test_a_fixed_camera_without_a_board_in_view_is_a_clear_error():
    with pytest.raises(BoardNotFound, match="no board"):
        fixed_camera_pose(np.zeros((480, 640, 3), np.uint8), K_TRUE, DIST_TRUE, np.eye(4))


def _inverse(T: np.ndarray) -> np.ndarray:
    return np.linalg.inv(T)


def hand_eye_scene(rng: np.random.Generator, n: int):
    """Eye-in-hand: a camera 8 cm off the TCP axis looking along it, the board fixed, n arm poses above it."""
    T_tcp_camera = pose([0.0, 0.0, np.pi / 2 + 0.03], [0.0, 0.075, -0.13])
    T_base_board = pose([np.pi, 0.0, 0.2], [0.35, -0.1, 0.16])
    centre = T_base_board[:3, :3] @ DEFAULT_BOARD.center_in_board + T_base_board[:3, 3]
    T_base_tcp = []
    for _ in range(n):
        tilt = Rotation.from_euler("xyz", [np.pi + rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), rng.uniform(-1, 1)])
        T = np.eye(4)
        T[:3, :3] = tilt.as_matrix()
        # put the camera ~0.3 m from the board centre along its optical axis
        T_base_camera_rot = T[:3, :3] @ T_tcp_camera[:3, :3]
        camera_position = centre - T_base_camera_rot[:, 2] * rng.uniform(0.25, 0.35)
        T[:3, 3] = camera_position - T[:3, :3] @ T_tcp_camera[:3, 3]
        T_base_tcp.append(T)
    T_camera_board = [_inverse(G @ T_tcp_camera) @ T_base_board for G in T_base_tcp]
    return T_tcp_camera, T_base_board, T_base_tcp, T_camera_board


def test_closed_form_hand_eye_is_exact_on_exact_poses():
    T_tcp_camera, _, G, C = hand_eye_scene(np.random.default_rng(5), 8)
    X = solve_hand_eye_closed_form(G, C)
    position, angle = pose_error(X, T_tcp_camera)
    assert position < 1e-6 and angle < 1e-6


def test_hand_eye_recovers_a_known_camera_from_board_views():
    rng = np.random.default_rng(6)
    T_tcp_camera, T_base_board, G, C = hand_eye_scene(rng, 12)
    views = [project_view(c, noise_px=0.2, rng=rng) for c in C]
    result = hand_eye(views, G, K_TRUE, DIST_TRUE)
    position, angle = pose_error(result.T_tcp_camera, T_tcp_camera)
    assert position < 0.001 and np.degrees(angle) < 0.1
    board_position, _ = pose_error(result.T_base_board, T_base_board)
    assert board_position < 0.002
    assert result.rms_px < 0.35


def test_inputs_that_do_not_go_together_are_a_calibration_error():
    _, _, G, C = hand_eye_scene(np.random.default_rng(8), 6)
    views = [project_view(c) for c in C]
    with pytest.raises(InconsistentViews, match="one TCP pose per image"):
        hand_eye(views, G[:-1], K_TRUE, DIST_TRUE)
    other_size = BoardView(views[0].ids, views[0].image_points, views[0].object_points, (1280, 720))
    with pytest.raises(InconsistentViews, match="share one size"):
        calibrate_intrinsics([*views, other_size])
    with pytest.raises(CalibrationFailed, match=r"\(H, W\)"):
        detect_board(np.zeros((4, 4, 4, 4), np.uint8))


def test_hand_eye_without_rotation_is_a_clear_error():
    T_tcp_camera, T_base_board, G, _ = hand_eye_scene(np.random.default_rng(7), 1)
    shifted = []
    for dx in (0.0, 0.02, 0.04, -0.02, -0.04):  # pure translations: the rotation is undetermined
        T = G[0].copy()
        T[0, 3] += dx
        shifted.append(T)
    views = [project_view(_inverse(g @ T_tcp_camera) @ T_base_board) for g in shifted]
    with pytest.raises(TooFewViews, match="non-parallel axes"):
        hand_eye(views, shifted, K_TRUE, DIST_TRUE)


CELL = {"profile": "realistic", "cell_seed": 3, "box_height": 0.12, "spec": "paper-test-0"}


def test_a_calibration_file_round_trips(tmp_path):
    camera = CameraCalibration(K_TRUE, DIST_TRUE, SIZE, T_base_camera=np.eye(4), reprojection_error_px=0.1)
    T_tcp_camera = pose([0.01, -0.02, np.pi / 2], [0.0, 0.075, -0.13])
    wrist = CameraCalibration(K_TRUE, DIST_TRUE, SIZE, T_tcp_camera=T_tcp_camera, extra={"views": 14})
    cell = CellCalibration({"overview": camera, "wrist": wrist}, source="test", cell=CELL)
    path = cell.save(tmp_path / "cal.json")
    loaded_cell = CellCalibration.load(path)
    loaded = loaded_cell.camera("overview")
    assert np.array_equal(loaded.K, K_TRUE) and np.array_equal(loaded.dist, DIST_TRUE)
    assert loaded_cell.to_dict() == cell.to_dict()
    loaded_wrist = loaded_cell.camera("wrist")
    assert loaded_wrist.on_arm and loaded_wrist.to_dict() == wrist.to_dict()
    assert np.array_equal(loaded_wrist.T_tcp_camera, T_tcp_camera)
    assert loaded_cell.cell == CELL


def test_a_lens_that_does_not_map_the_image_onto_itself_is_refused_and_real_lenses_pass():
    """The distortion check samples the radial factor from the centre to the farthest corner: a wide lens (its
    corners shrunk ~25 %), this module's camera and the twin's pinhole pass; k1 = 1000, a barrel strong enough to
    fold the corners back in, large tangential terms, fx three times fy and a principal point off the image do
    not."""
    wide = np.array([-0.32, 0.11, 0.0005, -0.0008, -0.015])  # a typical 90 deg-class lens
    for dist in (DIST_TRUE, wide, np.zeros(5)):
        CameraCalibration(K_TRUE, dist, SIZE, T_base_camera=np.eye(4))
    scaled = K_TRUE.copy()
    scaled[0, 0] *= 3.0
    off = K_TRUE.copy()
    off[0, 2] = -40.0
    for K, dist, message in (
        (K_TRUE, [1000.0, 0, 0, 0, 0], "scale the image by 1-"),
        (K_TRUE, [-3.0, 0, 0, 0, 0], "fold it over"),
        (K_TRUE, [0.0, 0, 0.2, 0, 0], "tangential"),
        (scaled, DIST_TRUE, "differ by more than 1.5x"),
        (off, DIST_TRUE, "principal point (-40, 237.8) px lies outside"),
    ):
        with pytest.raises(CalibrationError, match=re.escape(message)):
            CameraCalibration(K, np.asarray(dist), SIZE, T_base_camera=np.eye(4))


def test_a_calibration_applies_only_to_the_cell_it_was_made_for(tmp_path):
    camera = CameraCalibration(K_TRUE, DIST_TRUE, SIZE, T_base_camera=np.eye(4))
    calibration = CellCalibration({"overview": camera}, cell=CELL)
    calibration.check_cell("realistic", 3, 0.12)  # the same cell: no complaint
    for wrong, what in (
        (("harsh", 3, 0.12), "profile 'realistic' instead of 'harsh'"),
        (("realistic", 0, 0.12), "cell seed 3 instead of 0"),
        (("realistic", 3, 0.15), "box height 0.12 m instead of 0.1500 m"),
    ):
        with pytest.raises(CalibrationError, match="another cell") as err:
            calibration.check_cell(*wrong, spec="box.json")
        message = str(err.value)
        assert what in message and len(message.splitlines()) == 1
        assert f"scripts/calibrate.py --reality {wrong[0]} --cell-seed {wrong[1]} --spec box.json" in message
    # A file from before cells were recorded still loads, but cannot be checked against a cell.
    data = calibration.to_dict()
    del data["cell"]
    old = CellCalibration.from_dict(data)
    assert old.cell == {} and old.camera("overview").K.tolist() == K_TRUE.tolist()
    with pytest.raises(CalibrationError, match="does not record the cell"):
        old.check_cell("realistic", 3, 0.12)
    with pytest.raises(CalibrationError, match="'cell' must map"):
        CellCalibration.from_dict({"format": CALIBRATION_FORMAT, "cell": [1], "cameras": data["cameras"]})


@pytest.mark.parametrize(
    ("corrupt", "message"),
    [
        (lambda text: text[: len(text) // 2], "is not JSON"),
        (lambda text: text.replace("puzzlebox-calibration/1", "other/1"), "not a calibration file"),
        (lambda text: text.replace('"K": [', '"K": [[1, 2, 3], '), "K must be"),
        (lambda text: text.replace('"K"', '"k"'), "unknown camera calibration keys"),
        (lambda text: text.replace('"dist": [', '"dist": [1e999, '), "dist must be"),
    ],
)
def test_a_corrupted_calibration_file_is_refused(tmp_path, corrupt, message):
    camera = CameraCalibration(K_TRUE, DIST_TRUE, SIZE, T_base_camera=np.eye(4))
    path = CellCalibration({"overview": camera}).save(tmp_path / "cal.json")
    path.write_text(corrupt(path.read_text()))
    with pytest.raises(CalibrationError, match=message):
        CellCalibration.load(path)
