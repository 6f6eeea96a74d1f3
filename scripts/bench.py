"""Speed figures, measured in one run on this machine (ratios matter more than absolutes here).

    python scripts/bench.py --out FILE [--quick] [--scale-trials T] [--only manipulation|soak|outputs|locks]
                            [--trials T]

- agent decision latency: median and 90th percentile milliseconds per dual-controller decision on
  random lock graphs of N = 5, 10, 16, 32 components (beliefs as they evolve during real episodes;
  boxes beyond the robot's reach are generated for the symbolic simulator, as ``generate.py --anywhere``);
- belief over sets of lockers: median and 90th percentile milliseconds per decision and belief update
  (``choose`` + ``record``) of the dual agent on 8-component two-locker boxes, with ``max_lockers`` 1 (the
  paper's belief) and 2 (sets of up to two lockers), one after the other in this run;
- symbolic environment: steps per second of ``PuzzleEnv.step`` with random actions;
- twin: scene build + compile time; bare ``mj_step`` rate on the compiled paper scene (one step per
  call, as a Python user steps, and ``nstep`` in C) beside the twin's rate on the same model, with
  their ratio; overview render time per 640x480 frame without and with shadows;
- twin trial: simulated/wall time of one oracle twin trial on a paper test box (ideal cell, no video), the
  first in the process (renderer, scene and IK model built) and a second one (kept from the first);
- twin trial outputs (``--only outputs``: these alone): wall time of the same oracle trial plain, with ``--video``,
  with ``--record`` and with ``--state-log``, in turn (medians of 3), and the ratios to plain (and the state log's
  size); the rollout views' box visibility over every frame of 5 trials;
- lock check (``--only locks``: these alone): ``generate.py check-locks``'s band check on the 12 paper boxes, push
  after push against every push of a box as one ``mujoco.batch`` batch: times, ratio, whether identical;
- manipulation (``puzzlebox/lab/manipulation_speed.py``): ``BoxManipulation-v0`` control steps per second (state
  observations) beside bare ``mj_step`` replaying the same run (the same simulated time), with their ratio, and
  ``make_vec`` async with 2 workers against 1 (``--only manipulation``: these figures alone);
- scale (``puzzlebox/lab/bench_scale.py``): each executor's overhead per no-op task, and twin trials per hour of
  the same T oracle trials on one worker, on a local pool (one worker per core) and on a local Ray cluster,
  one after the other in this run, with each one's speed-up over one worker: start-up included, and warm
  (after one trial per worker);
- soak (``puzzlebox/lab/bench_soak.py``, ``--only soak [--trials T]``, alone): T twin trials (default 200) of varied
  boxes under ``realistic`` in this process, the resident memory after each, and whether the one after the last is
  within 50 MB of the one after trial 20 (the file is rewritten after every trial: a stopped soak keeps its curve).
Single-threaded numpy is enforced for the agent figures (one core).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one core, before numpy loads

import argparse  # noqa: E402
from pathlib import Path  # noqa: E402

from puzzlebox.lab.bench_figures import (  # noqa: E402
    bench_header,
    default_scale_trials,
    lock_check_figures,
    manipulation_figures,
    measured_figures,
    output_figures,
    scale_figures,
)
from puzzlebox.lab.bench_soak import SoakConfig, SoakPoint, soak_points, soak_verdict  # noqa: E402
from puzzlebox.lab.cli import OneLineParser, fail, one_line, run_script, write_json  # noqa: E402
from puzzlebox.lab.errors import RunStoreError  # noqa: E402
from puzzlebox.lab.out_lock import OutputLock  # noqa: E402

MAX_SCALE_TRIALS = 10_000


def soak(out: Path, results: dict, config: SoakConfig) -> Path:
    """Run the soak, printing a line and rewriting ``out`` after every trial; then the verdict."""
    points: list[SoakPoint] = []

    def keep(point: SoakPoint) -> None:
        points.append(point)
        print(f"soak trial {point.trial}: {point.spec} seed {point.seed} solved={point.solved} "
              f"{point.wall_s:.1f} s, resident {point.rss_mb:.1f} MB", flush=True)  # fmt: skip
        write_json(out, {**results, "soak": soak_verdict(points, config)})

    soak_points(config, keep)
    verdict = soak_verdict(points, config)
    if verdict["holds"] is not None:
        print(f"soak: resident {verdict['reference_rss_mb']:.1f} MB after trial {config.reference}, "
              f"{verdict['last_rss_mb']:.1f} MB after trial {len(points)} ({verdict['growth_mb']:+.1f} MB; bound "
              f"{config.bound_mb:g} MB: {'holds' if verdict['holds'] else 'DOES NOT HOLD'})")  # fmt: skip
    return write_json(out, {**results, "soak": verdict})


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", required=True, help="output JSON file")
    parser.add_argument("--quick", action="store_true", help="fewer episodes (CI smoke run)")
    parser.add_argument(
        "--scale-trials", type=int, default=None,
        help="twin trials per executor for the scale figures (default 40; --quick 4; 0 skips them)",
    )  # fmt: skip
    parser.add_argument("--only", choices=("manipulation", "soak", "outputs", "locks"),
                        help="measure these figures alone")  # fmt: skip
    parser.add_argument("--trials", type=int, default=None, help="twin trials of the soak (--only soak; default 200)")
    args = parser.parse_args(argv)
    if args.scale_trials is not None and not 0 <= args.scale_trials <= MAX_SCALE_TRIALS:
        fail(f"--scale-trials must be >= 0 and <= {MAX_SCALE_TRIALS}, got {args.scale_trials}")
    if args.trials is not None and (args.only != "soak" or not 1 <= args.trials <= MAX_SCALE_TRIALS):
        fail(f"--trials goes with --only soak and must be >= 1 and <= {MAX_SCALE_TRIALS}, got {args.trials}")
    try:  # owned before the work (minutes): a directory there, a read-only place or another writer is refused now
        lock = OutputLock(Path(args.out), directory=False)
    except RunStoreError as err:
        fail(one_line(err))
    results = bench_header()
    if args.only == "soak":
        path = soak(Path(args.out), results, SoakConfig() if args.trials is None else SoakConfig(trials=args.trials))
        print(f"-> {path}")
        lock.release()
        return 0
    only = {"manipulation": manipulation_figures, "outputs": output_figures, "locks": lock_check_figures}.get(
        args.only or "", measured_figures
    )
    for figure in only(args.quick):
        figure.keep(results)
        for line in figure.lines:
            print(line)
    path = write_json(Path(args.out), results)  # what is measured so far is kept if the scale part fails
    trials = args.scale_trials if args.scale_trials is not None else default_scale_trials(args.quick)
    trials = 0 if args.only else trials
    if trials:
        for figure in scale_figures(trials, args.quick):
            figure.keep(results)
            for line in figure.lines:
                print(line)
        path = write_json(Path(args.out), results)
    print(f"-> {path}")
    lock.release()
    return 0


if __name__ == "__main__":
    run_script(main)
