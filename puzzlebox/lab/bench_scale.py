"""Scale figures for ``bench.py``: twin trials per hour on one worker, on a local process pool and on a local
Ray cluster (the same oracle trials, one after the other in one run, so their ratios hold on a noisy machine),
and the per-task overhead of each executor on no-op tasks."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Mapping
from typing import Any

from puzzlebox.lab.runner import Executor, InlineExecutor, PoolExecutor, RayExecutor, Task
from puzzlebox.lab.trial_task import trial_task


def noop(settings: Mapping[str, Any]) -> dict[str, Any]:
    """A task that does nothing: what is left of its wall time is the executor's overhead."""
    return {"seed": settings["seed"]}


def _executors(workers: int) -> dict[str, Callable[[], Executor]]:
    return {
        "one worker": InlineExecutor,
        f"pool ({workers} workers)": lambda: PoolExecutor(workers),
        f"ray local ({workers} CPUs)": lambda: RayExecutor("auto", num_cpus=workers),
    }


def _timed(executor: Executor, tasks: list[Task]) -> tuple[float, int]:
    """Wall time [s] to run ``tasks`` on an entered executor (start-up excluded) and how many succeeded."""
    start = time.perf_counter()
    ok = sum(done.ok for done in executor.run(tasks, lambda: False))
    return time.perf_counter() - start, ok


def overhead_ms(tasks: int = 200, workers: int | None = None) -> dict[str, float]:
    """Milliseconds per no-op task on each executor (its start-up excluded), after a warm-up batch."""
    workers = workers or os.cpu_count() or 1
    noops = [Task(f"noop{i}", noop, {"seed": i}) for i in range(tasks)]
    out = {}
    for name, make in _executors(workers).items():
        with make() as executor:
            _timed(executor, noops[: 2 * workers])  # workers started and warm
            wall, _ = _timed(executor, noops)
        out[name] = 1000.0 * wall / tasks
    return out


def twin_throughput(trials: int = 40, workers: int | None = None) -> dict[str, Any]:
    """Twin trials per hour (oracle agent on the paper test boxes, ``ideal``, one per seed) on each executor,
    two ways: ``trials_per_hour`` start-up included (a worker's first trial pays its imports and scene build,
    as a user's run does; Ray's start-up is seconds) and ``warm_trials_per_hour``, the ``trials`` timed after
    one warm-up trial per worker (what a long sweep sees: start-up spread over thousands of trials)."""
    from puzzlebox.models.generator import paper_family

    workers = workers or os.cpu_count() or 1
    specs = paper_family("test")
    warm_up = [trial_task(f"w{k}", specs[k % len(specs)], 10_000 + k, sim="twin", agent="oracle", max_actions=30)
               for k in range(workers)]  # fmt: skip
    tasks = [trial_task(f"t{k}", specs[k % len(specs)], k, sim="twin", agent="oracle", max_actions=30)
             for k in range(trials)]  # fmt: skip
    figures: dict[str, Any] = {"trials": trials, "workers": workers}
    for name, make in _executors(workers).items():
        # the warm-up runs one trial per worker at once (pool and Ray hand one task to each idle worker)
        n_warm = 1 if name == "one worker" else workers
        start = time.perf_counter()
        with make() as executor:
            _timed(executor, warm_up[:n_warm])
            warm_wall, ok = _timed(executor, tasks)
        wall = time.perf_counter() - start
        figures[name] = {
            "wall_s": wall, "warm_wall_s": warm_wall, "solved": ok,
            "trials_per_hour": 3600.0 * (trials + n_warm) / wall, "warm_trials_per_hour": 3600.0 * trials / warm_wall,
        }  # fmt: skip
    for key in ("trials_per_hour", "warm_trials_per_hour"):
        one = figures["one worker"][key]
        for name in list(figures):
            if isinstance(figures[name], dict) and name != "one worker":
                figures[name][key.replace("trials_per_hour", "speedup_over_one_worker")] = figures[name][key] / one
    return figures
