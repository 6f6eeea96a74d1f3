r"""Train the memory agent in the symbolic simulator or end to end in the twin, and write its memory.

    python scripts/train.py --specs FILE... --episodes E --memory MEM.sqlite [--seed S] [--max-lockers K] [--resume]
    python scripts/train.py --specs FILE... --episodes E --memory MEM.sqlite --sim twin \
        [--reality ideal|realistic|harsh|FILE.json] [--calibration FILE.json] [--seed S] [--resume]
    python scripts/train.py --specs FILE... --episodes E --agent DEEP --checkpoint FILE [--seed S]

``DEEP`` is one of dqn, model-based, mt-dqn, mt-model-based.

``--max-lockers K`` (symbolic) trains the memory agent with a belief over sets of up to K lockers per component
(default: 2 if a training spec is a computer or has a part held by two lockers, else 1, the paper's one-locker
belief: ``learning.scene_lockers``); the memory stores each episode's graph in the one format either way,
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
import sys
from pathlib import Path

from puzzlebox.lab.cli import OneLineParser, fail, run_script, versions
from puzzlebox.lab.deep_training import train_deep
from puzzlebox.lab.errors import LabError
from puzzlebox.lab.inputs import MAX_ACTIONS, MAX_EPISODES, check_count, check_seed
from puzzlebox.lab.memory_training import MemoryTraining, training_command
from puzzlebox.lab.training_setup import (
    check_writable,
    hold_output_file,
    load_training_specs,
    memory_controller,
    twin_training_for,
)
from puzzlebox.learning import DEEP_AGENT_NAMES
from puzzlebox.learning.scene_lockers import training_max_lockers


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
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
        "--max-lockers", type=int, default=None, metavar="K",
        help="symbolic memory agent: believe in sets of up to K lockers per component (default: 2 if a training "
        "spec is a computer or has a part held by two lockers, else 1, the paper's)",
    )  # fmt: skip
    parser.add_argument("--resume", action="store_true", help="continue the latest run of this same command")
    args = parser.parse_args(argv)
    try:
        check_count(args.episodes, "--episodes", MAX_EPISODES)
        check_count(args.max_actions, "--max-actions", MAX_ACTIONS)
        check_seed(args.seed, count=args.episodes)  # episode e uses seed + e
        return _train(args)
    except LabError as err:
        fail(str(err))
    return 2  # not reached: fail exits


def _train(args: argparse.Namespace) -> int:
    specs = load_training_specs(args.specs)
    if args.max_lockers is None:  # what fits the training scenes (logged resolved: a rerun resumes the same run)
        symbolic_memory = args.sim == "symbolic" and args.agent == "memory"
        args.max_lockers = training_max_lockers(specs) if symbolic_memory else 1
    if args.sim == "symbolic" and (args.reality is not None or args.calibration is not None):
        fail("--reality and --calibration are for --sim twin")
    controller = memory_controller(args.max_lockers, args.sim, args.agent)
    twin = twin_training_for(args.reality, args.calibration, args.specs, specs) if args.sim == "twin" else None
    if args.agent != "memory":
        if twin is not None:
            fail("--sim twin trains the memory agent only (deep agents train in the symbolic simulator)")
        if args.checkpoint is None or args.memory is not None:
            fail(f"--agent {args.agent} trains a network: give --checkpoint FILE (and no --memory)")
        lock = hold_output_file(Path(args.checkpoint), "--checkpoint")  # one trainer writes a checkpoint
        command = {"command": "train", **vars(args), "versions": versions()}
        solved = train_deep(args.agent, specs, seed=args.seed, episodes=args.episodes, max_actions=args.max_actions,
                            checkpoint=args.checkpoint, command=command)  # fmt: skip
        print(f"trained {args.agent} for {args.episodes} episode(s), {solved} solved -> {args.checkpoint}")
        lock.release()
        return 0
    if args.memory is None:
        fail("the memory agent needs --memory MEM.sqlite")
    check_writable(Path(args.memory), "--memory")
    training = MemoryTraining(args.memory, training_command(vars(args)), args.resume)
    if training.resumed:
        print(f"resuming training run {training.run_id}: {training.resumed} of {args.episodes} episode(s) already "
              "in the memory")  # fmt: skip
    done, solved = training.train(specs, seed=args.seed, episodes=args.episodes, max_actions=args.max_actions,
                                  sim=args.sim, controller=controller, twin=twin)  # fmt: skip
    held = training.finish()
    print(f"trained {done} episode(s), {solved} solved; memory holds {held} -> {args.memory}")
    if done < args.episodes:
        print(f"stopped after {done} of {args.episodes} episode(s): every finished one is in the memory",
              file=sys.stderr)  # fmt: skip
        return 130
    return 0


if __name__ == "__main__":
    run_script(main)
