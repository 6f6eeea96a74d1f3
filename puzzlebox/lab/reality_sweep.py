"""``experiment.py reality``: the pipeline against each factor of the reality gap alone, over levels, and
all factors together, on the paper test boxes placed at random reachable poses.

For every profile (``twin.reality_levels``: level 0 ideal, 1 realistic, 2 harsh) the cell is calibrated
from ChArUco images as a real one would be (``lab.calibration_run``), then the memory agent runs every test
box at ``placements`` random reachable placements (seeds ``seed .. seed + placements - 1``, the same
placements at every level). A second sweep raises the F/T force noise alone, to find the noise at which
outcome agreement drops below 99 %.

Calibrations and trials are tasks of ``puzzlebox.lab.runner`` (``--workers K`` processes, default one per
core, or ``--ray``). Nothing is lost: each calibration and each trial is written to ``DIR/calibrations/``
and ``DIR/trials/`` as soon as it is made (atomically), and the same command resumes after an
interruption, reusing them. The summary (``DIR/reality.json``, ``.md``, ``.png``) is rewritten every few
seconds as trials end and at the end, a profile's point appearing once all its trials are in.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from puzzlebox.lab.calibration_run import calibrate_cell
from puzzlebox.lab.cli import write_json
from puzzlebox.lab.run_store import Periodic
from puzzlebox.lab.runner import Executor, RecordStore, Task, make_executor, run_tasks
from puzzlebox.lab.trial_figures import twin_figures
from puzzlebox.lab.trial_task import trial_task
from puzzlebox.learning import MemoryAgent, SymbolicWorld, run_episode, summarise
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.generator import paper_family
from puzzlebox.models.spec_loading import spec_from_dict
from puzzlebox.twin.reality import RealityProfile
from puzzlebox.twin.reality_levels import ALL, FACTORS, force_noise_profile, profile_at

AGREEMENT_BOUND = 0.99
"""Outcome agreement below which the F/T noise sweep reports its level."""
FORCE_NOISE_SERIES = "force-noise"


@dataclass(frozen=True)
class SweepConfig:
    """What ``experiment.py reality`` runs."""

    factors: tuple[str, ...] = (*FACTORS, ALL)
    levels: tuple[float, ...] = (0.0, 1.0, 2.0)
    """Levels of each factor (0 ideal, 1 realistic, 2 harsh)."""
    force_noise_levels: tuple[float, ...] = (0.0, 1.0, 3.0, 7.0, 15.0)
    """σ of the F/T force noise alone [N] (the issue: at 7 N the old single-sample rule read every toggle blocked)."""
    placements: int = 4
    """Random reachable placements per test box, per profile."""
    seed: int = 5000
    """Seed of the first placement (and of the world and agent of that run)."""
    max_actions: int = 30
    cell_seed: int = 0
    train_episodes: int = 9
    """Episodes of the memory agent's training on the paper training boxes (when no memory is given)."""

    def quick(self) -> SweepConfig:
        """CI size: the F/T factor at levels 0 and 1, one placement, no noise sweep."""
        quick = {"factors": ("force-torque",), "levels": (0.0, 1.0), "force_noise_levels": (), "placements": 1}
        return dataclasses.replace(self, **quick)

    def points(self) -> Iterator[tuple[str, float, RealityProfile]]:
        """``(series, level, profile)`` of every point; level 0 of every series is one shared profile."""
        baseline = dataclasses.replace(profile_at(ALL, 0.0, self.cell_seed), name="ideal-placed")
        for factor in self.factors:
            for level in self.levels:
                yield factor, level, baseline if level == 0 else profile_at(factor, level, self.cell_seed)
        for sigma in self.force_noise_levels:
            yield FORCE_NOISE_SERIES, sigma, baseline if sigma == 0 else force_noise_profile(sigma, self.cell_seed)


def ensure_memory(path: Path, config: SweepConfig) -> Path:
    """The memory agent's store: ``path`` if it holds episodes, else trained there on the paper training
    boxes (docs/results.md's recipe) and returned."""
    if path.exists():
        return path
    train = paper_family("train", seed=0)
    store = MemoryStore(str(path))
    try:
        for e in range(config.train_episodes):
            spec = train[e % len(train)]
            agent = MemoryAgent(store, learn=True)
            agent.episode_label = spec.name
            run_episode(agent, SymbolicWorld(spec, e), spec.name, e, config.max_actions)
    finally:
        store.close()
    return path


def run_sweep(
    out: Path, config: SweepConfig, memory_path: Path | None = None, workers: int | None = None, ray: str | None = None
) -> dict[str, Any]:
    """Run (or resume) the sweep into ``out`` on the task runner (``workers`` processes, default one per core,
    or Ray); returns the summary also written to ``out/reality.json``.

    Raises:
        LearningError: a calibration or trial failed (every other one is kept for the resume).
    """
    out.mkdir(parents=True, exist_ok=True)
    memory_path = ensure_memory(memory_path or out / "memory.sqlite", config)
    specs = paper_family("test", seed=0)
    points = list(config.points())
    profiles = {p.name: p for _, _, p in points}
    start = time.perf_counter()
    with make_executor(workers, ray) as executor:
        calibrations = [Task(name, calibration_task, {"spec": specs[0].to_dict(), "profile": profile.to_dict()})
                        for name, profile in profiles.items()]  # fmt: skip
        done = run_tasks(calibrations, RecordStore(out / "calibrations"), executor, desc="calibrations")
        done.raise_for_failures()
        trials, by_profile = [], {}
        for name, profile in profiles.items():
            calibration = done.records[name]["calibration"]
            for spec in specs:
                assert spec.box is not None  # the paper's boxes
                CellCalibration.from_dict(calibration).check_cell(name, profile.cell_seed, spec.box.size[2], spec.name)
                for seed in range(config.seed, config.seed + config.placements):
                    key = f"{name}-{spec.name}-seed{seed}"
                    trials.append(trial_task(
                        key, spec, seed, sim="twin", agent="memory", max_actions=config.max_actions,
                        memory=str(memory_path), reality=profile.to_dict(), calibration=calibration,
                    ))  # fmt: skip
                    by_profile[key] = name
        found: dict[str, dict[str, Any]] = {}

        def summary() -> dict[str, Any]:
            per_profile = {}
            for name in profiles:
                runs = [found[t.key] for t in trials if by_profile[t.key] == name and t.key in found]
                if len(runs) == len(specs) * config.placements:  # a profile's point once all its trials are in
                    per_profile[name] = _figures(runs, config.max_actions, done.records[name]["figures"])
            shown = [{"series": s, "level": lv, "profile": p.name, **per_profile[p.name]}
                     for s, lv, p in points if p.name in per_profile]  # fmt: skip
            return {
                "config": dataclasses.asdict(config), "memory": str(memory_path), "points": shown,
                "force_noise_threshold_n": force_noise_threshold(shown), "wall_time_s": time.perf_counter() - start,
            }  # fmt: skip

        report_now = Periodic(lambda: write_report(summary(), out))  # its plot alone takes ~0.3 s

        def keep(task: Task, record: dict[str, Any]) -> None:
            found[task.key] = record
            report_now()

        report = run_tasks(trials, RecordStore(out / "trials"), executor, on_record=keep, desc="reality sweep",
                           postfix=lambda r: f"solved {sum(x['solved'] for x in r.values())}/{len(r)}")  # fmt: skip
        report.raise_for_failures()
    found.update(report.records)
    result = summary()
    write_report(result, out)
    return result


def calibrated_cell(reality: RealityProfile, folder: Path, executor: Executor) -> dict[str, Any]:
    """The cell of ``reality`` calibrated once from ChArUco images, whatever box it then meets (a runner task whose
    record is kept in ``folder``: a rerun reuses it); its ``CellCalibration.to_dict()``."""
    board = paper_family("test", seed=0)[0]
    done = run_tasks([Task(reality.name, calibration_task, {"spec": board.to_dict(), "profile": reality.to_dict()})],
                     RecordStore(folder), executor, desc="calibration")  # fmt: skip
    done.raise_for_failures()
    return done.records[reality.name]["calibration"]


def calibration_task(settings: dict[str, Any]) -> dict[str, Any]:
    """Calibrate the cell of a profile (a runner task): the calibration and its figures."""
    run = calibrate_cell(spec_from_dict(settings["spec"]), RealityProfile.from_dict(settings["profile"]))
    return {"calibration": run.calibration.to_dict(), "figures": run.figures}


def _figures(runs: list[dict[str, Any]], max_actions: int, calibration: dict[str, Any]) -> dict[str, Any]:
    results = summarise(list(runs), max_actions)
    figures = twin_figures(runs)
    return {
        "trials": len(runs),
        "success_rate": results["success_rate"],
        "mean_actions": results["mean_actions"],
        "outcome_agreement": figures["outcome_agreement"],
        "actions_total": figures["actions_total"],
        "failed_tries_by_reason": figures["failed_tries_by_reason"],
        "unsolved_reasons": figures["unsolved_reasons"],
        "perceived_position_error_max_m": figures["perceived_position_error_max_m"],
        "peak_true_wrist_force_n": figures["peak_true_wrist_force_n"],
        "calibration_reprojection_px": max(f["reprojection_px"] for f in calibration.values()),
    }


def force_noise_threshold(points: list[dict[str, Any]]) -> float | None:
    """The smallest F/T force noise [N] of the noise sweep whose outcome agreement is below 99 %, or None."""
    low = [p["level"] for p in points if p["series"] == FORCE_NOISE_SERIES and p["outcome_agreement"] < AGREEMENT_BOUND]
    return min(low) if low else None


def write_report(summary: dict[str, Any], out: Path) -> None:
    """``reality.json``, ``reality.md`` (one row per point) and ``reality.png`` (each figure against the level)."""
    write_json(out / "reality.json", summary)
    (out / "reality.md").write_text(markdown(summary))
    plot(summary, out / "reality.png")


def markdown(summary: dict[str, Any]) -> str:
    lines = [
        "# The pipeline against the reality gap",
        "",
        "Each factor alone over levels (0 ideal, 1 realistic, 2 harsh; the F/T noise series: σ in N), the box at "
        f"random reachable placements ({summary['config']['placements']} per paper test box, seeds from "
        f"{summary['config']['seed']}); a run has {summary['config']['max_actions']} actions.",
        "",
        "| factor | level | trials | solved | mean actions | outcome agreement | failed tries (reason: count) "
        "| peak true wrist force [N] | calibration [px] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for p in summary["points"]:
        reasons = ", ".join(f"{k}: {v}" for k, v in sorted(p["failed_tries_by_reason"].items())) or "-"
        lines.append(
            f"| {p['series']} | {p['level']:g} | {p['trials']} | {p['success_rate']:.0%} | {p['mean_actions']:.2f} "
            f"| {p['outcome_agreement']:.1%} | {reasons} | {p['peak_true_wrist_force_n']:.0f} "
            f"| {p['calibration_reprojection_px']:.3f} |"
        )
    threshold = summary.get("force_noise_threshold_n")
    noise_levels = summary["config"]["force_noise_levels"]
    if noise_levels:
        lines += ["", "F/T force noise at which outcome agreement drops below 99 %: " + (
            f"**{threshold:g} N**" if threshold is not None
            else f"not reached up to {max(noise_levels):g} N (the highest level run)"
        )]  # fmt: skip
    unsolved = [(p["series"], p["level"], r) for p in summary["points"] for r in p["unsolved_reasons"]]
    if unsolved:
        lines += ["", "## Unsolved runs", ""] + [f"- {s} @ {lv:g}: {r}" for s, lv, r in unsolved]
    return "\n".join(lines) + "\n"


def plot(summary: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = (
        ("success_rate", "solved [-]"),
        ("mean_actions", "mean actions"),
        ("outcome_agreement", "outcome agreement [-]"),
        ("failed_per_trial", "failed tries per trial"),
    )
    fig, axes = plt.subplots(1, len(panels) + 1, figsize=(4.2 * (len(panels) + 1), 3.8))
    series = sorted({p["series"] for p in summary["points"]} - {FORCE_NOISE_SERIES}, key=_series_order)
    for key, label in panels:
        ax = axes[[k for k, _ in panels].index(key)]
        for s in series:
            pts = sorted((p for p in summary["points"] if p["series"] == s), key=lambda p: p["level"])
            ax.plot([p["level"] for p in pts], [_value(p, key) for p in pts], "o-", label=s)
        ax.set_xlabel("level (0 ideal, 1 realistic, 2 harsh)")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    if series:  # (a summary written before any factor's trial ended has none)
        axes[0].legend(fontsize=7)
    ax = axes[-1]
    noise = sorted((p for p in summary["points"] if p["series"] == FORCE_NOISE_SERIES), key=lambda p: p["level"])
    if noise:
        ax.plot([p["level"] for p in noise], [p["outcome_agreement"] for p in noise], "o-", color="k")
        ax.axhline(AGREEMENT_BOUND, color="r", lw=0.8, ls="--")
    ax.set_xlabel("F/T force noise σ [N]")
    ax.set_ylabel("outcome agreement [-]")
    ax.set_title("F/T noise alone")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp.png")
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    tmp.replace(path)


def _value(point: dict[str, Any], key: str) -> float:
    if key == "failed_per_trial":
        return sum(point["failed_tries_by_reason"].values()) / max(point["trials"], 1)
    value = point[key]
    return value if value is not None and math.isfinite(value) else float("nan")


def _series_order(name: str) -> int:
    order = (*FACTORS, ALL)
    return order.index(name) if name in order else len(order)
