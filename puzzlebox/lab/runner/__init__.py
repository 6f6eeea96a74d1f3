"""The task runner: executes pure, seeded, picklable tasks in-process, in a local process pool or on a
Ray cluster, writes each task's record atomically the moment it ends, and on a rerun computes only what
is missing. It knows nothing of what a task does (DESIGN.md: composing a trial is the composition layer's,
``puzzlebox.lab``).

Example::

    tasks = [Task(f"seed{s}", my_module.run_one, {"seed": s}) for s in range(40)]
    with make_executor(workers=2) as executor:
        report = run_tasks(tasks, RecordStore(out / "runs"), executor)
"""

from puzzlebox.lab.runner.errors import RunnerError
from puzzlebox.lab.runner.executors import (
    Completion,
    Executor,
    InlineExecutor,
    PoolExecutor,
    RayExecutor,
    make_executor,
)
from puzzlebox.lab.runner.records import RecordStore
from puzzlebox.lab.runner.run import RunReport, run_tasks
from puzzlebox.lab.runner.task import Task

__all__ = [
    "Completion",
    "Executor",
    "InlineExecutor",
    "PoolExecutor",
    "RayExecutor",
    "RecordStore",
    "RunReport",
    "RunnerError",
    "Task",
    "make_executor",
    "run_tasks",
]
