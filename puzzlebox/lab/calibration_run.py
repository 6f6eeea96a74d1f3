"""The cell's camera calibration procedure (``scripts/calibrate.py``, ``experiment.py reality``): the
steps a real cell runs with a ChArUco board, on the twin — see ``calibrate.py``'s docstring."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from puzzlebox.lab.cli import one_line
from puzzlebox.models import ModelsError
from puzzlebox.models.calibration import CameraCalibration, CellCalibration
from puzzlebox.models.spec import PuzzleSpec
from puzzlebox.skills.calibration import (
    CalibrationConfig,
    calibrate_intrinsics,
    detect_board,
    fixed_camera_pose,
    hand_eye,
    pose_error,
)
from puzzlebox.skills.errors import IKFailure, SkillError
from puzzlebox.skills.kinematics import ArmKinematics
from puzzlebox.skills.primitives import Toggler
from puzzlebox.twin.calibration_rig import CalibrationCell, RigConfig, RigError
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.reality import RealityProfile


class CellCalibrationError(Exception):
    """The procedure could not run (``exit_code`` 2: a bad spec or profile for the cell) or failed
    (``exit_code`` 1: too few usable views, the arm could not reach, the rig found no pose)."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message)
        self.exit_code = exit_code


@dataclass
class CellCalibrationRun:
    """What the procedure made: the calibration, per-camera figures (reprojection errors and, this being
    the twin, errors against the truth) and the configs it ran with."""

    calibration: CellCalibration
    figures: dict[str, dict[str, Any]]
    settings: dict[str, Any]
    overview: str
    wrist: str


def calibrate_cell(
    spec: PuzzleSpec, profile: RealityProfile, seed: int = 0, overview_views: int = 20, wrist_views: int = 16
) -> CellCalibrationRun:
    """Calibrate both cameras of the cell of ``spec`` under ``profile`` (see ``scripts/calibrate.py``).

    Raises:
        CellCalibrationError: with the exit code a command line should use.
    """
    rng = np.random.default_rng(seed)
    rig_config, calibration_config = RigConfig(), CalibrationConfig()
    try:
        cell = CalibrationCell(spec, seed=seed, reality=profile, config=rig_config)
    except (ModelsError, TwinError) as err:
        message = f"cannot build the cell for spec {spec.name} under profile {profile.name!r}: {one_line(err)}"
        raise CellCalibrationError(message, 2) from None
    with cell:
        robot = cell.robot
        overview, wrist = cell.overview_camera, cell.wrist_camera
        try:
            # 1. intrinsics of the overview camera: the board held in front of it
            images = []
            for T_base_board in cell.board_poses_in_front_of(overview, overview_views, rng):
                cell.place_board(T_base_board)
                images.append(cell.capture(overview).rgb)
            overview_intrinsics = calibrate_intrinsics(images, calibration_config)

            # 2. its pose: the board at the known place, a few still frames pooled
            T_base_board = cell.table_place()
            cell.place_board(T_base_board)
            frames = []
            for _ in range(4):
                frames.append(cell.capture(overview).rgb)
                robot.wait(0.02)
            overview_pose = fixed_camera_pose(
                frames, overview_intrinsics.K, overview_intrinsics.dist, T_base_board, calibration_config
            )

            # 3. the wrist camera: the board stays, the arm moves; each image's corners found once
            toggler = Toggler(robot, kinematics=ArmKinematics())
            board_views, tcp_poses, unreachable = [], [], 0
            for T_base_tcp in cell.wrist_viewpoints(T_base_board, wrist_views, rng):
                try:
                    toggler.move_to(T_base_tcp, 1.5)
                except IKFailure:
                    unreachable += 1
                    continue
                robot.wait(0.3)  # still: no motion blur, the servos settled
                board_views.append(detect_board(cell.capture(wrist).rgb, calibration_config))
                tcp_poses.append(robot.tcp_pose_in_base())
            toggler.go_rest()
            wrist_intrinsics = calibrate_intrinsics(board_views, calibration_config)
            wrist_pose = hand_eye(board_views, tcp_poses, wrist_intrinsics.K, wrist_intrinsics.dist, calibration_config)
        except (SkillError, RigError) as err:
            raise CellCalibrationError(f"calibration failed: {one_line(err)}", 1) from None

        truth = {name: cell.camera_truth(name) for name in (overview, wrist)}
        made_for = {
            "profile": cell.session.reality.name,
            "cell_seed": int(cell.session.reality.cell_seed),
            "box_height": cell.box_height,
            "spec": spec.name,
        }

    source = (
        f"charuco, profile {made_for['profile']}, cell seed {made_for['cell_seed']}, "
        f"box height {made_for['box_height']:.4f} m, spec {spec.name}, seed {seed}"
    )
    figures = {}
    cameras = {}
    for name, intrinsics, pose_kind in (
        (overview, overview_intrinsics, "fixed"),
        (wrist, wrist_intrinsics, "arm"),
    ):
        t = truth[name]
        if pose_kind == "fixed":
            T_est, T_true, pose_rms = overview_pose.T_base_camera, t.T_base_camera, overview_pose.rms_px
        else:
            T_est, T_true, pose_rms = wrist_pose.T_tcp_camera, t.T_tcp_camera, wrist_pose.rms_px
        assert T_true is not None  # the truth of a fixed camera has its base pose, of an arm camera its TCP pose
        position, angle = pose_error(T_est, T_true)
        focal = (np.diag(intrinsics.K)[:2] / np.diag(t.K)[:2] - 1.0) * 100.0
        principal = intrinsics.K[:2, 2] - t.K[:2, 2]
        figures[name] = {
            "reprojection_px": intrinsics.rms_px,
            "pose_reprojection_px": pose_rms,
            "views": len(intrinsics.views_used),
            "views_dropped": len(intrinsics.views_dropped),
            "truth_position_error_mm": position * 1000,
            "truth_angle_error_deg": float(np.degrees(angle)),
            "truth_focal_error_pct": focal.tolist(),
            "truth_principal_error_px": principal.tolist(),
        }
        extra = {k: v for k, v in figures[name].items() if not k.startswith("truth")}
        if pose_kind == "fixed":
            cameras[name] = CameraCalibration(
                intrinsics.K, intrinsics.dist, intrinsics.image_size, T_base_camera=T_est,
                reprojection_error_px=intrinsics.rms_px, extra=extra,
            )  # fmt: skip
        else:
            extra["unreachable_viewpoints"] = unreachable
            cameras[name] = CameraCalibration(
                intrinsics.K, intrinsics.dist, intrinsics.image_size, T_tcp_camera=T_est,
                reprojection_error_px=intrinsics.rms_px, extra=extra,
            )  # fmt: skip
    calibration = CellCalibration(cameras, source=source, cell=made_for)
    settings = {
        "cell": made_for,
        "profile": profile.to_dict(),
        "rig": dataclasses.asdict(rig_config),
        "calibration": dataclasses.asdict(calibration_config),
    }
    return CellCalibrationRun(calibration, figures, settings, overview, wrist)
