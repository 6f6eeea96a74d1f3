"""Run seeded trials of an agent on puzzle specs and write ``DIR/results.json``.

    python scripts/trial.py --specs FILE... [--memory MEM.sqlite] --sim {symbolic,twin} --runs K --seed S \
                            --max-actions M --out DIR [--agent NAME] [--max-lockers K] [--video] \
                            [--reality ideal|realistic|harsh|FILE.json] [--calibration FILE.json] [--wrong-kind] \
                            [--locks contact|latch] [--workers K | --ray auto|ADDRESS] [--resume | --force] \
                            [--robot twin|xarm --ip ADDRESS --cell FILE]

``--sim twin`` runs each trial end to end in the MuJoCo twin (ArUco perception, the agent, mink
primitives, F/T outcomes) and adds a per-action ``timeline`` to each run (sensed outcome beside the
simulator's truth, F/T peak, perceived position error, simulated and wall time) and summary figures;
``--record FILE.rrd`` writes a Rerun recording of each twin run (``twin/rerun_log.py``: camera images and
the pipeline's detections, the arm's and components' poses, the TCP path, the wrist force, the agent's belief
and decisions on the ``sim_time`` timeline; the ``viz`` extra).
``--video`` writes the multi-view rollout (``twin/rollout_video.py``: overview with the pipeline's detections,
three-quarter and wrist views, captions, the wrist force; ``rollout.mp4`` and ``rollout.frames.json`` for a
single run). ``--reality`` picks the twin's reality profile (sensor noise, calibration error,
friction, jams, slips, the box placed anywhere reachable; default ``ideal``), ``--calibration`` the
cell's camera calibration made by ``scripts/calibrate.py`` (default: the nominal, datasheet
calibration, exact only under ``ideal``); a calibration made for another cell (another profile,
``cell_seed`` or box height) is refused. ``--max-lockers K`` (memory and dual agents, in either sim) lets the
agent's belief hold a component with a set of up to K lockers (default 1: the paper's one-locker belief;
2 for boxes made with ``generate.py random --multi-locker``). ``--wrong-kind`` tells the pipeline (skills
and agent) one
component's kind wrong in every run, drawn from the run's seed (the run's ``told_kinds``): the force limits
must hold when a slide is pulled along a wheel's arc. ``--locks`` (twin) picks how the box holds its lock rules:
``contact`` (default), the mechanisms in the model that block by contact (``models/lock_mechanisms.py``), or
``latch``, the rule-driven joint equalities alone (the ablation; the records made before mechanisms existed).

``--robot xarm --ip ADDRESS --cell FILE --calibration FILE --specs SPEC --runs 1`` runs one trial on a real
xArm-7 (``real.XArmRobot``, the ``real`` extra) through the same pipeline (``puzzlebox/lab/real_trial.py``): the box
on the table is the one spec given; the cell config (``models/cell_config.py``) gives the cameras, the ArUco
dictionary and marker size, the force limit and latch threshold and the rest posture (the arm goes there
first); ``--calibration`` is the cell's camera calibration. Its record holds only what was sensed (no ground
truth: ``solved`` as perceived), written to ``DIR/runs/`` and ``DIR/results.json`` after every action. It
refuses at once, in one line, an address where no arm answers (first, in about a second), a missing SDK, a bad
cell config or calibration, more than one spec or run, and the twin-only flags. A stop by the arm's force limit
or workspace ends the trial with one line on stderr and exit 1; what was done is kept in ``DIR``.

Runs are tasks of ``learning.runner``: ``--workers K`` runs them in K worker processes (default: one per
core for ``--sim twin``; in-process for ``--sim symbolic``, whose runs last less than handing them over),
``--workers 1`` in this process (with a progress bar per run's actions), ``--ray auto`` on a local Ray
cluster and ``--ray HOST:PORT`` on a running one. A run's record is the same on each (wall times aside:
``sensed_sha256`` fingerprints everything the twin's pipeline sensed), so a resume may use another.
A run that raises is named with its key and the others go on (exit 1; ``--resume`` retries it).

Run ``r`` on every spec uses seed ``S + r`` for the world (component order, faults) and the agent.
``DIR/config.json`` records the resolved arguments and package versions, so the result can be re-run.
Each run's record is written to ``DIR/runs/`` the moment it ends and ``results.json`` is rewritten
from the records every few seconds and at the end (``runs_done`` of ``runs_planned``): a crash, a kill
or Ctrl-C (SIGINT or SIGTERM: stop after the current run; twice: at once) keeps every finished run, and
``--resume`` continues them. A directory that holds results is refused unless ``--resume`` (same arguments)
or ``--force`` (start over).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tqdm import tqdm

from puzzlebox.lab import trial_task as _trial_task
from puzzlebox.lab.agent_class import is_agent_class_name, load_agent_class
from puzzlebox.lab.cells import profile_of_calibration
from puzzlebox.lab.cli import fail, one_line, write_json
from puzzlebox.lab.errors import AgentClassError, RunStoreError
from puzzlebox.lab.interrupt import StopRequests
from puzzlebox.lab.run_store import Periodic, RunStore
from puzzlebox.lab.trial_figures import twin_figures
from puzzlebox.learning import AGENT_NAMES, LearningError, make_agent, summarise
from puzzlebox.learning.agents.factory import BELIEF_AGENT_NAMES
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.learning.runner import InlineExecutor, RunnerError, make_executor, run_tasks
from puzzlebox.models import SpecError, load_spec
from puzzlebox.twin.errors import TwinError

SIMS = ("symbolic", "twin")
ROBOTS = ("twin", "xarm")


def _real_main(args, arm: Callable[[str, Any], Any] | None = None) -> int:
    """``--robot xarm``: one trial on the real arm (``puzzlebox.lab.real_trial``), refusing clearly, in one line, what
    cannot run; an address where no arm answers is refused first, in about a second. ``arm(ip, cell)`` connects
    to the arm (default ``real.XArmRobot``, after probing the address; a test passes one over a test double)."""
    if args.ip is None or args.cell is None:
        fail("--robot xarm needs --ip ADDRESS (the arm's controller) and --cell FILE (the cell config)")
    if args.sim != "twin":
        fail("--robot xarm runs the perception and skills pipeline: give --sim twin")
    from puzzlebox.models.calibration import CalibrationError, CellCalibration
    from puzzlebox.models.cell_config import CellConfigError, load_cell_config
    from puzzlebox.real import RealError, XArmRobot, probe_controller

    try:
        cell = load_cell_config(args.cell)
        if arm is None:
            probe_controller(args.ip)
    except (CellConfigError, RealError) as err:
        fail(f"--robot xarm: {one_line(err)}")
    twin_only = [flag for flag, given in (
        ("--video", args.video), ("--record", args.record is not None), ("--wrong-kind", args.wrong_kind),
        ("--reality", args.reality != "ideal"), ("--workers", args.workers is not None),
        ("--ray", args.ray is not None), ("--resume", args.resume),
    ) if given]  # fmt: skip
    if twin_only:
        fail(f"--robot xarm runs one trial on the arm: {', '.join(twin_only)} are for twin trials")
    if len(args.specs) != 1:
        fail(f"--robot xarm tries the one box on the table: give one spec, got {len(args.specs)}")
    if args.runs != 1:
        fail(f"--robot xarm runs one trial per command: give --runs 1, got {args.runs}")
    if args.max_actions < 1 or args.seed < 0:
        fail("--max-actions must be >= 1 and --seed >= 0")
    if args.calibration is None:
        fail("--robot xarm needs --calibration FILE: the cell's camera calibration (scripts/calibrate.py)")
    try:
        spec = load_spec(args.specs[0])
        calibration = CellCalibration.load(args.calibration)
        for camera in (cell.overview_camera, cell.wrist_camera):
            calibration.camera(camera)
    except (SpecError, CalibrationError) as err:
        fail(f"--robot xarm: {one_line(err)}")
    if args.agent not in AGENT_NAMES:
        fail(f"unknown agent {args.agent!r}. Available agents: {sorted(AGENT_NAMES)}")
    if (args.agent == "memory") != (args.memory is not None):
        fail("--memory goes with --agent memory (and only with it): train one with scripts/train.py")
    from puzzlebox.lab.real_trial import cell_configs, run_real_trial

    try:
        cell_configs(cell)
        memory = MemoryStore.open_existing(args.memory) if args.memory else None
        make_agent(args.agent, spec, memory, args.checkpoint, max_lockers=args.max_lockers)
    except (ValueError, LearningError) as err:
        fail(f"--robot xarm: {one_line(err)}")

    out = Path(args.out)
    experiment = {"command": "trial", "robot": "xarm", "ip": args.ip, "cell": cell.to_dict(),
                  "calibration": str(Path(args.calibration).resolve()), "spec": spec.to_dict(), "agent": args.agent,
                  "memory": args.memory, "checkpoint": args.checkpoint, "seed": args.seed,
                  "max_actions": args.max_actions, "max_lockers": args.max_lockers}  # fmt: skip
    try:
        store = RunStore(out, experiment, force=args.force)
    except RunStoreError as err:
        fail(one_line(err))
    key = f"000-{spec.name}-seed{args.seed}"

    def write(record: dict) -> None:  # the record as it grows: a stop or a crash keeps every action done
        write_json(store.records.path(key), {"key": key, "record": record})
        store.write_results({**summarise([record], args.max_actions), "runs_done": 0, "runs_planned": 1})

    try:
        with (arm or XArmRobot)(args.ip, cell) as robot:
            record = run_real_trial(robot, calibration, spec, cell, args.agent, args.seed, args.max_actions,
                                    memory=memory, checkpoint=args.checkpoint, on_record=write,
                                    max_lockers=args.max_lockers)  # fmt: skip
    except RealError as err:  # the arm refused or failed a call mid-trial (a stop is in the record instead)
        fail(f"--robot xarm: {one_line(err)}; what was done is kept in {out}", code=1)
    store.write_results({**summarise([record], args.max_actions), "runs_done": 1, "runs_planned": 1})
    if record["stopped"]:
        print(f"error: the arm was stopped after {record['num_actions']} action(s): {one_line(record['stopped'])}; "
              f"kept in {out}", file=sys.stderr)  # fmt: skip
        return 1
    print(f"{args.agent} on the arm at {args.ip}: {'solved' if record['solved'] else 'not solved'} (as perceived) "
          f"in {record['num_actions']} action(s), {record['wall_time_s']:.0f} s -> {out / 'results.json'}")  # fmt: skip
    if record["ended"]:
        print(f"unsolved: {record['ended']}")
    return 0


def _results(runs: list[dict], args, planned: int) -> dict:
    results = summarise(runs, args.max_actions)
    if args.sim == "twin":
        results.update(twin_figures(runs))
    results["runs_done"], results["runs_planned"] = len(runs), planned
    return results


def _tasks(args, specs, reality, calibration, out: Path) -> list:
    """One task per spec and seed; run ``r`` of every spec uses seed ``--seed + r``."""
    tasks = []
    for i, spec in enumerate(specs):
        for r in range(args.runs):
            seed = args.seed + r
            video = record = None
            single = len(specs) * args.runs == 1
            if args.video:
                name = "rollout.mp4" if single else f"rollout-{spec.name}-s{seed}.mp4"
                video = str((out / name).resolve())
            if args.record:
                path = Path(args.record)
                record = str(path.resolve() if single else path.with_name(f"{path.stem}-{spec.name}-s{seed}.rrd"))
            tasks.append(_trial_task.trial_task(
                f"{i:03d}-{spec.name}-seed{seed}", spec, seed, sim=args.sim, agent=args.agent,
                max_actions=args.max_actions, memory=args.memory, checkpoint=args.checkpoint,
                reality=reality.to_dict() if reality is not None else None,
                calibration=calibration.to_dict() if calibration is not None else None, video=video,
                misreport_kind=args.wrong_kind, max_lockers=args.max_lockers, record=record,
                locks=args.locks,
            ))  # fmt: skip
    return tasks


def _solved(records: dict[str, dict]) -> str:
    return f"solved {sum(r['solved'] for r in records.values())}/{len(records)}"


class _ActionBar:
    """The inner progress bar of an in-process trial: one tick per action, a new bar per run."""

    def __init__(self, max_actions: int) -> None:
        self.max_actions, self.bar = max_actions, None

    def start(self, name: str) -> None:
        self.close()
        self.bar = tqdm(total=self.max_actions, desc=f"  {name}", unit="action", leave=False, disable=None)

    def __call__(self, _action) -> None:
        if self.bar is not None:
            self.bar.update()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def main(argv: list[str] | None = None, *, arm: Callable[[str, Any], Any] | None = None) -> int:
    """The command line (see the module docstring); ``arm(ip, cell)`` connects ``--robot xarm`` (default
    ``real.XArmRobot``: tests pass one over a test double of the SDK)."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--specs", nargs="+", required=True, help="puzzle spec files")
    parser.add_argument("--memory", default=None, help="memory file from train.py (memory agent; read only)")
    parser.add_argument("--sim", choices=SIMS, required=True)
    parser.add_argument("--runs", type=int, required=True, help="runs per spec")
    parser.add_argument("--seed", type=int, required=True, help="seed of run 0; run r uses seed + r")
    parser.add_argument("--max-actions", type=int, required=True, help="action budget per run")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument(
        "--agent", default="memory",
        help=f"one of {list(AGENT_NAMES)} (default: memory), or an agent class of one's own as package.module:Class "
        "(the puzzlebox.learning.Agent methods, constructed with no argument; importable where trial.py runs)",
    )  # fmt: skip
    parser.add_argument("--checkpoint", default=None, help="checkpoint from train.py (deep agents)")
    parser.add_argument(
        "--max-lockers", type=int, default=1, metavar="K",
        help="symbolic memory/dual agents: believe in sets of up to K lockers per component (default 1: the paper's)",
    )  # fmt: skip
    parser.add_argument("--video", action="store_true", help="record rollout videos (twin only)")
    parser.add_argument(
        "--record", default=None, metavar="FILE.rrd",
        help="a Rerun recording of each twin run (one run: FILE.rrd; more: FILE-<spec>-s<seed>.rrd; the viz extra)",
    )  # fmt: skip
    parser.add_argument(
        "--wrong-kind", action="store_true",
        help="twin: tell the pipeline one component's kind wrong in every run (drawn from the run's seed)",
    )  # fmt: skip
    parser.add_argument(
        "--reality", default="ideal", help="twin reality profile: ideal, realistic, harsh or a JSON file"
    )
    parser.add_argument(
        "--locks", choices=("contact", "latch"), default="contact",
        help="twin: the box's lock rules as mechanisms that block by contact (default) or as rule-driven latches "
        "(the ablation; jams are latches in both)",
    )  # fmt: skip
    parser.add_argument(
        "--calibration", default=None, help="camera calibration from scripts/calibrate.py (twin; needed for xarm)"
    )
    parser.add_argument(
        "--workers", type=int, default=None, help="worker processes (default: one per core for twin, 1 = in-process)"
    )
    parser.add_argument("--ray", default=None, metavar="auto|ADDRESS", help="run on Ray: auto = a local cluster")
    parser.add_argument(
        "--robot", choices=ROBOTS, default="twin",
        help="twin: the MuJoCo twin (default); xarm: one trial on a real xArm-7 at --ip (--cell, --calibration)",
    )  # fmt: skip
    parser.add_argument("--ip", default=None, metavar="ADDRESS", help="the xArm controller's address (--robot xarm)")
    parser.add_argument(
        "--cell", default=None, metavar="FILE", help="cell config, models/cell_config.py (--robot xarm)"
    )
    parser.add_argument("--resume", action="store_true", help="continue the runs already in --out (same arguments)")
    parser.add_argument("--force", action="store_true", help="delete the results already in --out first")
    args = parser.parse_args(argv)
    if args.robot == "xarm":
        return _real_main(args, arm)
    if args.ip is not None or args.cell is not None:
        fail("--ip and --cell go with --robot xarm")
    # The memory is read, never written, during trials: evaluation does not change what was learned.

    if args.runs < 1 or args.max_actions < 1:
        fail("--runs and --max-actions must be >= 1")
    if args.seed < 0:
        fail(f"--seed must be >= 0, got {args.seed}")
    if args.workers is not None and (args.workers < 1 or args.ray is not None):
        fail("--workers must be >= 1, and goes without --ray" if args.workers < 1 else "give --workers or --ray")
    own_agent = is_agent_class_name(args.agent)
    if own_agent:
        if os.getcwd() not in sys.path:  # as `python -m` would: an agent module beside the user imports (workers
            sys.path.insert(0, os.getcwd())  # inherit the path)
        try:
            load_agent_class(args.agent)
        except AgentClassError as err:
            fail(one_line(err))
        if args.memory or args.checkpoint or args.max_lockers != 1:
            fail(f"--memory, --checkpoint and --max-lockers are for the project's agents, not {args.agent!r}")
    elif args.agent not in AGENT_NAMES:
        fail(f"unknown agent {args.agent!r}. Available agents: {sorted(AGENT_NAMES)}, or package.module:Class")
    if (args.agent == "memory") != (args.memory is not None):
        fail("--memory goes with --agent memory (and only with it): train one with scripts/train.py")
    if args.max_lockers != 1:
        if args.agent not in BELIEF_AGENT_NAMES:
            fail(f"--max-lockers is for the agents {list(BELIEF_AGENT_NAMES)}, not {args.agent!r}")
        try:
            DualControllerConfig(max_lockers=args.max_lockers)
        except LearningError as err:
            fail(f"--max-lockers: {err}")
    if args.video and args.sim != "twin":
        fail("--video needs --sim twin")
    if args.record is not None:
        if args.sim != "twin":
            fail("--record needs --sim twin")
        if not args.record.endswith(".rrd"):
            fail(f"--record {args.record}: a Rerun recording file ends in .rrd")
        if not Path(args.record).resolve().parent.is_dir():
            fail(f"--record {args.record}: directory {Path(args.record).resolve().parent} does not exist")
        try:
            import rerun  # noqa: F401  (the viz extra: refused here in one line, not in every run)
        except ImportError:
            fail("--record needs the rerun-sdk package (the viz extra): pip install -e .[viz]")
    if args.sim != "twin" and (args.reality != "ideal" or args.calibration):
        fail("--reality and --calibration need --sim twin")
    if args.sim != "twin" and args.wrong_kind:
        fail("--wrong-kind needs --sim twin (the symbolic protocols' faults: experiment.py noise)")
    reality = calibration = None
    if args.sim == "twin":
        from puzzlebox.models.calibration import CalibrationError, CellCalibration
        from puzzlebox.twin.reality import load_profile

        try:
            reality = load_profile(args.reality)
            calibration = CellCalibration.load(args.calibration) if args.calibration else None
            reality = profile_of_calibration(reality, calibration)  # the cell the calibration was made in
        except (TwinError, CalibrationError) as err:
            fail(str(err))
    try:
        specs = [load_spec(path) for path in args.specs]
    except SpecError as err:
        fail(str(err))
    if calibration is not None:
        # A calibration belongs to one cell: the profile's imperfections and the box height (the overview
        # camera hangs above the lid) must be those it was made in, or every pose perceived is off.
        for path, spec in zip(args.specs, specs, strict=True):
            try:
                calibration.check_cell(reality.name, reality.cell_seed, spec.box.size[2], spec=str(path))
            except CalibrationError as err:
                fail(f"--calibration {args.calibration} for spec {spec.name}: {err}")

    try:  # what every run needs is checked once here: a bad memory or checkpoint is one line, not N errors
        memory = MemoryStore.open_existing(args.memory) if args.memory else None
        if not own_agent:
            make_agent(args.agent, specs[0], memory, args.checkpoint)
    except LearningError as err:
        fail(str(err))
    if memory is not None:
        memory.close()  # each run opens it where it runs

    out = Path(args.out)
    # where and how it runs changes no record; --robot is twin here (xarm stops above), as before the flag existed
    not_results = ("out", "resume", "force", "workers", "ray", "robot", "ip", "cell", "record")
    experiment = {"command": "trial", **{k: v for k, v in vars(args).items() if k not in not_results}}
    if args.max_lockers == 1:  # the default leaves the configuration as it was before k existed (resumable)
        del experiment["max_lockers"]
    if args.locks == "latch" or args.sim != "twin":  # latches: the configuration made before mechanisms existed
        del experiment["locks"]
    # symbolic runs last less than a hand-over; a pool is started for no more twin runs than there are
    workers = args.workers or (min(os.cpu_count() or 1, len(specs) * args.runs) if args.sim == "twin" else 1)
    try:
        executor = make_executor(workers, args.ray)
    except RunnerError as err:
        fail(str(err))
    try:
        store = RunStore(out, experiment, resume=args.resume, force=args.force)
    except RunStoreError as err:
        fail(one_line(err))
    tasks = _tasks(args, specs, reality, calibration, out)
    found: dict[str, dict] = {}
    keys = [t.key for t in tasks]

    summary = Periodic(lambda: store.write_results(_results([found[k] for k in keys if k in found], args, len(tasks))))

    def keep(task, record) -> None:
        found[task.key] = record
        summary()

    try:
        with StopRequests("run") as stop, executor:
            inner = isinstance(executor, InlineExecutor)  # per-action bars only where the trial runs here
            _trial_task.set_action_hook(_ActionBar(args.max_actions) if inner else None)
            report = run_tasks(tasks, store.records, executor, stop=lambda: stop.requested, on_record=keep,
                               postfix=_solved, desc=f"{args.agent} {args.sim} trials")  # fmt: skip
    except RunnerError as err:
        fail(str(err))
    runs = list(report.records.values())
    results = _results(runs, args, len(tasks))
    store.write_results(results)
    if report.failures:  # each was named as it failed, above the progress bar
        key, error = next(iter(report.failures.items()))
        print(f"error: {len(report.failures)} run(s) failed (first: {key}: {error.splitlines()[0]}); {len(runs)} kept "
              f"in {out}; --resume retries the failed ones", file=sys.stderr)  # fmt: skip
        return 1
    if report.stopped:
        print(
            f"stopped: {len(runs)} of {len(tasks)} run(s) kept in {out}; continue with the same command and --resume",
            file=sys.stderr,
        )
        return 130
    print(
        f"{args.agent} on {len(specs)} spec(s) x {args.runs} run(s): success {results['success_rate']:.1%}, "
        f"mean actions {results['mean_actions']:.2f} -> {out / 'results.json'}"
    )
    if args.sim == "twin":
        print(
            f"outcome agreement {results['outcome_agreement']:.1%} over {results['actions_total']} actions; "
            f"perceived position error max {1000 * results['perceived_position_error_max_m']:.1f} mm; "
            f"wall time per trial max {results['wall_time_per_trial_s_max']:.1f} s; "
            f"simulated/wall x{results['sim_over_wall']:.1f}; "
            f"peak true wrist force {results['peak_true_wrist_force_n']:.0f} N"
        )
        for line in results["unsolved_reasons"]:
            print(f"unsolved: {line}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
