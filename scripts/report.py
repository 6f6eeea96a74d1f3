"""Turn a trial or sweep directory into one self-contained HTML report.

    python scripts/report.py DIR [--out FILE.html] [--measure-load]

``DIR`` is the ``--out`` of ``scripts/trial.py`` (``results.json``, ``config.json``, ``runs/*.json``, videos
``*.mp4`` with ``--video``) or of ``scripts/sweep.py`` (the same, plus the per-cell summaries in
``results.json``). The page (default ``DIR/report.html``, written atomically) holds a summary table (for a
sweep, one row per cell with its settings), figures (actions per run, success per cell, peak wrist force per
action), the videos and every run with a compact timeline: one block per action, as wide as its simulated time
(twin runs; symbolic runs: equal blocks), coloured by the sensed outcome, marked where the sensed outcome
disagrees with the simulator's truth. CSS, figures (inline SVG) and script are in the page, nothing is fetched
from the network; videos are linked relative to the page, not inlined, so the page stays small. A twin
directory's page opens with the annotated top view of each box it ran (parts named, the goal ringed, lock features
in their locker's colour), rendered once into ``DIR/gallery/<spec>/top-annotated.png`` and linked.

``--measure-load`` opens the written page in headless Chromium (if installed) and adds its load time (ms from
navigation to the ``load`` event) to the output line. A DIR that is not a trial or sweep directory is refused
in one line (exit 2).
"""

from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from puzzlebox.lab.cli import OneLineParser, fail, one_line, run_script
from puzzlebox.lab.report_gallery import write_top_views
from puzzlebox.lab.report_html import ReportError, build_page, load_results_dir
from puzzlebox.models.atomic import write_text_atomically


def measure_load(page: Path, timeout_s: float = 60.0) -> tuple[float, float] | None:
    """(the page's load time in headless Chromium [ms], the browser process's whole wall time [s]), or None
    when Chromium is not installed or does not answer."""
    browser = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if browser is None:
        return None
    command = [browser, "--headless=new", "--no-sandbox", "--disable-gpu", "--dump-dom", page.resolve().as_uri()]
    start = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=timeout_s, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return None
    wall = time.perf_counter() - start
    found = re.search(r'data-load-ms="(\d+)"', done.stdout)
    return (float(found.group(1)), wall) if found else None


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dir", help="a trial or sweep directory (--out of trial.py or sweep.py)")
    parser.add_argument("--out", default=None, metavar="FILE.html", help="the page (default: DIR/report.html)")
    parser.add_argument("--measure-load", action="store_true", help="time the page's load in headless Chromium")
    args = parser.parse_args(argv)
    directory = Path(args.dir)
    page = Path(args.out) if args.out else directory / "report.html"
    if page.is_dir():
        fail(f"--out {page} is a directory: give a file name (FILE.html)")
    try:
        data = load_results_dir(directory)
        text = build_page(data, page, write_top_views(data, lambda why: print(f"note: {why}", file=sys.stderr)))
        write_text_atomically(page, text)
    except ReportError as err:
        fail(str(err))
    except OSError as err:
        fail(f"cannot write {page}: {one_line(err)}")
    size = page.stat().st_size
    line = (
        f"{data.kind} report: {len(data.runs)} run(s), {len(data.cells)} cell(s), {len(data.videos)} video(s) "
        f"-> {page} ({size} bytes, {size / 1e6:.2f} MB)"
    )
    if args.measure_load:
        measured = measure_load(page)
        line += (
            "; load time: chromium not available"
            if measured is None
            else f"; load {measured[0]:.0f} ms in headless Chromium ({measured[1]:.1f} s with browser start)"
        )
    print(line)
    return 0


if __name__ == "__main__":
    run_script(main)
