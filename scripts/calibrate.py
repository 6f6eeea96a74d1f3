"""Calibrate the cell's cameras from rendered images of a ChArUco board and write the calibration file.

    python scripts/calibrate.py --out FILE.json [--reality PROFILE] [--cell-seed S] [--spec SPEC]
                                [--seed S] [--overview-views N] [--wrist-views N]

The procedure a real cell runs (``twin.calibration_rig`` moves the board, ``skills.calibration`` does
the math, the skills' IK moves the arm):

1. the board held in front of the overview camera at varied distances and tilts: its intrinsics;
2. the board laid flat at a known place: the overview camera's pose in the base frame;
3. the board left there, the arm moving the wrist camera through varied viewpoints, recording the TCP
   pose the arm reports at each capture: the wrist camera's intrinsics and its hand-eye pose.

It writes a :class:`models.calibration.CellCalibration` atomically, recording the cell it was made for
(reality profile, ``cell_seed``, box height: ``scripts/trial.py --calibration`` refuses it for another
cell), writes the resolved settings (arguments, rig and calibration configs, spec, box height, profile)
beside it in ``FILE.config.json``, and prints one line per camera: the reprojection error and, because
this is the twin and the truth is known, the pose and focal-length errors against the truth.

Exit status: 0 written; 2 a mistake on the command line (bad argument, spec or profile); 1 the
calibration failed (too few usable views, the arm could not reach, the rig found no pose), one line on
stderr.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np
from _cli import fail, versions, write_json


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path, help="calibration file to write (JSON)")
    parser.add_argument("--reality", default="ideal", help="reality profile of the twin: a preset name or JSON file")
    parser.add_argument("--cell-seed", type=int, default=None, help="seed of the cell's fixed imperfections")
    parser.add_argument("--spec", type=Path, default=None, help="puzzle spec of the cell (default: paper test 0)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the session and of the procedure's poses")
    parser.add_argument("--overview-views", type=int, default=20, help="board views for the overview intrinsics")
    parser.add_argument("--wrist-views", type=int, default=16, help="arm viewpoints for the wrist camera")
    args = parser.parse_args(argv)
    if args.overview_views < 6:
        fail(f"--overview-views must be at least 6, got {args.overview_views}")
    if args.wrist_views < 6:
        fail(f"--wrist-views must be at least 6, got {args.wrist_views}")
    if args.cell_seed is not None and args.cell_seed < 0:
        fail(f"--cell-seed must be >= 0, got {args.cell_seed}")
    if args.out.exists() and args.out.is_dir():
        fail(f"--out {args.out} is a directory; give a file name")
    return args


def one_line(err: Exception) -> str:
    return " ".join(line.strip() for line in str(err).splitlines())


def load_inputs(args: argparse.Namespace):
    from models import ModelsError, load_spec
    from models.generator import paper_family
    from twin.errors import TwinError
    from twin.reality import load_profile

    try:
        spec = load_spec(args.spec) if args.spec is not None else paper_family("test", seed=0)[0]
    except (ModelsError, OSError) as err:
        fail(f"cannot use spec {args.spec}: {one_line(err)}")
    try:
        profile = load_profile(args.reality)
    except TwinError as err:
        fail(f"--reality: {one_line(err)}")
    if args.cell_seed is not None:
        profile = dataclasses.replace(profile, cell_seed=args.cell_seed)
    return spec, profile


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    spec, profile = load_inputs(args)
    start = time.perf_counter()

    from models import ModelsError
    from models.calibration import CameraCalibration, CellCalibration
    from skills.calibration import (
        CalibrationConfig,
        calibrate_intrinsics,
        detect_board,
        fixed_camera_pose,
        hand_eye,
        pose_error,
    )
    from skills.errors import IKFailure, SkillError
    from skills.kinematics import ArmKinematics
    from skills.primitives import Toggler
    from twin.calibration_rig import CalibrationCell, RigConfig, RigError
    from twin.errors import TwinError

    rng = np.random.default_rng(args.seed)
    rig_config, calibration_config = RigConfig(), CalibrationConfig()
    try:
        cell = CalibrationCell(spec, seed=args.seed, reality=profile, config=rig_config)
    except (ModelsError, TwinError) as err:
        fail(f"cannot build the cell for spec {spec.name} under profile {profile.name!r}: {one_line(err)}")
    with cell:
        robot = cell.robot
        overview, wrist = cell.overview_camera, cell.wrist_camera
        try:
            # 1. intrinsics of the overview camera: the board held in front of it
            images = []
            for T_base_board in cell.board_poses_in_front_of(overview, args.overview_views, rng):
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
            wrist_views, tcp_poses, unreachable = [], [], 0
            for T_base_tcp in cell.wrist_viewpoints(T_base_board, args.wrist_views, rng):
                try:
                    toggler.move_to(T_base_tcp, 1.5)
                except IKFailure:
                    unreachable += 1
                    continue
                robot.wait(0.3)  # still: no motion blur, the servos settled
                wrist_views.append(detect_board(cell.capture(wrist).rgb, calibration_config))
                tcp_poses.append(robot.tcp_pose_in_base())
            toggler.go_rest()
            wrist_intrinsics = calibrate_intrinsics(wrist_views, calibration_config)
            wrist_pose = hand_eye(wrist_views, tcp_poses, wrist_intrinsics.K, wrist_intrinsics.dist, calibration_config)
        except (SkillError, RigError) as err:
            fail(f"calibration failed: {one_line(err)}", code=1)

        truth = {name: cell.camera_truth(name) for name in (overview, wrist)}
        made_for = {
            "profile": cell.session.reality.name,
            "cell_seed": int(cell.session.reality.cell_seed),
            "box_height": cell.box_height,
            "spec": spec.name,
        }

    source = (
        f"charuco, profile {made_for['profile']}, cell seed {made_for['cell_seed']}, "
        f"box height {made_for['box_height']:.4f} m, spec {spec.name}, seed {args.seed}"
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
    path = CellCalibration(cameras, source=source, cell=made_for).save(args.out)
    settings = {
        "command": "calibrate",
        **{k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()},
        "cell": made_for,
        "profile": profile.to_dict(),
        "rig": dataclasses.asdict(rig_config),
        "calibration": dataclasses.asdict(calibration_config),
        "versions": versions(),
    }
    write_json(path.with_name(path.name + ".config.json"), settings)
    wall = time.perf_counter() - start
    for name, f in figures.items():
        frame = "T_base_camera" if name == overview else "T_tcp_camera"
        print(
            f"{name}: reprojection {f['reprojection_px']:.3f} px ({f['views']} views), pose reprojection "
            f"{f['pose_reprojection_px']:.3f} px; vs truth: {frame} {f['truth_position_error_mm']:.2f} mm "
            f"{f['truth_angle_error_deg']:.3f} deg, focal {f['truth_focal_error_pct'][0]:+.3f}/"
            f"{f['truth_focal_error_pct'][1]:+.3f} %, principal point {f['truth_principal_error_px'][0]:+.2f}/"
            f"{f['truth_principal_error_px'][1]:+.2f} px"
        )
    print(f"wrote {path} (settings in {path.name}.config.json) in {wall:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
