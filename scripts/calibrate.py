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
import json
import os
import tempfile
import time
from pathlib import Path

from puzzlebox.lab.cli import OneLineParser, fail, one_line, run_script, versions, write_json
from puzzlebox.lab.errors import RunStoreError
from puzzlebox.lab.inputs import MAX_SEED, MAX_VIEWS
from puzzlebox.lab.out_lock import OutputLock


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = OneLineParser(description=(__doc__ or "").partition("\n")[0])  # (no docstring under -OO)
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
    for flag, seed in (("--cell-seed", args.cell_seed), ("--seed", args.seed)):
        if seed is not None and not 0 <= seed <= MAX_SEED:
            fail(f"{flag} must be >= 0 and <= {MAX_SEED}, got {seed}")
    for flag, views in (("--overview-views", args.overview_views), ("--wrist-views", args.wrist_views)):
        if views > MAX_VIEWS:
            fail(f"{flag} must be at most {MAX_VIEWS}, got {views}")
    if args.out.exists() and args.out.is_dir():
        fail(f"--out {args.out} is a directory; give a file name")
    return args


def load_inputs(args: argparse.Namespace):
    from puzzlebox.models import ModelsError, load_spec
    from puzzlebox.models.generator import paper_family
    from puzzlebox.twin.errors import TwinError
    from puzzlebox.twin.reality import load_profile

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


def _kept_elsewhere(calibration) -> str:
    """Where the calibration made is kept when ``--out`` cannot be written: a file in the temporary folder, or, if
    that fails too, the calibration itself printed on stdout (JSON)."""
    kept = Path(tempfile.gettempdir()) / f"puzzlebox-calibration-{os.getpid()}-{int(time.time())}.json"
    try:
        calibration.save(kept)
    except OSError:
        print(json.dumps(calibration.to_dict(), indent=1))
        return "the calibration is printed on stdout (JSON): save it as the file"
    return f"the calibration is kept in {kept}: move it where it belongs"


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    spec, profile = load_inputs(args)
    start = time.perf_counter()
    try:  # before the work: a file that cannot be written there, or that another process writes, is refused now
        lock = OutputLock(args.out, directory=False)
    except RunStoreError as err:
        fail(one_line(err))

    from puzzlebox.lab.calibration_run import CellCalibrationError, calibrate_cell

    try:
        run = calibrate_cell(spec, profile, args.seed, args.overview_views, args.wrist_views)
    except CellCalibrationError as err:
        fail(str(err), code=err.exit_code)
    overview, figures = run.overview, run.figures
    settings = {
        "command": "calibrate",
        **{k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()},
        **run.settings,
        "versions": versions(),
    }
    try:
        path = run.calibration.save(args.out)
        write_json(path.with_name(path.name + ".config.json"), settings)
    except OSError as err:  # a full disk after the whole procedure: the calibration is not lost with it
        fail(f"cannot write {args.out} ({err.strerror or err}); {_kept_elsewhere(run.calibration)}", code=1)
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
    lock.release()
    return 0


if __name__ == "__main__":
    run_script(main)
