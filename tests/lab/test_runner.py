"""The task runner: the same task gives the same record on every executor, a rerun computes only what is
missing, a task's error is reported under its key without losing the others, a dead worker is replaced."""

from __future__ import annotations

import json
import threading

import pytest
import runner_tasks

from puzzlebox.lab.runner import (
    InlineExecutor,
    PoolExecutor,
    RayExecutor,
    RecordStore,
    RunnerError,
    RunReport,
    Task,
    run_tasks,
)
from puzzlebox.learning.errors import LearningError


def _tasks(n, function=runner_tasks.draws, **extra):
    return [Task(f"seed{s}", function, {"seed": s, **extra}) for s in range(n)]


def test_tasks_refuse_what_cannot_run_anywhere():
    with pytest.raises(RunnerError, match="not a file name"):
        Task("../escape", runner_tasks.draws)
    with pytest.raises(RunnerError, match="not a module-level function"):
        Task("a", lambda s: {})
    with pytest.raises(RunnerError, match="not JSON"):
        Task("a", runner_tasks.draws, {"x": object()})
    with pytest.raises(RunnerError, match="repeated"):
        run_tasks([Task("a", runner_tasks.noop), Task("a", runner_tasks.noop)], RecordStore("unused"), InlineExecutor())


def test_settings_define_a_task_and_its_hash():
    a, b = Task("k", runner_tasks.draws, {"seed": 1, "x": 2}), Task("k", runner_tasks.draws, {"x": 2, "seed": 1})
    assert a.settings_hash == b.settings_hash, "key order does not matter"
    assert a.settings_hash != Task("k", runner_tasks.draws, {"seed": 2, "x": 2}).settings_hash
    assert a.settings_hash != Task("k", runner_tasks.noop, {"seed": 1, "x": 2}).settings_hash


def test_the_same_tasks_give_the_same_records_in_process_in_the_pool_and_on_ray(tmp_path):
    tasks = _tasks(8)
    records = {}
    executors = {"inline": InlineExecutor(), "pool": PoolExecutor(2), "ray": RayExecutor("auto", num_cpus=2)}
    for name, executor in executors.items():
        with executor:
            report = run_tasks(tasks, RecordStore(tmp_path / name), executor)
        assert not report.failures and not report.stopped and len(report.computed) == 8
        assert list(report.records) == [t.key for t in tasks], "records come back in task order"
        records[name] = report.records
    assert records["inline"] == records["pool"] == records["ray"]
    on_disk = json.loads((tmp_path / "pool" / "seed3.json").read_text())
    assert on_disk["record"] == records["inline"]["seed3"] and on_disk["settings_sha256"] == tasks[3].settings_hash


def test_a_rerun_computes_only_missing_tasks_and_recomputes_changed_settings(tmp_path):
    store = RecordStore(tmp_path)
    with InlineExecutor() as executor:
        first = run_tasks(_tasks(5), store, executor)
        assert len(first.computed) == 5
        again = run_tasks(_tasks(8), store, executor)
        assert again.reused == [f"seed{s}" for s in range(5)] and again.computed == ["seed5", "seed6", "seed7"]
        changed = [Task(t.key, t.function, {**t.settings, "variant": 1}) for t in _tasks(8)]
        redone = run_tasks(changed, store, executor)
        assert len(redone.computed) == 8 and not redone.reused, "a record made with other settings is not mixed in"
    assert sorted(store.keys()) == sorted(f"seed{s}" for s in range(8)), "each task has exactly one record"


def test_a_task_error_is_reported_with_its_key_and_the_others_are_kept(tmp_path):
    for executor in (InlineExecutor(), PoolExecutor(2)):
        store = RecordStore(tmp_path / executor.name)
        with executor:
            report = run_tasks(_tasks(6, runner_tasks.fails_on_three), store, executor)
        assert list(report.failures) == ["seed3"]
        assert report.failures["seed3"].startswith("ValueError: seed 3 is cursed")
        assert "Traceback" in report.failures["seed3"], "the task's traceback is kept for whoever debugs it"
        assert sorted(report.records) == sorted(f"seed{s}" for s in (0, 1, 2, 4, 5)) == sorted(store.keys())


def test_a_killed_worker_is_replaced_and_its_task_run_again(tmp_path):
    tasks = [Task(f"seed{s}", runner_tasks.dies_once, {"seed": s, "flag": str(tmp_path / f"flag{s}")})
             for s in range(4)]  # fmt: skip
    for s in (0, 1, 3):  # only seed 2 kills its worker
        (tmp_path / f"flag{s}").write_text("already died")
    with PoolExecutor(2) as executor:
        report = run_tasks(tasks, RecordStore(tmp_path / "runs"), executor)
        assert executor.restarts >= 1
    assert not report.failures and len(report.records) == 4
    assert report.records["seed2"] == runner_tasks.draws({"seed": 2})


def test_a_task_that_always_kills_its_worker_fails_alone(tmp_path):
    tasks = _tasks(2) + [Task("killer", runner_tasks.always_dies, {"seed": 9})] + _tasks(5)[2:]
    with PoolExecutor(2, max_attempts=2) as executor:
        report = run_tasks(tasks, RecordStore(tmp_path / "runs"), executor)
    assert set(report.records) == {f"seed{s}" for s in range(5)}, "tasks that shared the pool with it are kept"
    assert list(report.failures) == ["killer"] and report.failures["killer"].startswith("WorkerDied")
    with pytest.raises(LearningError, match="^1 task\\(s\\) failed, the others kept; killer: WorkerDied"):
        report.raise_for_failures()


def test_a_complete_report_raises_nothing_and_a_stopped_one_says_what_it_kept():
    done = RunReport(records={"a": {}}, planned=1)
    done.raise_for_failures()
    stopped = RunReport(records={"a": {}}, planned=3, stopped=True)
    with pytest.raises(LearningError, match="interrupted: 1 finished deep job\\(s\\) kept"):
        stopped.raise_for_failures("deep job")


def test_a_stop_request_keeps_what_finished_and_a_rerun_completes_it(tmp_path):
    store = RecordStore(tmp_path)
    tasks = _tasks(6, runner_tasks.sleeps, seconds=0.2)
    stop = threading.Event()
    with PoolExecutor(2) as executor:
        report = run_tasks(tasks, store, executor, stop=stop.is_set, on_record=lambda task, record: stop.set())
    assert report.stopped and 1 <= len(report.records) < 6 and report.missing == 6 - len(report.records)
    assert sorted(store.keys()) == sorted(report.records)
    with InlineExecutor() as executor:
        rest = run_tasks(tasks, store, executor)
    assert not rest.stopped and len(rest.computed) == 6 - len(report.records) and len(rest.records) == 6
