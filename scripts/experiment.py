"""Run the paper's symbolic protocols for every agent and compare with the paper's numbers; or sweep
the reality gap in the twin.

    python scripts/experiment.py {variants,episodes,noise,all} --agents memory,dqn,model-based,mt-dqn,mt-model-based \\
        --out DIR [--quick] [--runs R] [--seeds S] [--workers W | --ray auto|ADDRESS]
    python scripts/experiment.py reality --out DIR [--quick] [--runs R] [--memory MEM.sqlite] [--workers W | --ray ...]
    python scripts/experiment.py faults --out DIR [--quick] [--runs R]
    python scripts/experiment.py twin-learning --out DIR [--quick] [--runs R] [--seeds S] [--workers W | --ray ...]
                                 [--agents memory,dqn,model-based]
    python scripts/experiment.py sysid --out DIR [--workers W] [--cells 0,1,2] [--quick]
    python scripts/experiment.py disassembly --agents memory,dual,dqn,model-based --out DIR [--quick] [--runs R]
                                 [--seeds S] [--workers W | --ray ...] [--validation] [--no-holding-rule]
    python scripts/experiment.py kinds --out DIR [--quick] [--runs R] [--workers W]

Writes ``DIR/<protocol>.json`` (every point, mean and std over training seeds and each seed's value,
the settings), ``DIR/<protocol>.png`` (success and mean actions, like the paper's Fig. 3 panels) and
``DIR/<protocol>.md`` (our numbers beside the paper's), and prints the tables. ``all`` runs the three
protocols (sharing the deep agents' training) and adds ``DIR/all.md`` with the episodes-to-100 %
table and the wall time of every part.

The deep agents (``dqn``, ``model-based``, ``mt-dqn``, ``mt-model-based``; torch) train as jobs, one
per agent, training seed and training-variant count, as tasks of ``learning.runner``: ``--workers`` at
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

``sysid`` (``puzzlebox/lab/sysid.py``) identifies the box's per-kind joint damping, joint friction and latch
compliance from logged robot data of toggles (oracle trials in the twin under ``realistic``, three cells) and
reports the nominal and the fitted twin's prediction errors of the wrench and the part's motion on held-out
toggles: ``DIR/sysid.{json,md,png}``, every trial's log in ``DIR/logs/``; the same command resumes.

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

``faults`` (``puzzlebox/lab/faults.py``) runs each fault class on purpose in real processes — ``trial.py``
SIGKILLed at random moments and resumed (``--runs`` runs in the twin; ``--quick``: symbolic), concurrent
trainers on one memory, a memory truncated at every page, the ordinary command-line mistakes — and writes
``DIR/faults.{json,md}``: cases, detected, survived, data kept.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from puzzlebox.lab.cli import fail, versions, write_json
from puzzlebox.learning.agents.factory import POSE_ENCODINGS
from puzzlebox.learning.errors import LearningError
from puzzlebox.learning.experiments import (
    PROTOCOLS,
    SYMBOLIC_AGENTS,
    ProtocolConfig,
    comparison_table,
    plot,
    results_table,
)
from puzzlebox.learning.experiments.deep_protocols import (
    DEEP_AGENTS,
    DeepSchedule,
    jobs_for,
    merge_deep_points,
    run_jobs,
)
from puzzlebox.learning.experiments.report import episodes_to_solve_table

DISASSEMBLY = "disassembly"
REALITY = "reality"
FAULTS = "faults"
TWIN_LEARNING = "twin-learning"
SYSID = "sysid"
KINDS = "kinds"
ALL = "all"
AGENTS = (*SYMBOLIC_AGENTS, *DEEP_AGENTS)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    choices = (*PROTOCOLS, ALL, REALITY, FAULTS, TWIN_LEARNING, SYSID, DISASSEMBLY, KINDS)
    parser.add_argument("protocol", choices=choices)
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
    args = parser.parse_args(argv)
    if args.cells is not None and args.protocol != SYSID:
        fail("--cells goes with the sysid protocol")
    if (args.validation or args.no_holding_rule) and args.protocol != DISASSEMBLY:
        fail("--validation and --no-holding-rule go with the disassembly protocol")

    if args.protocol == REALITY:
        return _reality(args)
    if args.protocol == FAULTS:
        return _faults(args)
    if args.protocol == TWIN_LEARNING:
        return _twin_learning(args)
    if args.protocol == SYSID:
        return _sysid(args)
    if args.protocol == DISASSEMBLY:
        return _disassembly(args)
    if args.protocol == KINDS:
        return _kinds(args)
    if args.memory is not None:
        fail("--memory is for the reality protocol (the symbolic protocols train their own)")
    agents = _agents(args, AGENTS)
    config, schedule = ProtocolConfig(), DeepSchedule()
    if args.quick:
        config, schedule = config.quick(), schedule.quick()
    if args.runs is not None:
        config = replace(config, runs_per_variant=args.runs)
    if args.seeds is not None:
        config = replace(config, training_seeds=args.seeds)
    if config.runs_per_variant < 1 or config.training_seeds < 1 or (args.workers is not None and args.workers < 1):
        fail("--runs, --seeds and --workers must be >= 1")

    out = Path(args.out)
    protocols = list(PROTOCOLS) if args.protocol == ALL else [args.protocol]
    write_json(
        out / f"{args.protocol}.config.json",
        {"command": "experiment", **vars(args), "protocol_config": asdict(config),
         "deep_schedule": asdict(schedule), "versions": versions()},
    )  # fmt: skip
    symbolic = [a for a in agents if a in SYMBOLIC_AGENTS]
    deep = [a for a in agents if a in DEEP_AGENTS]
    start = time.perf_counter()
    timings: dict[str, float] = {}
    results: dict[str, dict[str, Any]] = {}
    try:
        for protocol in protocols:
            t0 = time.perf_counter()
            results[protocol] = PROTOCOLS[protocol](symbolic, config, quick=args.quick)
            timings[f"{protocol}: symbolic agents"] = time.perf_counter() - t0
        if deep:
            jobs = [job for protocol in protocols for job in jobs_for(protocol, deep, config, schedule, args.poses)]
            records, summary = run_jobs(jobs, config, out, args.workers, args.ray)
            timings["deep agents (all their jobs)"] = summary["wall_time_s"]
            print(f"deep agents: {summary['computed']} job(s) run, {summary['reused']} reused from {out}/jobs")
            for protocol in protocols:
                results[protocol] = merge_deep_points(results[protocol], deep, records, config, schedule, args.poses)
                results[protocol]["deep_jobs"] = summary
    except LearningError as err:
        fail(str(err))
    total = time.perf_counter() - start
    for protocol, result in results.items():
        result["wall_time_s"] = total
        result["timings_s"] = timings
        _write(result, out, protocol)
    if args.protocol == ALL:
        lines = ["# All protocols", "", "## Episodes to 100% on the unseen variants", ""]
        lines += [episodes_to_solve_table(results["episodes"]), "", "## Wall time", "", "| part | s |", "|---|---|"]
        lines += [f"| {part} | {seconds:.0f} |" for part, seconds in timings.items()]
        lines += [f"| **total** | **{total:.0f}** |", ""]
        (out / "all.md").write_text("\n".join(lines))
        print("\n".join(lines))
    print(f"{args.protocol}: {total:.0f} s -> {out}/")
    return 0


def _reality(args: argparse.Namespace) -> int:
    from puzzlebox.lab.reality_sweep import SweepConfig, run_sweep

    if args.agents not in (None, "memory"):
        fail(f"the reality protocol runs the memory agent only, got --agents {args.agents}")
    if args.seeds is not None:
        fail("--seeds is for the symbolic protocols")
    if args.workers is not None and args.workers < 1:
        fail("--workers must be >= 1")
    config = _with_runs(SweepConfig().quick() if args.quick else SweepConfig(), args.runs, "placements", 1)
    memory = None
    if args.memory is not None:
        memory = Path(args.memory)
        if not memory.is_file():
            fail(f"--memory {memory}: no such file (train one with scripts/train.py, or leave it out)")
    out = Path(args.out)
    _write_config(out, "reality", args, sweep=asdict(config))
    try:
        summary = run_sweep(out, config, memory, args.workers, args.ray)
    except LearningError as err:
        fail(str(err))
    return _report(out, "reality", summary)


def _twin_learning(args: argparse.Namespace) -> int:
    from puzzlebox.lab.twin_learning import TwinLearningConfig, run_twin_learning

    if args.memory is not None:
        fail("the twin-learning protocol runs the memory agent from its own memories (no --memory)")
    if args.workers is not None and args.workers < 1:
        fail("--workers must be >= 1")
    config = TwinLearningConfig().quick() if args.quick else TwinLearningConfig()
    if args.agents is not None:  # the memory's curve always; the deep agents asked for beside it
        agents = [a.strip() for a in args.agents.split(",") if a.strip()]
        unknown = [a for a in agents if a not in ("memory", *DEEP_AGENTS)]
        if unknown or "memory" not in agents:
            fail(f"twin-learning --agents: memory and any of {list(DEEP_AGENTS)}, got {agents}")
        config = replace(config, deep_agents=tuple(a for a in agents if a != "memory"))
    config = _with_runs(config, args.runs, "placements", 1)
    if args.seeds is not None:
        if args.seeds < 1:
            fail(f"--seeds must be >= 1, got {args.seeds}")
        config = replace(config, seeds=tuple(range(args.seeds)))
    out = Path(args.out)
    _write_config(out, TWIN_LEARNING, args, twin_learning=asdict(config))
    try:
        summary = run_twin_learning(out, config, args.workers, args.ray)
    except LearningError as err:
        fail(str(err))
    return _report(out, TWIN_LEARNING, summary)


def _kinds(args: argparse.Namespace) -> int:
    from puzzlebox.lab.kinds_experiment import KindsConfig, run_kinds

    given = [f"--{k}" for k in ("agents", "seeds", "ray", "memory") if getattr(args, k) is not None]
    if given:
        fail(f"the kinds protocol takes only --out, --runs, --workers and --quick, got {' '.join(given)}")
    if args.workers is not None and args.workers < 1:
        fail("--workers must be >= 1")
    config = _with_runs(KindsConfig().quick() if args.quick else KindsConfig(), args.runs, "runs", 1)
    out = Path(args.out)
    _write_config(out, KINDS, args, kinds=asdict(config))
    summary = run_kinds(out, config, args.workers)
    return _report(out, KINDS, summary)


def _sysid(args: argparse.Namespace) -> int:
    from puzzlebox.lab.sysid import SysIdConfig, run_sysid

    given = [f"--{name}" for name in ("agents", "runs", "seeds", "ray", "memory") if getattr(args, name) is not None]
    if given:
        fail(f"the sysid protocol takes only --out, --workers, --cells and --quick, got {' '.join(given)}")
    if args.workers is not None and args.workers < 1:
        fail(f"--workers must be >= 1, got {args.workers}")
    config = SysIdConfig().quick() if args.quick else SysIdConfig()
    if args.cells is not None:
        try:
            cells = tuple(int(c) for c in args.cells.split(","))
        except ValueError:
            fail(f"--cells takes comma-separated integers (cell seeds), got {args.cells!r}")
        if not cells or min(cells) < 0 or len(set(cells)) != len(cells):
            fail(f"--cells takes distinct cell seeds >= 0, got {args.cells!r}")
        config = replace(config, cell_seeds=cells)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        fail(f"--out {out} is a file, not a directory")
    _write_config(out, SYSID, args, sysid=asdict(config))
    try:
        summary = run_sysid(out, config, args.workers)
    except LearningError as err:
        fail(str(err))
    return _report(out, SYSID, summary)


def _disassembly(args: argparse.Namespace) -> int:
    from puzzlebox.learning.experiments.disassembly import AGENTS as DISASSEMBLY_AGENTS
    from puzzlebox.learning.experiments.disassembly import DisassemblyConfig, run_disassembly
    from puzzlebox.learning.experiments.disassembly_report import plot as plot_disassembly
    from puzzlebox.learning.experiments.disassembly_report import table as disassembly_table

    if args.memory is not None:
        fail("the disassembly protocol trains its own memories (no --memory)")
    agents = _agents(args, DISASSEMBLY_AGENTS)
    if args.workers is not None and args.workers < 1:
        fail(f"--workers must be >= 1, got {args.workers}")
    config = _with_runs(DisassemblyConfig().quick() if args.quick else DisassemblyConfig(), args.runs,
                        "runs_per_test", 1)  # fmt: skip
    if args.seeds is not None:
        if args.seeds < 1:
            fail(f"--seeds must be >= 1, got {args.seeds}")
        config = replace(config, training_seeds=args.seeds)
    config = replace(config, validation=args.validation, holding_rule=not args.no_holding_rule)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        fail(f"--out {out} is a file, not a directory")
    _write_config(out, DISASSEMBLY, args, disassembly=asdict(config))
    try:
        summary = run_disassembly(out, agents, config, args.workers, args.ray)
    except LearningError as err:
        fail(str(err))
    write_json(out / f"{DISASSEMBLY}.json", summary)
    plot_disassembly(summary, out / f"{DISASSEMBLY}.png")
    (out / f"{DISASSEMBLY}.md").write_text(f"# Disassembly\n\n{disassembly_table(summary)}")
    return _report(out, DISASSEMBLY, summary)


def _faults(args: argparse.Namespace) -> int:
    from puzzlebox.lab.faults import FaultsConfig, run_faults

    if any(v is not None for v in (args.agents, args.seeds, args.workers, args.ray, args.memory)):
        fail("the faults protocol takes only --out, --quick and --runs")
    config = _with_runs(FaultsConfig().quick() if args.quick else FaultsConfig(), args.runs, "trial_runs", 2,
                        " (a kill lands between two runs)")  # fmt: skip
    out = Path(args.out)
    _write_config(out, "faults", args, faults=asdict(config))
    return _report(out, "faults", run_faults(out, config))


def _agents(args: argparse.Namespace, available: tuple[str, ...]) -> list[str]:
    """The ``--agents`` of a protocol that needs them, each one of ``available`` (else one line, exit 2)."""
    if args.agents is None:
        fail(f"protocol {args.protocol!r} needs --agents (comma-separated, from {list(available)})")
    agents = [a.strip() for a in args.agents.split(",") if a.strip()]
    unknown = [a for a in agents if a not in available]
    if not agents or unknown:
        fail(f"unknown agents {unknown or agents} for {args.protocol!r}; available: {list(available)}")
    return agents


def _with_runs(config: Any, runs: int | None, field: str, minimum: int, why: str = "") -> Any:
    """``config`` with ``--runs`` in ``field`` (unchanged without it); below ``minimum`` is a one-line error."""
    if runs is None:
        return config
    if runs < minimum:
        fail(f"--runs must be >= {minimum}{why}, got {runs}")
    return replace(config, **{field: runs})


def _write_config(out: Path, name: str, args: argparse.Namespace, **settings: Any) -> None:
    """``DIR/<name>.config.json``: the command line, the resolved settings and the versions, beside the results."""
    write_json(out / f"{name}.config.json", {"command": "experiment", **vars(args), **settings, "versions": versions()})


def _report(out: Path, name: str, summary: dict[str, Any]) -> int:
    print((out / f"{name}.md").read_text())
    print(f"{name}: {summary['wall_time_s']:.0f} s -> {out}/")
    return 0


def _write(result: dict[str, Any], out: Path, protocol: str) -> None:
    write_json(out / f"{protocol}.json", result)
    plot(result, out / f"{protocol}.png")
    tables = f"## {protocol}: all points (success / mean actions)\n\n{results_table(result)}\n\n"
    tables += f"## {protocol}: ours beside the paper\n\n{comparison_table(result)}\n"
    if protocol == "episodes":
        tables += f"\n## episodes to 100% on the unseen variants\n\n{episodes_to_solve_table(result)}\n"
    (out / f"{protocol}.md").write_text(tables)
    print(tables)


if __name__ == "__main__":
    raise SystemExit(main())
