"""The disassembly experiment (``puzzlebox.learning.experiments.disassembly``) on the task runner: each (curve,
training seed) job one task, its record ``OUT/records/<key>.json`` written the moment it ends, so an interrupted
run resumes where it stopped; the seeds pooled into the summary."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from puzzlebox.lab.runner import RecordStore, Task, make_executor, run_tasks
from puzzlebox.learning.experiments.disassembly import DisassemblyConfig, jobs_for, scenes, summarise
from puzzlebox.models import PuzzleSpec


def tasks_for(
    agents: Sequence[str], config: DisassemblyConfig, scenes_: tuple[PuzzleSpec, list[PuzzleSpec]] | None = None
) -> list[Task]:
    """Every (curve, training seed) task of the experiment (``scenes_``: :func:`scenes` of ``config``, if made).
    The job functions stay in the learning layer: their module and name are part of each record's settings hash."""
    return [Task(job.key, job.function, job.settings) for job in jobs_for(agents, config, scenes_)]


def run_disassembly(out: Path, agents: Sequence[str], config: DisassemblyConfig, workers: int | None = None,
                    ray: str | None = None) -> dict[str, Any]:  # fmt: skip
    """Run (or resume) the experiment into ``out`` — ``workers`` processes (default: one per core; 1: in-process)
    or Ray (``ray``: ``auto`` or an address); returns the summary (``experiment.py`` writes it as
    ``out/disassembly.json``) with the wall time [s] and the tasks computed and reused.

    Raises:
        LearningError: a task failed (every other one is kept for the resume) or the run was interrupted.
    """
    start = time.perf_counter()
    train, tests = scenes(config)
    tasks = tasks_for(agents, config, (train, tests))
    with make_executor(workers, ray) as executor:
        report = run_tasks(tasks, RecordStore(out / "records"), executor, desc="disassembly")
    report.raise_for_failures()
    summary = summarise(report.records, config, tests)
    summary.update({"wall_time_s": time.perf_counter() - start, "config": asdict(config), "agents": list(agents),
                    "tasks": {"computed": len(report.computed), "reused": len(report.reused)}})  # fmt: skip
    return summary
