"""A batch of trials as ``trial.py`` runs it: every spec x ``runs`` seeds as runner tasks, executed in-process, in a
worker pool or on Ray, each record kept the moment it ends (:class:`~puzzlebox.lab.run_store.RunStore`), the
summary rewritten as they come and at the end."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tqdm import tqdm

from puzzlebox.lab import trial_task
from puzzlebox.lab.inputs import MAX_ACTIONS, MAX_TASKS, MAX_WORKERS, InputError, check_count, check_seed
from puzzlebox.lab.interrupt import StopRequests
from puzzlebox.lab.run_store import Periodic, RunStore
from puzzlebox.lab.runner import Executor, InlineExecutor, RunReport, run_tasks
from puzzlebox.lab.trial_figures import twin_figures
from puzzlebox.learning import summarise
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.names import name_slug
from puzzlebox.twin.reality import RealityProfile

__all__ = ["InputError", "TrialBatch", "batch_results", "check_batch_numbers", "run_batch", "summary_lines"]


@dataclass(frozen=True)
class TrialBatch:
    """Trials of one agent on ``specs``: run ``r`` of every spec uses seed ``seed + r``.

    ``video``: a rollout video per run (``rollout.mp4`` for a single run, else ``rollout-<spec>-s<seed>.mp4``, in
    the output directory); ``record``: a Rerun recording per run (``FILE.rrd`` for one, else
    ``FILE-<spec>-s<seed>.rrd``); ``state_log``: each run's state at every control tick, ``states/<run key>.npz``
    in the output directory (:mod:`puzzlebox.lab.state_log`). The other fields are
    :func:`puzzlebox.lab.trial_task.trial_task`'s."""

    specs: tuple[PuzzleSpec, ...]
    runs: int
    seed: int
    sim: str
    agent: str
    max_actions: int
    memory: str | None = None
    checkpoint: str | None = None
    reality: RealityProfile | None = None
    calibration: CellCalibration | None = None
    video: bool = False
    record: str | None = None
    misreport_kind: bool = False
    max_lockers: int | None = None
    locks: str = "contact"
    state_log: bool = False

    def tasks(self, out: Path) -> list:
        """One runner task per spec and seed, keyed ``<spec index>-<spec slug>-seed<seed>`` (the slug of a name:
        :func:`~puzzlebox.models.names.name_slug`; so are the video and recording files named)."""
        tasks = []
        single = len(self.specs) * self.runs == 1
        for i, spec in enumerate(self.specs):
            slug = name_slug(spec.name)
            for r in range(self.runs):
                seed = self.seed + r
                video = record = None
                if self.video:
                    video = str((out / ("rollout.mp4" if single else f"rollout-{slug}-s{seed}.mp4")).resolve())
                if self.record:
                    path = Path(self.record)
                    record = str(path.resolve() if single else path.with_name(f"{path.stem}-{slug}-s{seed}.rrd"))
                key = f"{i:03d}-{slug}-seed{seed}"
                states = str((out / "states" / f"{key}.npz").resolve()) if self.state_log else None
                tasks.append(trial_task.trial_task(
                    key, spec, seed, sim=self.sim, agent=self.agent,
                    max_actions=self.max_actions, memory=self.memory, checkpoint=self.checkpoint,
                    reality=self.reality.to_dict() if self.reality is not None else None,
                    calibration=self.calibration.to_dict() if self.calibration is not None else None, video=video,
                    misreport_kind=self.misreport_kind, max_lockers=self.max_lockers, record=record,
                    locks=self.locks, state_log=states,
                ))  # fmt: skip
        return tasks


def check_batch_numbers(specs: int, runs: int, seed: int, max_actions: int, workers: int | None = None) -> None:
    """``trial.py``'s numbers, before any work: ``runs`` per spec (``specs`` x ``runs`` trials at most
    :data:`~puzzlebox.lab.inputs.MAX_TASKS`), seeds ``seed``..``seed + runs - 1``, the action budget and the worker
    count each in its range (:class:`~puzzlebox.lab.inputs.InputError` naming the flag)."""
    check_count(runs, "--runs", MAX_TASKS // max(specs, 1))
    check_count(max_actions, "--max-actions", MAX_ACTIONS)
    check_seed(seed, "--seed", runs)
    if workers is not None:
        check_count(workers, "--workers", MAX_WORKERS)


def batch_results(runs: Sequence[dict[str, Any]], batch: TrialBatch, planned: int) -> dict[str, Any]:
    """``results.json``: the contract's summary (:func:`puzzlebox.learning.summarise`), the twin's figures, and
    ``runs_done`` of ``runs_planned``."""
    results = summarise(list(runs), batch.max_actions)
    if batch.sim == "twin" and runs:  # (no figures of no run)
        results.update(twin_figures(list(runs)))
    results["runs_done"], results["runs_planned"] = len(runs), planned
    return results


class _ActionBar:
    """The inner progress bar of an in-process trial: one tick per action, a new bar per run."""

    def __init__(self, max_actions: int) -> None:
        self.max_actions, self.bar = max_actions, None

    def start(self, name: str) -> None:
        self.close()
        self.bar = tqdm(total=self.max_actions, desc=f"  {name}", unit="action", leave=False, disable=None)

    def __call__(self, _action) -> None:
        if self.bar is not None:
            self.bar.update()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


def run_batch(batch: TrialBatch, store: RunStore, executor: Executor) -> tuple[RunReport, dict[str, Any]]:
    """Run ``batch`` on ``executor`` into ``store`` (skipping runs it holds; SIGINT or SIGTERM stops after the
    current run, twice at once); returns the runner's report and the final ``results.json``, written."""
    tasks = batch.tasks(store.out)
    found: dict[str, dict] = {}
    keys = [t.key for t in tasks]
    summary = Periodic(lambda: store.write_results(batch_results([found[k] for k in keys if k in found], batch,
                                                                  len(tasks))))  # fmt: skip

    def keep(task, record) -> None:
        found[task.key] = record
        summary()

    def solved(records: dict[str, dict]) -> str:
        return f"solved {sum(r['solved'] for r in records.values())}/{len(records)}"

    with store.keeping(), StopRequests("run") as stop, executor:  # a full disk: one line, what is kept
        inner = isinstance(executor, InlineExecutor)  # per-action bars only where the trial runs here
        trial_task.set_action_hook(_ActionBar(batch.max_actions) if inner else None)
        report = run_tasks(tasks, store.records, executor, stop=lambda: stop.requested, on_record=keep,
                           postfix=solved, desc=f"{batch.agent} {batch.sim} trials")  # fmt: skip
    results = batch_results(list(report.records.values()), batch, len(tasks))
    store.write_results(results)
    return report, results


def summary_lines(results: dict[str, Any], batch: TrialBatch, out: Path) -> list[str]:
    """What ``trial.py`` prints when a batch ends: success and actions, and the twin's figures."""
    if not results["runs"]:
        return [f"{batch.agent} on {len(batch.specs)} spec(s) x {batch.runs} run(s): no run finished -> "
                f"{out / 'results.json'}"]  # fmt: skip
    lines = [
        f"{batch.agent} on {len(batch.specs)} spec(s) x {batch.runs} run(s): success {results['success_rate']:.1%}, "
        f"mean actions {results['mean_actions']:.2f} -> {out / 'results.json'}"
    ]
    if batch.sim == "twin":
        lines.append(
            f"outcome agreement {results['outcome_agreement']:.1%} over {results['actions_total']} actions; "
            f"perceived position error max {1000 * results['perceived_position_error_max_m']:.1f} mm; "
            f"wall time per trial max {results['wall_time_per_trial_s_max']:.1f} s; "
            f"simulated/wall x{results['sim_over_wall']:.1f}; "
            f"peak true wrist force {results['peak_true_wrist_force_n']:.0f} N"
        )
        lines += [f"unsolved: {line}" for line in results["unsolved_reasons"]]
    return lines
