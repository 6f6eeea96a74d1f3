r"""Run seeded trials of an agent on puzzle specs and write ``DIR/results.json``.

    python scripts/trial.py --specs FILE... [--memory MEM.sqlite] --sim {symbolic,twin} --runs K --seed S \
                            --max-actions M --out DIR [--agent NAME|package.module:Class] [--max-lockers K] \
                            [--video] [--state-log] [--record FILE.rrd] [--reality ideal|realistic|harsh|FILE.json] \
                            [--calibration FILE.json] [--wrong-kind] [--locks contact|latch] \
                            [--workers K | --ray auto|ADDRESS] [--resume | --force] \
                            [--robot twin|xarm --ip ADDRESS --cell FILE]

``--sim twin`` runs each trial end to end in the MuJoCo twin (ArUco perception, the agent, mink primitives, F/T
outcomes); ``--robot xarm`` runs one on a real xArm-7 through the same pipeline. Run ``r`` uses seed ``S + r``. Each
record is written to ``DIR/runs/`` as its run ends: a crash or Ctrl-C keeps every finished run, ``--resume``
continues. Every flag: docs/command-line.md; the Python API: :func:`puzzlebox.lab.run_trial`.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from puzzlebox.lab.agent_class import check_agent
from puzzlebox.lab.cli import OneLineParser, fail, one_line, run_script
from puzzlebox.lab.errors import AgentClassError, ArmTrialFailed, ArmTrialRefused, RunStoreError, TrialConfigError
from puzzlebox.lab.run_store import RunStore
from puzzlebox.lab.runner import RunnerError, make_executor
from puzzlebox.lab.spec_files import check_belief_sizes, check_box_reach, check_distinct_specs
from puzzlebox.lab.trial_batch import (
    InputError,
    TrialBatch,
    check_batch_numbers,
    run_batch,
    summary_lines,
)
from puzzlebox.learning import AGENT_NAMES, LearningError, make_agent
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models import SpecError, load_spec

SIMS, ROBOTS = ("symbolic", "twin"), ("twin", "xarm")
# where and how runs execute, not their records: left out of the resumable configuration
NOT_RESULTS = ("out", "resume", "force", "workers", "ray", "robot", "ip", "cell", "record")


def _arm_main(args, arm: Callable[[str, Any], Any] | None) -> int:
    """``--robot xarm``: one trial on the real arm, every twin-only flag refused first."""
    from puzzlebox.lab.arm_trial_command import ArmTrialRequest, reach_arm, run_arm_trial  # (the arm's stack)

    if args.ip is None or args.cell is None:
        fail("--robot xarm needs --ip ADDRESS (the arm's controller) and --cell FILE (the cell config)")
    if args.sim != "twin":
        fail("--robot xarm runs the perception and skills pipeline: give --sim twin")
    try:
        reach_arm(args.ip, args.cell, probe=arm is None)  # an address where no arm answers is refused first
        twin_only = [flag for flag, given in (
            ("--video", args.video), ("--record", args.record is not None), ("--wrong-kind", args.wrong_kind),
            ("--state-log", args.state_log),
            ("--reality", args.reality != "ideal"), ("--workers", args.workers is not None),
            ("--ray", args.ray is not None), ("--resume", args.resume),
        ) if given]  # fmt: skip
        if twin_only:
            fail(f"--robot xarm runs one trial on the arm: {', '.join(twin_only)} are for twin trials")
        if len(args.specs) != 1:
            fail(f"--robot xarm tries the one box on the table: give one spec, got {len(args.specs)}")
        if args.runs != 1:
            fail(f"--robot xarm runs one trial per command: give --runs 1, got {args.runs}")
        if args.calibration is None:
            fail("--robot xarm needs --calibration FILE: the cell's camera calibration (scripts/calibrate.py)")
        request = ArmTrialRequest(args.ip, args.cell, args.calibration, args.specs[0], args.agent, args.memory,
                                  args.checkpoint, args.seed, args.max_actions, args.max_lockers, Path(args.out),
                                  args.force)  # fmt: skip
        record, out = run_arm_trial(request, arm)
    except ArmTrialRefused as err:
        fail(f"--robot xarm: {err}")
    except ArmTrialFailed as err:
        fail(f"--robot xarm: {err}", code=1)
    except RunStoreError as err:
        fail(one_line(err))
    if record["stopped"]:
        print(f"error: the arm was stopped after {record['num_actions']} action(s): {one_line(record['stopped'])}; "
              f"kept in {out}", file=sys.stderr)  # fmt: skip
        return 1
    print(f"{args.agent} on the arm at {args.ip}: {'solved' if record['solved'] else 'not solved'} (as perceived) "
          f"in {record['num_actions']} action(s), {record['wall_time_s']:.0f} s -> {out / 'results.json'}")  # fmt: skip
    if record["ended"]:
        print(f"unsolved: {record['ended']}")
    return 0


def _check_twin_flags(args) -> None:
    if args.video and args.sim != "twin":
        fail("--video needs --sim twin")
    if args.state_log and args.sim != "twin":
        fail("--state-log needs --sim twin")
    if args.record is not None:
        if args.sim != "twin":
            fail("--record needs --sim twin")
        if not args.record.endswith(".rrd"):
            fail(f"--record {args.record}: a Rerun recording file ends in .rrd")
        folder = Path(args.record).resolve().parent
        if not folder.is_dir():
            fail(f"--record {args.record}: directory {folder} does not exist")
        try:  # a place that cannot be written failed every run at its end, after the work, and kept an --out
            tempfile.TemporaryFile(dir=folder).close()
        except OSError as err:
            fail(f"--record {args.record}: directory {folder} cannot be written ({err.strerror})")
        try:
            import rerun  # noqa: F401  (the viz extra: refused here in one line, not in every run)
        except ImportError:
            fail("--record needs the rerun-sdk package (the viz extra): pip install -e .[viz]")
    if args.sim != "twin" and (args.reality != "ideal" or args.calibration):
        fail("--reality and --calibration need --sim twin")
    if args.sim != "twin" and args.wrong_kind:
        fail("--wrong-kind needs --sim twin (the symbolic protocols' faults: experiment.py noise)")


def main(argv: list[str] | None = None, *, arm: Callable[[str, Any], Any] | None = None) -> int:
    """The command line (see the module docstring); ``arm(ip, cell)`` connects ``--robot xarm`` (default
    ``real.XArmRobot``: tests pass one over a test double of the SDK)."""
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--specs", nargs="+", required=True, help="puzzle spec files")
    parser.add_argument("--memory", default=None, help="memory file from train.py (memory agent; read only)")
    parser.add_argument("--sim", choices=SIMS, required=True)
    parser.add_argument("--runs", type=int, required=True, help="runs per spec")
    parser.add_argument("--seed", type=int, required=True, help="seed of run 0; run r uses seed + r")
    parser.add_argument("--max-actions", type=int, required=True, help="action budget per run")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--agent", default="memory", help=f"{', '.join(AGENT_NAMES)} or package.module:Class")
    parser.add_argument("--checkpoint", default=None, help="checkpoint from train.py (deep agents)")
    parser.add_argument("--max-lockers", type=int, metavar="K", help="memory/dual: up to K lockers a part")
    parser.add_argument("--video", action="store_true", help="record rollout videos (twin only)")
    parser.add_argument("--state-log", action="store_true",
                        help="twin: each run's state at every control tick, DIR/states/<run>.npz")  # fmt: skip
    parser.add_argument("--record", default=None, metavar="FILE.rrd", help="a Rerun recording of each twin run")
    parser.add_argument("--wrong-kind", action="store_true", help="twin: tell the pipeline one kind wrong per run")
    parser.add_argument("--reality", default="ideal", help="twin reality profile: ideal, realistic, harsh or a file")
    parser.add_argument("--locks", choices=("contact", "latch"), default="contact", help="twin: mechanisms or latches")
    parser.add_argument("--calibration", default=None, help="camera calibration from calibrate.py (twin, xarm)")
    parser.add_argument("--workers", type=int, default=None, help="worker processes (default: a core each for twin)")
    parser.add_argument("--ray", default=None, metavar="auto|ADDRESS", help="run on Ray: auto = a local cluster")
    parser.add_argument("--robot", choices=ROBOTS, default="twin", help="twin (default) or xarm: a real xArm-7 at --ip")
    parser.add_argument("--ip", default=None, metavar="ADDRESS", help="the xArm controller's address (--robot xarm)")
    parser.add_argument("--cell", default=None, metavar="FILE", help="cell config (--robot xarm)")
    parser.add_argument("--resume", action="store_true", help="continue the runs already in --out (same arguments)")
    parser.add_argument("--force", action="store_true", help="delete the results already in --out first")
    args = parser.parse_args(argv)
    if args.robot == "xarm":
        return _arm_main(args, arm)
    if args.ip is not None or args.cell is not None:
        fail("--ip and --cell go with --robot xarm")
    try:  # run r uses seed S + r: the last seed too is a seed; sizes bounded (a typo is one line, not MemoryError)
        check_batch_numbers(len(args.specs), args.runs, args.seed, args.max_actions, args.workers)
    except InputError as err:
        fail(str(err))
    if args.workers is not None and (args.workers < 1 or args.ray is not None):
        fail("--workers must be >= 1, and goes without --ray" if args.workers < 1 else "give --workers or --ray")
    if ":" in args.agent and os.getcwd() not in sys.path:  # as `python -m` would: an agent module beside the user
        sys.path.insert(0, os.getcwd())  # imports (pool workers inherit the path)
    try:
        own_agent = check_agent(args.agent, args.memory, args.checkpoint, args.max_lockers)
    except (AgentClassError, TrialConfigError) as err:
        fail(one_line(err))
    _check_twin_flags(args)
    try:
        specs = [load_spec(path) for path in args.specs]
        check_distinct_specs(specs, args.specs)
        check_belief_sizes(specs, args.specs, args.max_lockers)
    except (SpecError, InputError) as err:
        fail(str(err))
    reality = calibration = None
    if args.sim == "twin":
        from puzzlebox.lab.cells import CellError, load_cell  # (the twin's stack: not loaded for symbolic runs)

        try:  # a calibration belongs to one cell (its profile, cell seed and box height): the cell is taken from it
            reality, calibration = load_cell(args.reality, args.calibration, dict(zip(args.specs, specs, strict=True)))
        except CellError as err:
            fail(one_line(err))
        try:
            check_box_reach(specs, args.specs, reality.placement)
        except InputError as err:
            fail(str(err))
    try:  # what every run needs is checked once here: a bad memory or checkpoint is one line, not N errors
        memory = MemoryStore.open_existing(args.memory) if args.memory else None  # read, never written
        if not own_agent:
            make_agent(args.agent, specs[0], memory, args.checkpoint)
    except LearningError as err:
        fail(str(err))
    if memory is not None:
        memory.close()  # each run opens it where it runs

    out = Path(args.out)
    experiment = {"command": "trial", **{k: v for k, v in vars(args).items() if k not in NOT_RESULTS}}
    if args.max_lockers is None:  # the default leaves the configuration as it was before k existed (resumable)
        del experiment["max_lockers"]
    if args.locks == "latch" or args.sim != "twin":  # latches: the configuration made before mechanisms existed
        del experiment["locks"]
    if not args.state_log:  # likewise: a directory made before state logs existed resumes
        del experiment["state_log"]
    batch = TrialBatch(tuple(specs), args.runs, args.seed, args.sim, args.agent, args.max_actions, args.memory,
                       args.checkpoint, reality, calibration, args.video, args.record, args.wrong_kind,
                       args.max_lockers, args.locks, args.state_log)  # fmt: skip
    # symbolic runs last less than a hand-over; a pool is started for no more twin runs than there are
    workers = args.workers or (min(os.cpu_count() or 1, len(specs) * args.runs) if args.sim == "twin" else 1)
    try:
        executor = make_executor(workers, args.ray)
        store = RunStore(out, experiment, resume=args.resume, force=args.force)
        report, results = run_batch(batch, store, executor)
    except (RunnerError, RunStoreError) as err:
        fail(one_line(err))
    runs, planned = len(report.records), results["runs_planned"]
    if report.failures:  # each was named as it failed, above the progress bar
        key, error = next(iter(report.failures.items()))
        print(f"error: {len(report.failures)} run(s) failed (first: {key}: {error.splitlines()[0]}); {runs} kept "
              f"in {out}; --resume retries the failed ones", file=sys.stderr)  # fmt: skip
        return 1
    if report.stopped:
        print(f"stopped: {runs} of {planned} run(s) kept in {out}; continue with the same command and --resume",
              file=sys.stderr)  # fmt: skip
        return 130
    print("\n".join(summary_lines(results, batch, out)))
    return 0


if __name__ == "__main__":
    run_script(main)
