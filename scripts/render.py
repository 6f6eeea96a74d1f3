"""Render a puzzle box in the twin: a PNG from a named camera and, with --video, an MP4 of a scripted
sweep that opens each unlocked component in turn.

    python scripts/render.py SPEC --out DIR [--camera NAME] [--video] [--seed S]

Writes ``DIR/<camera>.png`` (and ``DIR/sweep.mp4``, ``DIR/sweep.json``) with ``DIR/render.config.json``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import imageio.v3 as iio
from _cli import fail, versions, write_json

from models import ModelsError, SpecError, load_spec
from twin.errors import TwinError
from twin.rendering import RenderConfig, Renderer
from twin.scripted_sweep import sweep_open
from twin.session import TwinSession
from twin.video import VideoWriter


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("spec", help="puzzle spec file")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--camera", default="overview", help="camera name (default: overview)")
    parser.add_argument("--video", action="store_true", help="also record the scripted sweep as an MP4")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=480)
    parser.add_argument("--shadows", action="store_true", help="render shadows (3-4x slower on the CPU)")
    args = parser.parse_args(argv)
    try:
        spec = load_spec(args.spec)
    except SpecError as err:
        fail(str(err))
    out = Path(args.out)
    write_json(out / "render.config.json", {"command": "render", **vars(args), "versions": versions()})
    config = RenderConfig(width=args.width, height=args.height, shadows=args.shadows)
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
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
