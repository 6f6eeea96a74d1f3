"""Run the paper's symbolic protocols for every agent and compare with the paper's numbers; or sweep
the reality gap in the twin.

    python scripts/experiment.py {variants,episodes,noise,all} --agents memory,dqn,model-based,mt-dqn,mt-model-based \\
        --out DIR [--quick] [--runs R] [--seeds S] [--workers W | --ray auto|ADDRESS]
    python scripts/experiment.py reality --out DIR [--quick] [--runs R] [--memory MEM.sqlite] [--workers W | --ray ...]
    python scripts/experiment.py faults --out DIR [--quick] [--runs R]
    python scripts/experiment.py twin-learning --out DIR [--quick] [--runs R] [--seeds S] [--workers W | --ray ...]
                                 [--agents memory,dqn,model-based] [--test-set paper|hard]
    python scripts/experiment.py hard-sets --out DIR [--profile realistic|harsh|FILE] [--boxes B] [--runs R]
                                 [--seed S] [--calibration both|with|without] [--memory MEM.sqlite] [--quick]
                                 [--workers W | --ray ...]
    python scripts/experiment.py regression --out DIR [--reference REGRESSION.json] [--quick] [--workers W | --ray ...]
    python scripts/experiment.py sysid --out DIR [--workers W] [--cells 0,1,2] [--quick]
    python scripts/experiment.py tries --out DIR [--workers W] [--quick]
    python scripts/experiment.py disassembly --agents memory,dual,dqn,model-based --out DIR [--quick] [--runs R]
                                 [--seeds S] [--workers W | --ray ...] [--validation] [--no-holding-rule]
    python scripts/experiment.py kinds --out DIR [--quick] [--runs R] [--workers W]
    python scripts/experiment.py manipulation --out DIR [--quick] [--seeds N] [--steps N] [--algo ppo|sac]

Writes ``DIR/<protocol>.json`` (every point, mean and std over training seeds and each seed's value,
the settings), ``DIR/<protocol>.png`` (success and mean actions, like the paper's Fig. 3 panels) and
``DIR/<protocol>.md`` (our numbers beside the paper's), and prints the tables. ``all`` runs the three
protocols (sharing the deep agents' training) and adds ``DIR/all.md`` with the episodes-to-100 %
table and the wall time of every part.

The deep agents (``dqn``, ``model-based``, ``mt-dqn``, ``mt-model-based``; torch) train as jobs, one
per agent, training seed and training-variant count, as tasks of ``puzzlebox.lab.runner``: ``--workers`` at
a time (default: one per core; ``--ray auto|ADDRESS``: on Ray). Every finished job is saved in
``DIR/jobs/`` at once: run the same command again after an
interruption and it resumes, reusing every finished job.

``reality`` (``puzzlebox/lab/reality_sweep.py``) runs the memory agent end to end in the twin on the paper
test boxes at ``--runs`` random reachable placements each (default 4), with each factor of the reality
gap alone at levels 0 (ideal), 1 (realistic) and 2 (harsh), all factors together, and the F/T force noise
alone over σ; each profile's cell is calibrated from ChArUco images first. It writes
``DIR/reality.{json,md,png}`` (success, mean actions, outcome agreement and failure reasons against each
factor's level; the F/T noise at which outcome agreement drops below 99 %) and keeps every calibration and
trial in ``DIR/calibrations/`` and ``DIR/trials/``: the same command resumes. ``--memory`` is the memory
agent's store (default: trained into ``DIR/memory.sqlite`` on the paper training boxes).

``twin-learning`` (``puzzlebox/lab/twin_learning.py``) measures the memory agent in the twin after 0-2 simulated
robot hours from an empty memory, a symbolic one, and a symbolic one with twin experience:
``DIR/twin-learning.{json,md,png}``, the test boxes' optimum beside every figure. ``--test-set hard`` tests on
eight-part boxes of every kind (random, multi-locker, chains: ``puzzlebox/lab/hard_sets.py``) held out from training
on boxes of the same families.

``hard-sets`` (``puzzlebox/lab/hard_grid.py``) runs the memory agent end to end in the twin on ``--boxes`` boxes
(default 20) of each hard family at ``--runs`` random reachable placements each (default 2) under ``--profile``
(default ``realistic``), its memory the twin-learning ``symbolic`` start (40 generated training boxes per family, or
``--memory``), every trial with the cell calibrated first and without a calibration file (``--calibration``);
``--seed S`` draws fresh test boxes (from seed S) and placements (from S + 100): ``DIR/hard-sets.{json,md,png}``,
per cell and family solved, mean actions against the optimum, peak true wrist force and runs over 45 N, outcome
agreement; every trial in ``DIR/trials/``: the same command resumes.

``regression`` (``puzzlebox/lab/regression_grid.py``) runs a fixed grid of twin trials (the paper test boxes x 5 seeds
under ``realistic`` and ``harsh``, 6 hard boxes x 2 placements, 10 runs with a misreported kind) and writes each
trial's fingerprint — its actions, their outcomes, ``sensed_sha256`` — to ``DIR/regression.json``; with
``--reference`` (an earlier run's ``regression.json``) it lists every difference and exits 1 if there is any: a
change meant to keep the behaviour keeps it bit for bit.

``sysid`` (``puzzlebox/lab/sysid.py``) identifies the box's per-kind joint damping, joint friction and latch
compliance from logged robot data of toggles (oracle trials in the twin under ``realistic``, three cells) and
reports the nominal and the fitted twin's prediction errors of the wrench and the part's motion on held-out
toggles: ``DIR/sysid.{json,md,png}``, every trial's log in ``DIR/logs/``; the same command resumes.

``tries`` (``puzzlebox/lab/tries_experiment.py``) records every try of twin trials (the paper test boxes under
``ideal``, ``realistic`` and ``harsh``, runs with a misreported kind, hard boxes) with the readings the hand's
judgement read and the simulator's truth, one file per trial in ``DIR/tries/``, then runs the judgement offline on
every recorded pinch and door swing: ``DIR/tries.{json,md,png}`` (agreement with the truth per motion, profile, split
and cause, with confusion matrices; the time a judgement takes) and ``DIR/sample.npz`` (a few of each cause); the
same command resumes.

``disassembly`` (``learning/experiments/disassembly.py``) trains every agent on the measured ``lab-computer-a``
and tests it on ``lab-computer-b`` and 10 variants of it (RAM sticks and GPU cables added or removed, every pose
jittered; ``--runs`` runs per test scene, default 5): success = the motherboard removed within 24 actions,
against training episodes (memory: 1-20, with the paper's one-locker belief and with sets of two lockers,
``memory-k2``; the deep agents, with dense rewards: 0-200). It writes ``DIR/disassembly.{json,md,png}``; each
(agent, training seed) is a task whose record is kept in ``DIR/records/``: the same command resumes.
``--validation`` tests on 10 variants of ``lab-computer-a`` instead (seeds 5000-5009: where every setting was
chosen); ``--no-holding-rule`` lets the belief agents believe that a removed part holds another (the paper's
hypothesis space, an ablation).

``kinds`` (``puzzlebox/lab/kinds_experiment.py``) runs boxes mixing every registered kind (door, slide, wheel,
drawer, lever): every five-kind chain and 100 random boxes symbolically, and 3 held-out chains end to end in the
twin under ``ideal`` and ``realistic``, by the memory agent trained on the other chains:
``DIR/kinds.{json,md,png}``; every step resumes.

``manipulation`` (``puzzlebox/lab/manipulation_experiment.py``; ``pip install puzzlebox[rl]``) trains PPO (or SAC)
from scratch on ``BoxManipulation-v0``, a free slide and a free wheel, ``--seeds`` seeds of ``--steps`` env steps each:
``DIR/manipulation.{json,png,md}``, success against env steps (a point appended at each evaluation).

``faults`` (``puzzlebox/lab/faults.py``) runs each fault class on purpose in real processes — ``trial.py``
SIGKILLed at random moments and resumed (``--runs`` runs in the twin; ``--quick``: symbolic), concurrent
trainers on one memory, a memory truncated at every page, the ordinary command-line mistakes — and writes
``DIR/faults.{json,md}``: cases, detected, survived, data kept.
"""

from __future__ import annotations

import argparse
import sys

from puzzlebox.lab.cli import OneLineParser, fail, run_script
from puzzlebox.lab.errors import ExperimentStepFailed, LabError
from puzzlebox.lab.experiment_flags import AGENTS, PROTOCOL_NAMES, ExperimentFlags
from puzzlebox.lab.experiment_protocols import run_experiment
from puzzlebox.lab.interrupt import AbortOnSignal, Interrupted
from puzzlebox.lab.learning_boxes import TEST_SETS
from puzzlebox.learning.agents.factory import POSE_ENCODINGS


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("protocol", choices=PROTOCOL_NAMES)
    parser.add_argument("--agents", default=None, help=f"comma-separated, from {list(AGENTS)} (reality: memory)")
    parser.add_argument("--out", required=True, help="output directory (also the resume cache of deep jobs)")
    parser.add_argument("--quick", action="store_true", help="CI size: few runs, one training seed, short schedules")
    parser.add_argument("--runs", type=int, default=None, help="runs per unseen variant (default 50)")
    parser.add_argument("--seeds", type=int, default=None, help="training seeds (default 3)")
    parser.add_argument("--workers", type=int, default=None, help="parallel deep-agent jobs (default: cores)")
    parser.add_argument("--ray", default=None, metavar="auto|ADDRESS", help="deep-agent jobs on Ray (auto: local)")
    parser.add_argument(
        "--poses", choices=POSE_ENCODINGS, default="relative",
        help="where the deep agents' graph network sees poses: relative (edges, default) or absolute (nodes, "
        "as the authors' release: an ablation)",
    )  # fmt: skip
    parser.add_argument("--memory", default=None, help="reality: the memory agent's store (default: trained in DIR)")
    parser.add_argument(
        "--cells", default=None, metavar="SEEDS", help="sysid: the cells' seeds, comma-separated (default 0,1,2)"
    )
    parser.add_argument(
        "--validation", action="store_true",
        help="disassembly: test on variants of the training computer (the split settings are chosen on)",
    )  # fmt: skip
    parser.add_argument(
        "--no-holding-rule", action="store_true",
        help="disassembly: the belief agents may believe a removed part holds another (the paper's hypotheses)",
    )  # fmt: skip
    parser.add_argument("--steps", type=int, default=None, help="manipulation: env steps per run (default 60000)")
    parser.add_argument("--algo", default=None, help="manipulation: ppo (default) or sac")
    parser.add_argument("--test-set", choices=TEST_SETS, default=None, help="twin-learning: paper (default) or hard")
    parser.add_argument(
        "--profile", default=None, help="hard-sets: the cell's reality profile, a preset or a JSON file (realistic)"
    )
    parser.add_argument("--boxes", type=int, default=None, help="hard-sets: test boxes of each family (default 20)")
    parser.add_argument(
        "--seed", type=int, default=None,
        help="hard-sets: fresh test boxes from seed S and placements from S + 100 (default 36000, 36100); "
        "twin-learning: test placements from S, training episodes from S + 10000 (default 60000, 70000)",
    )  # fmt: skip
    parser.add_argument(
        "--reference", default=None, metavar="REGRESSION.json",
        help="regression: an earlier run's DIR/regression.json; exit 1 if any action, outcome or sensed hash differs",
    )  # fmt: skip
    parser.add_argument(
        "--calibration", choices=("both", "with", "without"), default=None,
        help="hard-sets: run every trial with the cell calibrated first, without a calibration file, or both "
        "(default); twin-learning: train and test with (default) or without a calibration file",
    )  # fmt: skip
    args = parser.parse_args(argv)
    try:  # SIGINT or SIGTERM, whatever this process inherited: stop now, in one line; every saved job is kept
        with AbortOnSignal():
            run_experiment(ExperimentFlags(**vars(args)))
    except ExperimentStepFailed as err:  # the command it ran said why itself
        return err.returncode
    except LabError as err:
        fail(str(err))
    except (Interrupted, KeyboardInterrupt) as err:
        name = err.signal_name if isinstance(err, Interrupted) else "SIGINT"
        print(f"{name}: stopped; every finished job is kept in {args.out}: the same command resumes", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    run_script(main)
