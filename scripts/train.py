"""Train the memory agent in the symbolic simulator or end to end in the twin, and write its memory.

    python scripts/train.py --specs FILE... --episodes E --memory MEM.sqlite [--seed S] [--max-lockers K] [--resume]
    python scripts/train.py --specs FILE... --episodes E --memory MEM.sqlite --sim twin \
        [--reality ideal|realistic|harsh|FILE.json] [--calibration FILE.json] [--seed S] [--resume]
    python scripts/train.py --specs FILE... --episodes E --agent DEEP --checkpoint FILE [--seed S]

``DEEP`` is one of dqn, model-based, mt-dqn, mt-model-based.

``--max-lockers K`` (symbolic) trains the memory agent with a belief over sets of up to K lockers per component
(default 1: the paper's one-locker belief); the memory stores each episode's graph in the one format either way,
each pair's probability of being among the lockers (``learning.lock_belief.LockBelief.locker_memberships``: for
one locker the belief itself), so any agent can recall it.

Episode ``e`` runs on ``specs[e % len(specs)]`` with world seed ``S + e``. The memory is written to
SQLite after every episode (one transaction each, the episode's training-log row with it), so an
interrupted run keeps every finished episode and the log always matches the memory; training an
existing memory continues it, and several trainers may share one file. ``MEM.sqlite.train.json`` is an
export of the file's training log (every run's resolved arguments and versions, every episode's
outcome), written when training ends or stops. Ctrl-C or SIGTERM stops after the current episode.

``--sim twin`` runs each episode end to end in the MuJoCo twin under the reality profile ``--reality``
(perception from rendered images with ``--calibration``, the primitives, the F/T outcomes), and the memory
keeps only what the robot sensed: the outcomes it read and the poses it perceived, never the simulator's
truth. Each episode is stored with its provenance (``twin``, the profile, its simulated robot time);
``scripts/memory.py MEM.sqlite`` shows how much of a memory came from where. ``--resume`` continues the
latest run of the same command in the memory (same specs, episodes, seed, sim, profile, calibration and
budget): the episodes it stored are not run again, so a run killed and resumed ends with the memory an
uninterrupted one writes (a kill loses at most the episode in progress).
"""

from __future__ import annotations

import argparse
import json
import os
import sqlite3
import sys
from pathlib import Path

from tqdm import tqdm

from puzzlebox.lab.cells import profile_of_calibration
from puzzlebox.lab.cli import fail, versions, write_json
from puzzlebox.lab.interrupt import StopRequests
from puzzlebox.learning import DEEP_AGENT_NAMES, MemoryAgent, SymbolicWorld, run_episode
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import LearningError
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models import SpecError, load_spec


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--specs", nargs="+", required=True, help="training puzzle spec files")
    parser.add_argument("--episodes", type=int, required=True, help="training episodes (cycling through the specs)")
    parser.add_argument("--memory", default=None, help="SQLite memory file (created or continued): memory agent")
    parser.add_argument("--agent", default="memory", choices=("memory", *DEEP_AGENT_NAMES))
    parser.add_argument("--checkpoint", default=None, help="output checkpoint (dqn and model-based agents)")
    parser.add_argument("--seed", type=int, default=0, help="world seed of episode 0; episode e uses seed + e")
    parser.add_argument("--max-actions", type=int, default=50, help="action budget per training episode")
    parser.add_argument("--sim", choices=("symbolic", "twin"), default="symbolic", help="where episodes run")
    parser.add_argument("--reality", default=None, help="twin reality profile: ideal, realistic, harsh or FILE.json")
    parser.add_argument("--calibration", default=None, help="twin: the cell's calibration file (calibrate.py)")
    parser.add_argument(
        "--max-lockers", type=int, default=1, metavar="K",
        help="symbolic memory agent: believe in sets of up to K lockers per component (default 1: the paper's)",
    )  # fmt: skip
    parser.add_argument("--resume", action="store_true", help="continue the latest run of this same command")
    args = parser.parse_args(argv)
    if args.episodes < 1 or args.max_actions < 1:
        fail("--episodes and --max-actions must be >= 1")
    if args.seed < 0:
        fail(f"--seed must be >= 0, got {args.seed}")
    try:
        specs = [load_spec(path) for path in args.specs]
    except SpecError as err:
        fail(str(err))
    if args.sim == "symbolic" and (args.reality is not None or args.calibration is not None):
        fail("--reality and --calibration are for --sim twin")
    controller = None
    if args.max_lockers != 1:
        if args.sim != "symbolic" or args.agent != "memory":
            fail("--max-lockers is for the memory agent with --sim symbolic (the twin's keeps the one-locker belief)")
        try:
            controller = DualControllerConfig(max_lockers=args.max_lockers)
        except LearningError as err:
            fail(f"--max-lockers: {err}")
    twin = _twin_setup(args, specs) if args.sim == "twin" else None
    if args.agent != "memory":
        if twin is not None:
            fail("--sim twin trains the memory agent only (deep agents train in the symbolic simulator)")
        if args.checkpoint is None or args.memory is not None:
            fail(f"--agent {args.agent} trains a network: give --checkpoint FILE (and no --memory)")
        _check_writable(Path(args.checkpoint), "--checkpoint")
        return _train_deep(args, specs)
    if args.memory is None:
        fail("the memory agent needs --memory MEM.sqlite")
    memory_path = Path(args.memory)
    _check_writable(memory_path, "--memory")
    command = {key: value for key, value in vars(args).items() if key != "resume"}
    if args.max_lockers == 1:  # the default leaves the command as it was before k existed (resumable)
        del command["max_lockers"]
    try:
        store = MemoryStore(args.memory)
        run_id, done_seeds = _resumed_run(store, command) if args.resume else (None, set())
        if run_id is None:
            run_id = store.begin_training_run({"command": "train", **command, "versions": versions()})
    except LearningError as err:
        fail(str(err))
    except sqlite3.OperationalError as err:  # e.g. a read-only directory for SQLite's journal
        fail(f"--memory {memory_path}: cannot write ({err})")

    log_path = Path(args.memory + ".train.json")
    solved = 0
    done = len(done_seeds)
    if done:
        print(f"resuming training run {run_id}: {done} of {args.episodes} episode(s) already in the memory")
    with StopRequests("episode") as stop:
        try:
            todo = [e for e in range(args.episodes) if args.seed + e not in done_seeds]
            for e in tqdm(todo, desc=f"training ({args.sim})", unit="episode", disable=None):
                if stop.requested:
                    break
                spec = specs[e % len(specs)]
                agent = MemoryAgent(store, learn=True, config=controller if twin is None else twin.controller)
                agent.episode_label, agent.episode_seed, agent.training_run = spec.name, args.seed + e, run_id
                if twin is None:
                    result = run_episode(agent, SymbolicWorld(spec, args.seed + e), spec.name, args.seed + e,
                                         args.max_actions)  # fmt: skip
                else:
                    result = twin.episode(agent, spec, args.seed + e, args.max_actions)
                solved, done = solved + result.solved, done + 1
        except KeyboardInterrupt:
            pass
    # the log is in the memory file, episode by episode; its export is written once, at the end (reading
    # the whole log after every episode made a long training quadratic)
    write_json(log_path, {"memory": args.memory, "runs": store.training_log()})
    store.close()
    print(f"trained {done} episode(s), {solved} solved; memory holds {store.num_episodes} -> {args.memory}")
    if done < args.episodes:
        print(f"stopped after {done} of {args.episodes} episode(s): every finished one is in the memory",
              file=sys.stderr)  # fmt: skip
        return 130
    return 0


def _resumed_run(store: MemoryStore, command: dict) -> tuple[int | None, set[int]]:
    """The latest training run in ``store`` made by the same ``command`` (versions aside) and the seeds of the
    episodes it stored; (None, empty) when there is none."""
    for run in reversed(store.training_log()):
        config = dict(run["config"])  # type: ignore[arg-type]
        config.pop("versions", None)
        config.pop("command", None)
        if config == json.loads(json.dumps(command)):
            return run["id"], {e["seed"] for e in run["episodes"]}  # type: ignore[union-attr]
    return None, set()


def _twin_setup(args: argparse.Namespace, specs: list):
    """The twin episode runner for ``--sim twin`` (the twin loads only when asked); a calibration must be the
    one of this cell (profile and box height), as ``trial.py`` checks."""
    from puzzlebox.lab.twin_training import TwinTraining
    from puzzlebox.models.calibration import CalibrationError, CellCalibration
    from puzzlebox.twin.errors import TwinError
    from puzzlebox.twin.reality import load_profile

    try:
        reality = load_profile(args.reality or "ideal")
        calibration = CellCalibration.load(args.calibration) if args.calibration else None
        reality = profile_of_calibration(reality, calibration)  # the cell the calibration was made in
    except (TwinError, CalibrationError) as err:
        fail(str(err))
    for path, spec in zip(args.specs, specs, strict=True):
        if calibration is not None:
            try:
                calibration.check_cell(reality.name, reality.cell_seed, spec.box.size[2], spec=str(path))
            except CalibrationError as err:
                fail(f"--calibration {args.calibration} for spec {spec.name}: {err}")
    return TwinTraining(reality, calibration)


def _check_writable(path: Path, flag: str) -> None:
    """Fail now, not after the training, if ``path`` cannot be written."""
    if path.is_dir():
        fail(f"{flag} {path} is a directory, not a file")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        fail(f"{flag} {path}: cannot create its directory ({err.strerror})")
    target = path if path.exists() else path.parent
    if not os.access(target, os.W_OK):
        fail(f"{flag} {path}: cannot write {'it' if path.exists() else 'there'} (read-only)")


def _train_deep(args: argparse.Namespace, specs: list) -> int:
    from puzzlebox.learning.baselines import make_learner, save_checkpoint  # torch only when asked

    agent = make_learner(args.agent, args.seed)
    log = {"command": "train", **vars(args), "versions": versions(), "runs": []}
    for e in tqdm(range(args.episodes), desc=f"training {args.agent}", unit="episode", disable=None):
        spec = specs[e % len(specs)]
        result = run_episode(agent, SymbolicWorld(spec, args.seed + e), spec.name, args.seed + e, args.max_actions)
        log["runs"].append({k: v for k, v in result.to_dict().items() if k != "actions"})
        if (e + 1) % 50 == 0 or e + 1 == args.episodes:  # nothing much lost on a crash
            save_checkpoint(agent, args.checkpoint)
            write_json(Path(args.checkpoint + ".train.json"), log)
    solved = sum(r["solved"] for r in log["runs"])
    print(f"trained {args.agent} for {args.episodes} episode(s), {solved} solved -> {args.checkpoint}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
