"""The calibration rig in the twin: the rendered board sits exactly where it was placed, and calibration
from rendered images recovers the true cameras (``TwinSession.camera_truth``: overview intrinsics and
pose, wrist hand-eye) within the issue's targets, in the ideal cell and in a realistic one (camera
errors, noise, encoder noise); the rig aims with the nominal calibration; the scene without the board
is unchanged; the script refuses bad arguments cleanly."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from puzzlebox.models.calibration import CameraCalibration
from puzzlebox.models.charuco import BOARD_BODY, DEFAULT_BOARD
from puzzlebox.models.generator import paper_family
from puzzlebox.models.scene import SceneConfig, build_scene
from puzzlebox.skills.calibration import (
    CalibrationConfig,
    board_pose_in_camera,
    calibrate_intrinsics,
    detect_board,
    fixed_camera_pose,
    hand_eye,
    pose_error,
)
from puzzlebox.skills.errors import IKFailure
from puzzlebox.skills.primitives import Toggler
from puzzlebox.twin.calibration_rig import CalibrationCell

ROOT = Path(__file__).resolve().parents[2]


# Hand-eye bounds [m, deg] against the truth: exact arm poses under ideal; realistic adds encoder noise
# to the TCP poses the arm reports (measured: ~0.03 mm / 0.01 deg ideal, ~0.3 mm / 0.1 deg realistic).
HAND_EYE_BOUNDS = {"ideal": (0.001, 0.1), "realistic": (0.003, 0.3)}


@pytest.fixture(scope="module", params=["ideal", "realistic"])
def cell(request):
    with CalibrationCell(paper_family("test", seed=0)[0], seed=0, reality=request.param) as cell:
        yield cell


def test_the_truth_is_the_sessions_and_the_rig_aims_with_the_nominal_calibration(cell):
    for camera in (cell.overview_camera, cell.wrist_camera):
        truth = cell.camera_truth(camera)
        assert isinstance(truth, CameraCalibration)
        session_truth = cell.session.camera_truth(camera)
        assert np.array_equal(truth.K, session_truth.K) and np.array_equal(truth.dist, session_truth.dist)
    assert cell.camera_truth(cell.wrist_camera).on_arm and not cell.camera_truth(cell.overview_camera).on_arm
    # Under realistic the nominal overview pose is off the truth by more than the calibration's targets,
    # so meeting them below is the calibration's doing.
    truth = cell.camera_truth(cell.overview_camera)
    position, angle = pose_error(cell.nominal.camera(cell.overview_camera).T_base_camera, truth.T_base_camera)
    if cell.session.reality.name == "realistic":
        assert position > 0.002 and np.degrees(angle) > 0.2
    else:
        assert position < 1e-9 and angle < 1e-9
    # The held poses are aimed with the nominal camera: every one projects mostly into its nominal image.
    nominal = cell.nominal.camera(cell.overview_camera)
    T_base_camera_inv = np.linalg.inv(nominal.T_base_camera)
    for T_base_board in cell.board_poses_in_front_of(cell.overview_camera, 5, np.random.default_rng(3)):
        centre = T_base_board[:3, :3] @ DEFAULT_BOARD.center_in_board + T_base_board[:3, 3]
        x, y, z = T_base_camera_inv[:3, :3] @ centre + T_base_camera_inv[:3, 3]
        u, v = nominal.K[0, 0] * x / z + nominal.K[0, 2], nominal.K[1, 1] * y / z + nominal.K[1, 2]
        assert 0 < u < nominal.image_size[0] and 0 < v < nominal.image_size[1]


def test_a_rendered_board_is_found_exactly_where_it_was_placed(cell):
    truth = cell.camera_truth(cell.overview_camera)
    T_base_board = cell.board_poses_in_front_of(cell.overview_camera, 1, np.random.default_rng(0))[0]
    cell.place_board(T_base_board)
    view = detect_board(cell.capture(cell.overview_camera).rgb)
    assert view is not None and len(view.ids) >= 20
    T_camera_board = board_pose_in_camera(view, truth.K, truth.dist)
    position, angle = pose_error(truth.T_base_camera @ T_camera_board, T_base_board)
    assert position < 0.001 and np.degrees(angle) < 0.1


def test_the_board_lies_print_up_at_the_known_place(cell):
    T = cell.table_place()
    assert T[2, 2] == pytest.approx(-1.0)  # the board's z goes into the print: down
    centre = T[:3, :3] @ DEFAULT_BOARD.center_in_board + T[:3, 3]
    assert centre[:2] == pytest.approx(cell.session.config.scene.overview_xy)
    # A surveyed fixture: exactly the spec's box height plus the stand.
    assert centre[2] == pytest.approx(cell.session.spec.box.size[2] + cell.config.place_above_lid, abs=1e-12)


def test_overview_calibration_from_rendered_images_meets_the_targets(cell):
    rng = np.random.default_rng(1)
    images = []
    for T in cell.board_poses_in_front_of(cell.overview_camera, 10, rng):
        cell.place_board(T)
        images.append(cell.capture(cell.overview_camera).rgb)
    intrinsics = calibrate_intrinsics(images)
    truth = cell.camera_truth(cell.overview_camera)
    assert intrinsics.rms_px <= 0.5
    assert np.allclose(np.diag(intrinsics.K)[:2], np.diag(truth.K)[:2], rtol=0.005)

    T_base_board = cell.table_place()
    cell.place_board(T_base_board)
    pose = fixed_camera_pose(cell.capture(cell.overview_camera).rgb, intrinsics.K, intrinsics.dist, T_base_board)
    position, angle = pose_error(pose.T_base_camera, truth.T_base_camera)
    assert position < 0.002 and np.degrees(angle) < 0.2  # the targets
    assert pose.rms_px <= 0.5


def test_wrist_hand_eye_from_rendered_images_is_within_a_millimetre_or_a_few(cell):
    cell.session.reset()
    T_base_board = cell.table_place()
    cell.place_board(T_base_board)
    toggler = Toggler(cell.robot)
    images, tcp_poses = [], []
    for T_base_tcp in cell.wrist_viewpoints(T_base_board, 8, np.random.default_rng(2)):
        try:
            toggler.move_to(T_base_tcp, 1.0)
        except IKFailure:
            continue
        cell.robot.wait(0.2)
        images.append(cell.capture(cell.wrist_camera).rgb)
        tcp_poses.append(cell.robot.tcp_pose_in_base())
    assert len(images) >= 6
    truth = cell.camera_truth(cell.wrist_camera)
    # Intrinsics are not the point here (the overview test covers them): use the true ones.
    result = hand_eye(images, tcp_poses, truth.K, truth.dist, CalibrationConfig())
    position, angle = pose_error(result.T_tcp_camera, truth.T_tcp_camera)
    max_position, max_angle = HAND_EYE_BOUNDS[cell.session.reality.name]
    assert position < max_position and np.degrees(angle) < max_angle
    board_position, _ = pose_error(result.T_base_board, T_base_board)
    assert board_position < 0.003
    assert result.rms_px <= 0.5


def test_the_board_is_a_mocap_body_only_when_asked_for():
    spec = paper_family("test", seed=0)[0]
    plain = build_scene(spec).root.to_xml_string()
    assert BOARD_BODY not in plain
    with_board = build_scene(spec, SceneConfig(calibration_board=True))
    model = with_board.compile()
    assert model.body(BOARD_BODY).mocapid[0] >= 0
    assert model.nmocap == 1


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--reality", "no-such-profile"], "--reality"),
        (["--overview-views", "2"], "--overview-views must be at least 6"),
        (["--spec", "/no/such/spec.json"], "cannot use spec"),
    ],
)
def test_the_script_refuses_bad_arguments_in_one_line(tmp_path, args, message):
    result = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "calibrate.py"), "--out", str(tmp_path / "cal.json"), *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    assert message in result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
