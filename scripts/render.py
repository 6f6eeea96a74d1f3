"""Render a puzzle box in the twin: a PNG from a named camera and, with --video, an MP4 of a scripted
sweep that opens each unlocked component in turn; or, with --views and/or --turntable, a gallery of the box
alone with its lock features (twin.gallery).

    python scripts/render.py SPEC --out DIR [--camera NAME] [--video] [--seed S]
    python scripts/render.py SPEC --out DIR [--views] [--turntable [--frames N] [--fps F]]
    python scripts/render.py replay LOG.npz --out FILE.mp4 [--period S] [--fps F]

``replay`` draws a twin trial's rollout video from its state log (``trial.py --state-log``: ``DIR/states/<run>.npz``)
without its physics: the frames the trial would have drawn live with ``--video`` (at ``--period 0.1`` simulated
seconds apart, the default), or as many as another ``--period`` asks, played at ``--fps``.

Writes ``DIR/<camera>.png`` (and ``DIR/sweep.mp4``, ``DIR/sweep.json``); or ``DIR/top.png``,
``DIR/three-quarter.png``, ``DIR/component-<name>.png``, the annotated ``DIR/top-annotated.png`` and
``DIR/three-quarter-annotated.png`` (parts labelled, the goal marked, lock features in their locker's colour, a
legend of the lock rules below) (--views) and ``DIR/turntable.mp4`` (--turntable); always ``DIR/render.config.json``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import imageio.v3 as iio

from puzzlebox.lab.cli import OneLineParser, fail, one_line, run_script, versions, write_json
from puzzlebox.lab.errors import RunStoreError
from puzzlebox.lab.inputs import MAX_IMAGE_SIDE, MAX_VIEWS, check_count, check_seed
from puzzlebox.lab.out_lock import OutputLock
from puzzlebox.models import ModelsError, SpecError, load_spec
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.rendering import RenderConfig, Renderer
from puzzlebox.twin.scripted_sweep import sweep_open
from puzzlebox.twin.session import TwinSession
from puzzlebox.twin.video import VideoWriter


def replay(argv: list[str]) -> int:
    """``render.py replay LOG.npz --out FILE.mp4 [--period S] [--fps F]`` (module docstring)."""
    from puzzlebox.lab.replay_video import replay_video
    from puzzlebox.twin.rollout_video import RolloutConfig, VideoError

    parser = OneLineParser(prog="render.py replay", description="Draw a twin trial's rollout video from its state log.")
    parser.add_argument("log", help="a state log (trial.py --state-log: DIR/states/<run>.npz)")
    parser.add_argument("--out", required=True, help="the MP4 file to write")
    parser.add_argument("--period", type=float, default=0.1, help="simulated time between frames [s] (default 0.1)")
    parser.add_argument("--fps", type=float, default=30.0, help="playback rate [frames/s] (default 30)")
    args = parser.parse_args(argv)
    if not 0.01 <= args.period <= 60.0 or not 0 < args.fps <= 1000:
        fail(f"--period must be in [0.01, 60] s and --fps in (0, 1000], got {args.period} and {args.fps}")
    out = Path(args.out)
    if out.suffix.lower() != ".mp4":
        fail(f"--out {out}: the video is an MP4 file (.mp4)")
    if not Path(args.log).is_file():
        fail(f"{args.log}: no such state log")
    try:
        frames = replay_video(args.log, out, RolloutConfig(period=args.period, fps=args.fps))
    except (ValueError, OSError, VideoError, TwinError, SpecError) as err:
        fail(f"{args.log}: {one_line(err)}")
    print(f"{frames} frames -> {out}")
    return 0


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["replay"]:
        return replay(argv[1:])
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("spec", help="puzzle spec file")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--camera", help="camera name (default: overview)")
    parser.add_argument("--video", action="store_true", help="also record the scripted sweep as an MP4")
    parser.add_argument("--views", action="store_true", help="the box's standard views: top, three-quarter, close-ups")
    parser.add_argument("--turntable", action="store_true", help="a camera circling the box once, as turntable.mp4")
    parser.add_argument("--frames", type=int, default=72, help="turntable frames (default: 72, 5 deg apart)")
    parser.add_argument("--fps", type=float, default=24.0, help="turntable playback rate [frames/s] (default: 24)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--shadows", action="store_true", help="render shadows (3-4x slower on the CPU)")
    args = parser.parse_args(argv)
    gallery = args.views or args.turntable
    if gallery and (args.video or args.camera is not None):
        fail("--camera and --video render the twin's scene; run them apart from --views/--turntable")
    if args.turntable and (args.frames < 1 or not 0 < args.fps <= 1000):
        fail(f"--frames must be >= 1 and --fps in (0, 1000], got {args.frames} and {args.fps}")
    if args.turntable and (args.width % 2 or args.height % 2):
        fail(f"--turntable needs an even --width and --height (H.264 yuv420p), got {args.width}x{args.height}")
    args.camera = args.camera or "overview"
    try:
        for flag, value, bound in (("--width", args.width, MAX_IMAGE_SIDE), ("--height", args.height, MAX_IMAGE_SIDE),
                                   ("--frames", args.frames, MAX_VIEWS)):  # fmt: skip
            check_count(value, flag, bound)
        check_seed(args.seed)
        config = RenderConfig(width=args.width, height=args.height, shadows=args.shadows)
        spec = load_spec(args.spec)
    except (ValueError, SpecError) as err:
        fail(one_line(err))
    if gallery and spec.box is None:
        fail(f"spec {spec.name!r} is a disassembly scene (no box): --views and --turntable render puzzle boxes")
    out = Path(args.out)
    try:  # owned before any work: a file there, a read-only place or another writer is refused now
        lock = OutputLock(out)
        write_json(out / "render.config.json", {"command": "render", **vars(args), "versions": versions()})
    except RunStoreError as err:
        fail(one_line(err))
    except OSError as err:
        fail(f"--out {out}: cannot write there ({err.strerror or err})")
    if gallery:
        return _gallery(spec, out, config, args, lock)
    try:
        with TwinSession(spec, seed=args.seed) as session, Renderer(session.model, config) as renderer:
            png = out / f"{args.camera.replace('/', '_')}.png"
            iio.imwrite(png, renderer.render(session.data, args.camera))
            print(f"wrote {png}")
            if args.video:
                video = out / "sweep.mp4"
                with VideoWriter(video, fps=15) as writer:
                    writer.append(renderer.render(session.data, args.camera))
                    steps = sweep_open(session, lambda s: writer.append(renderer.render(s.data, args.camera)))
                (out / "sweep.json").write_text(json.dumps([step.__dict__ for step in steps], indent=2))
                opened = [s.component for s in steps if s.opened]
                print(f"wrote {video}: opened {opened} in {session.time:.1f} s simulated")
    except (ModelsError, TwinError) as err:
        fail(str(err))
    lock.release()
    return 0


def _gallery(spec, out: Path, config: RenderConfig, args: argparse.Namespace, lock: OutputLock) -> int:
    from puzzlebox.twin.gallery import Gallery

    try:
        with Gallery(spec, config) as gallery:
            if args.views:
                paths = gallery.write_views(out) + gallery.write_annotated(out)
                print(f"wrote {len(paths)} views to {out}: {', '.join(p.name for p in paths)}")
            if args.turntable:
                video = gallery.write_turntable(out / "turntable.mp4", frames=args.frames, fps=args.fps)
                print(f"wrote {video}: {args.frames} frames at {args.fps:g} frames/s")
    except (ModelsError, TwinError) as err:
        fail(one_line(err))
    lock.release()
    return 0


if __name__ == "__main__":
    run_script(main)
