"""The paper's symbolic protocols (variants, episodes, noise, or all three) for every agent asked, as
``experiment.py`` runs them: the symbolic agents in this process, the deep agents as resumable training jobs
(``deep_protocols_run``, saved in ``DIR/jobs/``), and per protocol ``DIR/<protocol>.json``,
``.png`` and ``.md`` (our numbers beside the paper's); ``all`` adds ``DIR/all.md`` (episodes to 100 % and the
wall time of every part)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from puzzlebox.lab.cli import write_json
from puzzlebox.lab.deep_protocols_run import run_jobs
from puzzlebox.lab.errors import ExperimentFailed, ExperimentSettingsError
from puzzlebox.lab.experiment_flags import AGENTS, ALL, ExperimentFlags
from puzzlebox.learning.errors import LearningError
from puzzlebox.learning.experiments import (
    PROTOCOLS,
    SYMBOLIC_AGENTS,
    ProtocolConfig,
    comparison_table,
    plot,
    results_table,
)
from puzzlebox.learning.experiments.deep_protocols import DEEP_AGENTS, DeepSchedule, jobs_for, merge_deep_points
from puzzlebox.learning.experiments.report import episodes_to_solve_table


def run_paper_protocols(flags: ExperimentFlags, echo: Callable[[str], object] = print) -> None:
    """Run ``flags.protocol`` (one of the paper's, or ``all``) for ``flags.agents`` and write its results in
    ``flags.out``; ``echo`` gets the deep jobs' count, every table and the wall time.
    :class:`ExperimentSettingsError` for settings that cannot run, :class:`ExperimentFailed` if the learning
    layer refuses."""
    if flags.memory is not None:
        raise ExperimentSettingsError("--memory is for the reality protocol (the symbolic protocols train their own)")
    agents = flags.agent_names(AGENTS)
    config, schedule = ProtocolConfig(), DeepSchedule()
    if flags.quick:
        config, schedule = config.quick(), schedule.quick()
    if flags.runs is not None:
        config = replace(config, runs_per_variant=flags.runs)
    if flags.seeds is not None:
        config = replace(config, training_seeds=flags.seeds)
    if config.runs_per_variant < 1 or config.training_seeds < 1 or (flags.workers is not None and flags.workers < 1):
        raise ExperimentSettingsError("--runs, --seeds and --workers must be >= 1")

    out = Path(flags.out)
    protocols = list(PROTOCOLS) if flags.protocol == ALL else [flags.protocol]
    flags.write_config(out, flags.protocol, protocol_config=asdict(config), deep_schedule=asdict(schedule))
    symbolic = [a for a in agents if a in SYMBOLIC_AGENTS]
    deep = [a for a in agents if a in DEEP_AGENTS]
    start = time.perf_counter()
    timings: dict[str, float] = {}
    results: dict[str, dict[str, Any]] = {}
    try:
        for protocol in protocols:
            t0 = time.perf_counter()
            results[protocol] = PROTOCOLS[protocol](symbolic, config, quick=flags.quick)
            timings[f"{protocol}: symbolic agents"] = time.perf_counter() - t0
        if deep:
            jobs = [job for protocol in protocols for job in jobs_for(protocol, deep, config, schedule, flags.poses)]
            records, summary = run_jobs(jobs, config, out, flags.workers, flags.ray)
            timings["deep agents (all their jobs)"] = summary["wall_time_s"]
            echo(f"deep agents: {summary['computed']} job(s) run, {summary['reused']} reused from {out}/jobs")
            for protocol in protocols:
                results[protocol] = merge_deep_points(results[protocol], deep, records, config, schedule, flags.poses)
                results[protocol]["deep_jobs"] = summary
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    total = time.perf_counter() - start
    for protocol, result in results.items():
        result["wall_time_s"] = total
        result["timings_s"] = timings
        echo(write_protocol(result, out, protocol))
    if flags.protocol == ALL:
        echo(write_all_protocols(results, timings, total, out))
    echo(f"{flags.protocol}: {total:.0f} s -> {out}/")


def write_protocol(result: dict[str, Any], out: Path, protocol: str) -> str:
    """``DIR/<protocol>.json``, ``.png`` and ``.md`` (every point, then ours beside the paper); the tables."""
    write_json(out / f"{protocol}.json", result)
    plot(result, out / f"{protocol}.png")
    tables = f"## {protocol}: all points (success / mean actions)\n\n{results_table(result)}\n\n"
    tables += f"## {protocol}: ours beside the paper\n\n{comparison_table(result)}\n"
    if protocol == "episodes":
        tables += f"\n## episodes to 100% on the unseen variants\n\n{episodes_to_solve_table(result)}\n"
    (out / f"{protocol}.md").write_text(tables)
    return tables


def write_all_protocols(results: dict[str, dict[str, Any]], timings: dict[str, float], total: float, out: Path) -> str:
    """``DIR/all.md``: the episodes-to-100 % table and the wall time of every part; its text."""
    lines = ["# All protocols", "", "## Episodes to 100% on the unseen variants", ""]
    lines += [episodes_to_solve_table(results["episodes"]), "", "## Wall time", "", "| part | s |", "|---|---|"]
    lines += [f"| {part} | {seconds:.0f} |" for part, seconds in timings.items()]
    lines += [f"| **total** | **{total:.0f}** |", ""]
    (out / "all.md").write_text("\n".join(lines))
    return "\n".join(lines)
