"""Run a list of tasks on an executor: reuse the records already stored, compute the rest, store each
record the moment it arrives, show progress, and keep everything finished when stopped or interrupted."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from tqdm import tqdm

from puzzlebox.lab.runner.errors import RunnerError
from puzzlebox.lab.runner.executors import Executor
from puzzlebox.lab.runner.records import RecordStore
from puzzlebox.lab.runner.task import Task
from puzzlebox.learning.errors import LearningError


@dataclass
class RunReport:
    """What a call of :func:`run_tasks` did.

    Attributes:
        records: every finished task's record by key, in the order of the task list.
        reused: keys whose record was already stored (same settings).
        computed: keys computed by this call.
        failures: key -> error text (first line: ``Type: message``) of every task that raised.
        stopped: a stop request or an interrupt left tasks undone.
        wall_time_s: duration of the call [s].
        planned: tasks in the list.
    """

    records: dict[str, dict[str, Any]] = field(default_factory=dict)
    reused: list[str] = field(default_factory=list)
    computed: list[str] = field(default_factory=list)
    failures: dict[str, str] = field(default_factory=dict)
    stopped: bool = False
    wall_time_s: float = 0.0
    planned: int = 0

    def raise_for_failures(self, what: str = "task") -> None:
        """Raise :class:`~puzzlebox.learning.errors.LearningError` (one line: how many ``what``s failed, the first
        one's key and error) if a task failed, or if a stop left tasks undone; the finished records are kept either
        way."""
        if self.failures:
            key, error = next(iter(self.failures.items()))
            first = error.splitlines()[0]
            raise LearningError(f"{len(self.failures)} {what}(s) failed, the others kept; {key}: {first}")
        if self.stopped:
            raise LearningError(f"interrupted: {len(self.records)} finished {what}(s) kept; run the same command again")

    @property
    def missing(self) -> int:
        """Tasks with neither a record nor a failure (left undone by a stop)."""
        return self.planned - len(self.records) - len(self.failures)


def run_tasks(
    tasks: Sequence[Task],
    store: RecordStore,
    executor: Executor,
    *,
    stop: Callable[[], bool] = lambda: False,
    on_record: Callable[[Task, dict[str, Any]], None] | None = None,
    postfix: Callable[[dict[str, dict[str, Any]]], str] | None = None,
    desc: str = "tasks",
) -> RunReport:
    """Execute every task of ``tasks`` that ``store`` lacks on ``executor`` (already entered).

    Each record is stored atomically as it arrives, then ``on_record(task, record)`` is called (e.g. to
    rewrite a summary). A task's exception is reported in :attr:`RunReport.failures` under its key and
    the others go on. ``stop()`` true: no new task starts, those in flight finish and are kept. Ctrl-C
    (:class:`KeyboardInterrupt`) abandons the tasks in flight and returns what finished, ``stopped`` set.

    Raises:
        RunnerError: two tasks share a key.
    """
    start = time.perf_counter()
    keys = [t.key for t in tasks]
    duplicates = sorted({k for k in keys if keys.count(k) > 1})
    if duplicates:
        raise RunnerError(f"task keys must be unique; repeated: {duplicates[:5]}")
    report = RunReport(planned=len(tasks))
    found: dict[str, dict[str, Any]] = {}
    todo = []
    for task in tasks:
        record = store.get(task)
        if record is None:
            todo.append(task)
        else:
            found[task.key] = record
            report.reused.append(task.key)
    store.remove_stale()
    where = f"{executor.name}, {executor.workers} worker(s)" if executor.workers > 1 else executor.name
    bar = tqdm(total=len(tasks), initial=len(found), desc=f"{desc} ({where})", unit="task", disable=None)
    if postfix is not None:
        bar.set_postfix_str(postfix(found))
    try:
        for done in executor.run(todo, stop):
            if done.ok:
                store.put(done.task, done.payload)
                found[done.task.key] = done.payload
                report.computed.append(done.task.key)
                if on_record is not None:
                    on_record(done.task, done.payload)
            else:
                report.failures[done.task.key] = str(done.payload)
                bar.write(f"task {done.task.key} failed: {str(done.payload).splitlines()[0]}")
            bar.update()
            if postfix is not None:
                bar.set_postfix_str(postfix(found))
    except KeyboardInterrupt:
        report.stopped = True
    finally:
        bar.close()
    report.records = {k: found[k] for k in keys if k in found}
    report.stopped = report.stopped or report.missing > 0
    report.wall_time_s = time.perf_counter() - start
    return report
