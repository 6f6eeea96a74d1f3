"""``experiment.py hard-sets``: the memory agent end to end in the twin on the hard test sets (issue 36's grid).

The test boxes are the first ``boxes`` of each hard family of :mod:`puzzlebox.lab.hard_sets` (eight parts of every
kind: random, multi-locker, chains) from seed ``test_seed`` on, each tried at ``placements`` random reachable poses
(world seeds ``eval_seed + p``); the multi-locker boxes with a belief over sets of up to two lockers. ``--seed S``
draws fresh ones: boxes from seed S, placements from S + 100 (the defaults, 36000 and 36100, are the boxes the
development looked at). The agent's memory is the twin-learning ``symbolic`` start
(:mod:`puzzlebox.lab.twin_learning`): one symbolic episode on each of ``train_boxes`` generated training boxes per
family (other seeds: held out), or a memory given with ``--memory``. Every trial runs twice (``calibrations``):
with the profile's cell calibrated from ChArUco images first, and without a calibration file (the nominal cell).

Every step is a task of :mod:`puzzlebox.lab.runner` whose record is kept the moment it ends (``DIR/calibrations/``,
``DIR/memory/``, ``DIR/trials/``): the same command resumes. The summary, ``DIR/hard-sets.{json,md,png}``: per
cell (with and without the calibration), per family and over all, trials solved, mean actions (an unsolved trial
counts the budget), the boxes' optimum and the ratio to it, the peak true wrist force and the runs above the force
margin (45 N), the outcome agreement (sensed moved / not moved against the simulator's truth) and why each unsolved
run ended.
"""

from __future__ import annotations

import dataclasses
import os
import statistics
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from puzzlebox.lab.cli import write_json
from puzzlebox.lab.hard_sets import HardSetConfig
from puzzlebox.lab.learning_boxes import LearningBox, test_boxes, training_boxes
from puzzlebox.lab.reality_sweep import calibrated_cell
from puzzlebox.lab.runner import RecordStore, Task, make_executor, run_tasks
from puzzlebox.lab.trial_figures import twin_figures
from puzzlebox.lab.trial_task import file_sha256, trial_task
from puzzlebox.lab.twin_learning import symbolic_training
from puzzlebox.learning import summarise
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models.spec_loading import spec_from_dict
from puzzlebox.twin.reality import load_profile

FORCE_MARGIN_N = 45.0
"""Issue 36's force margin: no try should pass this true wrist force [N] (the guard's limit stays 60 N)."""


CALIBRATIONS = ("calibrated", "uncalibrated")
"""The cells a trial may run in: with the profile's cell calibrated first, and without a calibration file."""


@dataclass(frozen=True)
class HardGridConfig:
    """What ``experiment.py hard-sets`` runs."""

    profile: str = "realistic"
    """The reality profile of the cell (``--profile``)."""
    boxes: int = 20
    """Test boxes of each hard family (``--boxes``)."""
    placements: int = 2
    """Random reachable placements of each test box (``--runs``)."""
    train_boxes: int = 40
    """Training boxes of each family in the symbolic memory (each once), as in ``twin-learning --test-set hard``."""
    train_seed: int = 0
    """Seed of the symbolic training (the twin-learning ``symbolic`` start of that seed)."""
    test_seed: int = 36_000
    """Seed of test box 0 of every family (box ``i``: ``test_seed + i``; ``--seed``)."""
    eval_seed: int = 36100
    """World seed of placement ``p``: ``eval_seed + p`` (``--seed S``: S + 100)."""
    calibrations: tuple[str, ...] = CALIBRATIONS
    """Which cells every trial runs in: ``calibrated`` (the profile's cell calibrated first) and/or
    ``uncalibrated`` (no calibration file: the nominal cell) (``--calibration``)."""
    max_actions: int = 40
    """Action budget of a trial (a chain of 8 takes 8 at best)."""

    def __post_init__(self) -> None:
        unknown = [c for c in self.calibrations if c not in CALIBRATIONS]
        if unknown or not self.calibrations or len(set(self.calibrations)) < len(self.calibrations):
            raise ValueError(
                f"calibrations must be distinct ones of {list(CALIBRATIONS)}, got {list(self.calibrations)}"
            )
        HardSetConfig(test_seed=self.test_seed, train_seed=0)  # the test seeds never meet the training ones

    def with_seed(self, seed: int) -> HardGridConfig:
        """Fresh test boxes and placements: boxes from ``seed``, placements' world seeds from ``seed + 100``."""
        return dataclasses.replace(self, test_seed=seed, eval_seed=seed + 100)

    def quick(self) -> HardGridConfig:
        """CI size: one box of each family at one placement, 2 training boxes of each family, 16 actions."""
        return dataclasses.replace(self, boxes=1, placements=1, train_boxes=2, max_actions=16)


def memory_task(settings: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """The symbolic memory (a runner task): ``settings['episodes']`` episodes on the training boxes, written to
    ``context['dir']/memory-s<seed>.sqlite`` through a temporary file, so a killed task leaves no half memory."""
    folder = Path(context["dir"])
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / f"memory-s{settings['seed']}.sqlite"
    partial = folder / f".{target.name}.partial"
    partial.unlink(missing_ok=True)
    train = [spec_from_dict(d) for d in settings["train"]]
    store = MemoryStore(partial)
    try:
        symbolic_training(store, settings["seed"], len(train), settings["max_actions"], train,
                          settings["train_max_lockers"])  # fmt: skip
        episodes = store.num_episodes
    finally:
        store.close()
    os.replace(partial, target)
    return {"memory": target.name, "episodes": episodes, "sha256": file_sha256(target)}


def run_hard_grid(
    out: Path, config: HardGridConfig, memory: Path | None = None, workers: int | None = None, ray: str | None = None
) -> dict[str, Any]:
    """Run (or resume) the grid into ``out``; returns the summary written to ``out/hard-sets.json``.

    Raises:
        LearningError: a task failed (every other one is kept for the resume).
    """
    out.mkdir(parents=True, exist_ok=True)
    reality = load_profile(config.profile)
    tests = test_boxes("hard", config.boxes, out / "specs", HardSetConfig(test_seed=config.test_seed))
    begin = time.perf_counter()
    phases: dict[str, float] = {}
    with make_executor(workers, ray) as executor:
        calibration = None
        if "calibrated" in config.calibrations:
            calibration = calibrated_cell(reality, out / "calibrations", executor)
            phases["calibration_s"] = time.perf_counter() - begin
        memory_path = memory
        if memory_path is None:
            train = training_boxes("hard", config.train_boxes, out / "specs")
            task = Task(f"memory-s{config.train_seed}", memory_task, {
                "seed": config.train_seed, "max_actions": config.max_actions,
                "train": [b.spec.to_dict() for b in train], "train_max_lockers": [b.max_lockers for b in train],
            }, context={"dir": str(out / "memory")})  # fmt: skip
            trained = run_tasks([task], RecordStore(out / "memory" / "records"), executor, desc="symbolic memory")
            trained.raise_for_failures()
            memory_path = out / "memory" / trained.records[task.key]["memory"]
        phases["memory_s"] = time.perf_counter() - begin - sum(phases.values())
        cells = {
            cell: [
                trial_task(
                    f"{box.spec.name}-p{p}" + ("" if cell == "calibrated" else f"-{cell}"),
                    box.spec,
                    config.eval_seed + p,
                    sim="twin",
                    agent="memory",
                    max_actions=config.max_actions,
                    memory=str(memory_path),
                    reality=reality.to_dict(),
                    calibration=calibration if cell == "calibrated" else None,
                    max_lockers=box.max_lockers,
                )  # fmt: skip
                for box in tests
                for p in range(config.placements)
            ]
            for cell in config.calibrations
        }
        trials = [t for cell in cells.values() for t in cell]
        measured = run_tasks(trials, RecordStore(out / "trials"), executor, desc="hard-set trials",
                             postfix=lambda r: f"solved {sum(x['solved'] for x in r.values())}/{len(r)}")  # fmt: skip
        measured.raise_for_failures()
        phases["trials_s"] = time.perf_counter() - begin - sum(phases.values())
    runs = {cell: [measured.records[t.key] for t in tasks] for cell, tasks in cells.items()}
    summary = summarise_grid(config, reality.name, runs, tests)
    summary["memory"] = {"path": str(memory_path), "sha256": file_sha256(memory_path)}
    summary["wall_time_s"] = time.perf_counter() - begin
    summary["wall_time_by_phase_s"] = phases
    write_json(out / "hard-sets.json", summary)
    (out / "hard-sets.md").write_text(markdown(summary))
    plot(summary, out / "hard-sets.png")
    return summary


def summarise_grid(
    config: HardGridConfig,
    profile: str,
    runs: dict[str, list[dict[str, Any]]] | list[dict[str, Any]],
    tests: list[LearningBox],
) -> dict[str, Any]:
    """Per cell (``runs``: the records of each of ``config.calibrations``; a list: calibrated), per family and over
    all (``rows``, each cell's last one ``all``; each row names its ``calibration``): the figures of the module
    docstring."""
    by_cell = runs if isinstance(runs, dict) else {"calibrated": runs}
    best = {b.spec.name: b for b in tests}
    families = list(dict.fromkeys(b.family for b in tests))
    rows = []
    for cell, records in by_cell.items():
        rows += [_row(f, [r for r in records if best[r["spec"]].family == f], best, config.max_actions)
                 for f in families]  # fmt: skip
        rows.append(_row("all", records, best, config.max_actions))
        for row in rows[-len(families) - 1 :]:
            row["calibration"] = cell
    return {"config": dataclasses.asdict(config), "profile": profile, "rows": rows,
            "test_boxes": [{"spec": b.spec.name, "family": b.family, "optimum": b.optimum,
                            "max_lockers": b.max_lockers} for b in tests]}  # fmt: skip


def _row(name: str, runs: list[dict[str, Any]], best: dict[str, LearningBox], max_actions: int) -> dict[str, Any]:
    figures, results = twin_figures(runs), summarise(list(runs), max_actions)  # (unsolved: max_actions)
    optimum = statistics.fmean(best[r["spec"]].optimum for r in runs)
    return {
        "set": name,
        "trials": len(runs),
        "solved": sum(r["solved"] for r in runs),
        "success_rate": results["success_rate"],
        "mean_actions": results["mean_actions"],
        "optimum": optimum,
        "ratio_to_optimum": results["mean_actions"] / optimum,
        "peak_true_wrist_force_n": figures["peak_true_wrist_force_n"],
        "runs_over_margin": sum(r["peak_true_wrist_force_n"] > FORCE_MARGIN_N for r in runs),
        "outcome_agreement": figures["outcome_agreement"],
        "actions_total": figures["actions_total"],
        "unsolved_reasons": figures["unsolved_reasons"],
    }


def markdown(summary: dict[str, Any]) -> str:
    config = summary["config"]
    lines = [
        "# The hard test sets in the twin",
        "",
        f"The memory agent end to end in the twin (`{summary['profile']}`), {config['boxes']} boxes of each hard "
        f"family x {config['placements']} random placements, {config['max_actions']} actions per trial (an unsolved "
        f"trial counts them); memory: {config['train_boxes']} training boxes per family, once each, symbolically. "
        f"Test boxes from seed {config.get('test_seed', 36000)}, placements from world seed {config['eval_seed']}.",
        "",
        "| cell | set | runs | solved | mean actions | optimum | ratio | peak true wrist force | runs > 45 N "
        "| outcome agreement |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in summary["rows"]:
        lines.append(
            f"| {r.get('calibration', 'calibrated')} | {r['set']} | {r['trials']} | {r['solved']}/{r['trials']} "
            f"| {r['mean_actions']:.2f} | {r['optimum']:.2f} | {r['ratio_to_optimum']:.2f} "
            f"| {r['peak_true_wrist_force_n']:.1f} N | {r['runs_over_margin']} "
            f"| {r['outcome_agreement']:.1%} of {r['actions_total']} |"
        )
    for r in summary["rows"]:
        if r["set"] == "all":
            unsolved = r["unsolved_reasons"]
            lines += ["", f"Unsolved ({r.get('calibration', 'calibrated')}): "
                      + ("; ".join(unsolved) if unsolved else "none") + "."]  # fmt: skip
    if "wall_time_s" in summary:
        phases = ", ".join(f"{k.removesuffix('_s')} {v / 60:.1f}" for k, v in summary["wall_time_by_phase_s"].items())
        lines += ["", f"Wall time: {summary['wall_time_s'] / 60:.1f} min ({phases} min)."]
    return "\n".join(lines) + "\n"


def plot(summary: dict[str, Any], path: Path) -> None:
    """Mean actions against the optimum, and the peak true wrist force against the margin, per set."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = summary["rows"]
    cells = len({r.get("calibration") for r in rows})
    names = [f"{r['set']}" + (f" ({r['calibration']})" if cells > 1 else "") + f"\n{r['solved']}/{r['trials']} solved"
             for r in rows]  # fmt: skip
    x = range(len(rows))
    fig, axes = plt.subplots(1, 2, figsize=(10 if cells == 1 else 16, 4))
    axes[0].bar([i - 0.2 for i in x], [r["mean_actions"] for r in rows], width=0.4, label="mean actions")
    axes[0].bar([i + 0.2 for i in x], [r["optimum"] for r in rows], width=0.4, label="optimum", color="C2")
    axes[0].set_ylabel("actions per trial")
    axes[1].bar(list(x), [r["peak_true_wrist_force_n"] for r in rows], color="C1")
    axes[1].axhline(FORCE_MARGIN_N, color="k", linestyle="--", label=f"margin {FORCE_MARGIN_N:g} N")
    axes[1].set_ylabel("peak true wrist force [N]")
    for ax in axes:
        ax.set_xticks(list(x), names, fontsize=8)
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=8)
    fig.suptitle(f"hard test sets in the twin ({summary['profile']})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
