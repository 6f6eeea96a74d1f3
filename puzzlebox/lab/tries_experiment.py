"""``experiment.py tries``: record every try of a set of twin trials into a corpus, then measure the hand's
judgement on it offline (:mod:`puzzlebox.lab.try_corpus`).

The trials: the paper's three test boxes under each profile (``ideal``, ``realistic``, ``harsh``, each with its
cell's calibration) and under ``realistic`` without a calibration file (``realistic-uncalibrated``), runs with one
kind misreported (``realistic``), and hard boxes of each family (``realistic``), each solved by the dual agent from an
empty memory. The split: the paper boxes are the ``development`` part (the
judgement's thresholds were set over the project's history on them, at other seeds); the hard boxes, drawn from a
seed range used nowhere else, and the misreported runs are ``held-out``.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.lab.cli import write_json
from puzzlebox.lab.hard_sets import FAMILY_NAMES, hard_box
from puzzlebox.lab.reality_sweep import calibration_task
from puzzlebox.lab.runner import RecordStore, Task, make_executor, run_tasks
from puzzlebox.lab.try_corpus import RecordedTry, judge_corpus, load_tries, sample, save_tries
from puzzlebox.learning import make_agent, run_episode
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.atomic import write_atomically
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.generator import paper_family
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.spec_loading import spec_from_dict
from puzzlebox.twin.reality import RealityProfile, load_profile


@dataclass(frozen=True)
class TriesConfig:
    """What ``experiment.py tries`` records."""

    profiles: tuple[str, ...] = ("ideal", "realistic", "harsh")
    uncalibrated: tuple[str, ...] = ("realistic",)
    """Profiles whose paper-box trials are also recorded without a calibration file (the twin's nominal, datasheet
    calibration; reported as ``<profile>-uncalibrated``)."""
    paper_seeds: tuple[int, ...] = (7000, 7001, 7002, 7003)
    """Trial seeds (placements) of each paper test box in each cell."""
    misreported: int = 12
    """Runs with one kind misreported (``realistic``; box ``i % 3``, seed ``7100 + i``)."""
    hard_boxes: int = 2
    """Hard boxes of each family (seeds from :attr:`hard_seed`), one placement each (``realistic``)."""
    hard_seed: int = 97_000
    agent: str = "dual"
    max_actions: int = 20

    def quick(self) -> TriesConfig:
        """A quick look: one placement per cell, two misreported runs, one hard box of each family (17 trials)."""
        return dataclasses.replace(self, paper_seeds=(7000,), misreported=2, hard_boxes=1)


def _trials(config: TriesConfig) -> Iterator[tuple[str, PuzzleSpec, int, str, bool, bool, str]]:
    """(key, spec, seed, profile, calibrated, one kind misreported, split) of every trial."""
    paper = paper_family("test", seed=0)
    cells = [(p, True) for p in config.profiles] + [(p, False) for p in config.uncalibrated]
    for profile, calibrated in cells:
        cell = profile if calibrated else f"{profile}-uncalibrated"
        for spec in paper:
            for seed in config.paper_seeds:
                yield f"{cell}-{spec.name}-s{seed}", spec, seed, profile, calibrated, False, "development"
    for i in range(config.misreported):
        box = paper[i % 3]
        yield f"misreported-{box.name}-s{7100 + i}", box, 7100 + i, "realistic", True, True, "held-out"
    for family in FAMILY_NAMES:
        for b in range(config.hard_boxes):
            spec = hard_box(family, config.hard_seed + b)
            yield f"hard-{spec.name}", spec, config.hard_seed + b, "realistic", True, False, "held-out"


def record_task(settings: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """Run one trial with every toggle recorded (a runner task); the tries go to ``context["file"]``."""
    from puzzlebox.lab.twin_trial import evaluation_world, wrong_kind  # MuJoCo only in the task
    from puzzlebox.learning.belief import CELL_BELIEF
    from puzzlebox.skills import SkillError
    from puzzlebox.twin.errors import SimulationDiverged
    from puzzlebox.twin.session import TwinSession

    start = time.perf_counter()
    spec, seed = spec_from_dict(settings["spec"]), settings["seed"]
    profile = RealityProfile.from_dict(settings["profile"])
    # None: the twin's nominal calibration, exact under ``ideal`` only
    calibration = CellCalibration.from_dict(settings["calibration"]) if settings["calibration"] else None
    tries: list[RecordedTry] = []
    with TwinSession(spec, seed=seed, reality=profile) as session:
        told = wrong_kind(session.spec, seed) if settings["misreported"] else {}
        world = evaluation_world(session, session.robot, calibration, seed, told)
        base = {"key": settings["key"], "profile": settings["profile_name"], "box": spec.name, "seed": seed,
                "split": settings["split"], "misreported": told}  # fmt: skip
        _record_toggles(world, session, tries, base)
        agent = make_agent(settings["agent"], session.spec, belief=CELL_BELIEF)
        try:
            result = run_episode(agent, world, spec.name, seed, settings["max_actions"])
            solved, ended = result.solved, result.ended
        except (SkillError, SimulationDiverged) as err:  # the tries recorded so far are kept
            solved, ended = False, f"{type(err).__name__}: {err}"
    save_tries(context["file"], tries)
    return {"key": settings["key"], "solved": solved, "ended": ended, "tries": len(tries),
            "judged": sum(t.trace is not None for t in tries), "wall_time_s": time.perf_counter() - start}  # fmt: skip


def _record_toggles(world: Any, session: Any, tries: list[RecordedTry], base: dict[str, Any]) -> None:
    """Wrap ``world``'s toggle primitive on the instance: each toggle's result, readings and (evaluation only)
    the part's true state and fraction before and after it go to ``tries``."""
    toggler, spec = world.toggler, session.spec
    index = {c.name: i for i, c in enumerate(spec.components)}
    travels = [get_kind(c.kind).travel for c in spec.components]
    original = toggler.toggle

    def toggle(jm: Any, opening: bool = True, *args: Any, **kwargs: Any) -> Any:
        marker = next((m for m, model in world.joint_models.items() if model is jm), -1)
        i = index[world.names[marker]]
        before = (int(session.component_states()[i]), float(session.component_positions()[i]))
        result = original(jm, opening, *args, **kwargs)
        after = (int(session.component_states()[i]), float(session.component_positions()[i]))
        truth = {"state_before": before[0], "state_after": after[0],
                 "fraction_before": before[1] / travels[i], "fraction_after": after[1] / travels[i]}  # fmt: skip
        context = {**base, "action": len(world.log) + 1, "component": world.names[marker], "kind": jm.kind,
                   "opening": bool(opening)}  # fmt: skip
        cause = result.cause.value if result.cause is not None else None
        tries.append(RecordedTry(context, result.outcome, cause, truth, result.trace))
        return result

    toggler.toggle = toggle


def run_tries(out: Path, config: TriesConfig, workers: int | None = None) -> dict[str, Any]:
    """Record (or resume recording) the corpus into ``out/tries/`` and judge it; returns the summary also written
    to ``out/tries.json`` (and ``out/tries.md``)."""
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    profiles = {name: load_profile(name) for name in (*config.profiles, *config.uncalibrated)}
    records = out / "records"
    with make_executor(workers, None) as executor:
        spec0 = paper_family("test", seed=0)[0]
        calibrations = [Task(f"calibration-{name}", calibration_task, {"spec": spec0.to_dict(), "profile": p.to_dict()})
                        for name, p in profiles.items()]  # fmt: skip
        done = run_tasks(calibrations, RecordStore(records / "calibrations"), executor, desc="calibrations")
        done.raise_for_failures()
        cal = {name: done.records[f"calibration-{name}"]["calibration"] for name in profiles}
        tasks = [
            Task(key, record_task, {"key": key, "spec": spec.to_dict(), "seed": seed,
                                    "profile": profiles[profile].to_dict(),
                                    "profile_name": profile if calibrated else f"{profile}-uncalibrated",
                                    "calibration": cal[profile] if calibrated else None, "misreported": misreported,
                                    "split": split, "agent": config.agent, "max_actions": config.max_actions},
                 context={"file": str(out / "tries" / f"{key}.npz")})
            for key, spec, seed, profile, calibrated, misreported, split in _trials(config)
        ]  # fmt: skip
        report = run_tasks(tasks, RecordStore(records / "trials"), executor, desc="recorded trials",
                           postfix=lambda r: f"tries {sum(x['tries'] for x in r.values())}")  # fmt: skip
        report.raise_for_failures()
    tries = [t for task in tasks for t in load_tries(out / "tries" / f"{task.key}.npz")]
    summary = {"trials": len(tasks), "tries": len(tries), **judge_corpus(tries),
               "wall_time_s": time.perf_counter() - start}  # fmt: skip
    write_json(out / "tries.json", summary)
    save_tries(out / "sample.npz", sample(tries))
    write_atomically(out / "tries.md", lambda tmp: tmp.write_text(markdown(summary)))
    write_atomically(out / "tries.png", lambda tmp: plot(summary, tmp))
    return summary


def _row(name: str, tally: dict[str, Any]) -> str:
    c = tally["confusion"]
    agreement = "-" if tally["agreement"] is None else f"{100 * tally['agreement']:.2f} %"
    return (f"| {name} | {tally['pinches']} | {tally['same_as_live']} | {agreement} | {c['moved']['moved']} / "
            f"{c['moved']['not moved']} | {c['blocked']['moved']} / {c['blocked']['not moved']} | "
            f"{c['failed']['moved']} / {c['failed']['not moved']} |")  # fmt: skip


def markdown(summary: dict[str, Any]) -> str:
    """The report: the judgement's agreement with the truth per group, with each group's confusion matrix."""
    head = ("| group | judged | judged as live | agreement (evidence) | moved: truly moved / not | "
            "blocked: truly moved / not | failed: truly moved / not |\n|---|---|---|---|---|---|---|")  # fmt: skip
    lines = [
        "# The hand's judgement on the corpus of recorded tries", "",
        f"{summary['trials']} trials, {summary['tries']} tries; the judgement run offline on every recorded pinch and "
        f"door swing ({summary['ms_per_judgement']:.3f} ms each). Tries no recorded judgement concluded (closing "
        f"pushes, top-ups, failed grasps), by cause: {json.dumps(summary['unjudged'])}.", "", head,
        _row("all", summary["all"]["all"]),
    ]  # fmt: skip
    for group in ("motion", "split", "profile", "cause"):
        lines += [_row(f"{group} {k}", v) for k, v in summary[group].items()]
    return "\n".join(lines) + "\n"


def plot(summary: dict[str, Any], path: Path) -> None:
    """One confusion matrix per profile (rows: what the judgement concluded; columns: the truth), counts in the
    cells, the agreement over the evidence in the title."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    profiles = list(summary["profile"])
    fig, axes = plt.subplots(1, max(len(profiles), 1), figsize=(3.4 * max(len(profiles), 1), 3.2), squeeze=False)
    judged, truth = ("moved", "blocked", "failed"), ("moved", "not moved")
    for ax, name in zip(axes[0], profiles, strict=False):
        tally = summary["profile"][name]
        counts = np.array([[tally["confusion"][j][t] for t in truth] for j in judged], dtype=float)
        shade = counts / max(counts.max(), 1.0)
        ax.imshow(shade, cmap="Blues", vmin=0.0, vmax=1.0)
        for (row, col), n in np.ndenumerate(counts):
            colour = "white" if shade[row, col] > 0.5 else "black"
            ax.text(col, row, f"{n:.0f}", ha="center", va="center", fontsize=10, color=colour)
        ax.set_xticks(range(len(truth)), [f"truly {t}" for t in truth], fontsize=8)
        ax.set_yticks(range(len(judged)), [f"judged {j}" for j in judged], fontsize=8)
        agreement = "-" if tally["agreement"] is None else f"{100 * tally['agreement']:.2f} %"
        ax.set_title(f"{name}: {tally['pinches']} tries, {agreement}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110, format="png")
    plt.close(fig)


__all__ = ["TriesConfig", "plot", "record_task", "run_tries"]
