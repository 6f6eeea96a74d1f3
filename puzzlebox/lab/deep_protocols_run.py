"""The deep agents' protocol jobs (``puzzlebox.learning.experiments.deep_protocols``) on the task runner: each job
one task, its record ``OUT/jobs/<key>.json`` (its network ``<key>.pt`` beside it) written the moment it ends, so an
interrupted run resumes where it stopped and a job file made with other settings is recomputed, never mixed in."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from puzzlebox.lab.runner import RecordStore, Task, make_executor, run_tasks
from puzzlebox.learning.experiments.deep_protocols import TrainingJob, job_settings, run_job_task
from puzzlebox.learning.experiments.protocol import ProtocolConfig


def job_task(job: TrainingJob, config: ProtocolConfig, out_dir: Path) -> Task:
    """The runner task of ``job``: its record is ``OUT/jobs/<key>.json``, its network ``<key>.pt``."""
    settings = json.loads(json.dumps(job_settings(job, config)))
    # run_job_task stays in the learning layer: its module and name are part of the settings' hash, so the job
    # files written before the runner moved are still reused
    return Task(job.key, run_job_task, settings, context={"out_dir": str(out_dir)})


def cached_record(job: TrainingJob, config: ProtocolConfig, out_dir: Path) -> dict[str, Any] | None:
    """The finished record of ``job`` in ``out_dir`` if it was made with the same settings."""
    return RecordStore(Path(out_dir) / "jobs").get(job_task(job, config, out_dir))


def run_jobs(
    jobs: Sequence[TrainingJob],
    config: ProtocolConfig,
    out_dir: Path,
    workers: int | None = None,
    ray: str | None = None,
) -> tuple[dict[str, dict[str, Any]], dict[str, Any]]:
    """Run (or reuse) every job on the task runner — ``workers`` processes (default: one per core; 1:
    in-process) or Ray (``ray``: ``auto`` or an address) — longest first. Returns the records by job key
    and a summary (reused, computed, wall time [s]).

    Raises:
        LearningError: a job failed (after every other job finished and was kept).
    """
    unique = sorted(
        {job.key: job for job in jobs}.values(), key=lambda j: (-j.episodes, j.agent.startswith("model"), j.key)
    )
    tasks = [job_task(job, config, out_dir) for job in unique]
    with make_executor(workers, ray) as executor:
        report = run_tasks(
            tasks, RecordStore(Path(out_dir) / "jobs"), executor, desc=f"deep agents ({len(tasks)} jobs)"
        )
    report.raise_for_failures("deep job")
    summary = {
        "jobs": len(tasks),
        "reused": len(report.reused),
        "computed": len(report.computed),
        "workers": executor.workers,
        "wall_time_s": report.wall_time_s,
    }
    return report.records, summary
