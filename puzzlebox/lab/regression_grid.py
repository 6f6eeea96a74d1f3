"""``experiment.py regression``: a fixed grid of twin trials whose records a change that should not alter behaviour
must leave as they were — every action, its outcome and the hash of everything the robot sensed.

The grid (:func:`grid_trials`): the three paper test boxes x 5 seeds under ``realistic`` and under ``harsh``, each
profile's cell calibrated first (30 trials); the first two boxes of each hard family (eight parts: random,
multi-locker, chains) x 2 placements under ``realistic``, calibrated (12); and 10 runs with one kind misreported on
the paper test boxes under ``realistic``, calibrated (10). The memory agent's memories are trained symbolically in the
grid's own folder (the 9 paper training boxes once each; 10 training boxes of each hard family once each), so the
grid depends on nothing outside it.

``DIR/regression.json`` holds, per trial, what must not change (:func:`fingerprint`): solved, the number of
actions, each action's component and outcome, and ``sensed_sha256``; beside them each action's reason, for reading.
:func:`compare` lists every difference from a reference file of the same form (``--reference``: the command then
exits 1 when any is found, one line each). Every step is a task of :mod:`puzzlebox.lab.runner` kept the moment it
ends: the same command resumes.
"""

from __future__ import annotations

import dataclasses
import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from puzzlebox.lab.cli import write_json
from puzzlebox.lab.hard_grid import HardGridConfig, memory_task
from puzzlebox.lab.learning_boxes import test_boxes, training_boxes
from puzzlebox.lab.reality_sweep import calibrated_cell
from puzzlebox.lab.runner import RecordStore, Task, make_executor, run_tasks
from puzzlebox.lab.trial_task import file_sha256, trial_task
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.generator import paper_family
from puzzlebox.twin.reality import load_profile

MUST_MATCH = ("solved", "num_actions", "actions", "sensed_sha256")
"""The fields of a trial's fingerprint that a behaviour-preserving change keeps (``reasons`` is for reading)."""


@dataclass(frozen=True)
class RegressionGridConfig:
    """What ``experiment.py regression`` runs (the defaults are the grid; :meth:`quick` a one-trial plumbing check)."""

    paper_boxes: int = 3
    """The first paper test boxes."""
    paper_seeds: int = 5
    """Seeds 0..n-1 of each paper test box under each of ``paper_profiles``."""
    paper_profiles: tuple[str, ...] = ("realistic", "harsh")
    hard_boxes: int = 2
    """Test boxes of each hard family (their first seeds), under ``realistic``."""
    hard_placements: int = 2
    """Placements of each hard box (world seeds as ``experiment.py hard-sets``: ``HardGridConfig.eval_seed + p``)."""
    hard_train_boxes: int = 10
    """Training boxes of each hard family in the hard boxes' symbolic memory."""
    misreported: int = 10
    """Runs with one kind misreported (paper test box ``i % 3``, seed 6000 + i), under ``realistic``."""
    max_actions: int = 30
    """Action budget of a paper trial (a hard trial: 40)."""

    def quick(self) -> RegressionGridConfig:
        """CI size: one paper trial under ``realistic`` (box 0, seed 0), nothing else."""
        return dataclasses.replace(self, paper_boxes=1, paper_seeds=1, paper_profiles=("realistic",), hard_boxes=0,
                                   misreported=0, max_actions=8)  # fmt: skip


def run_regression_grid(out: Path, config: RegressionGridConfig, workers: int | None = None,
                        ray: str | None = None) -> dict[str, Any]:  # fmt: skip
    """Run (or resume) the grid into ``out``; returns the fingerprints written to ``out/regression.json``.

    Raises:
        LearningError: a task failed (every other one is kept for the resume).
    """
    out.mkdir(parents=True, exist_ok=True)
    begin = time.perf_counter()
    with make_executor(workers, ray) as executor:
        profiles = {name: load_profile(name) for name in {*config.paper_profiles, "realistic"}}
        calibrations = {name: calibrated_cell(p, out / "calibrations", executor) for name, p in profiles.items()}
        memories = _memories(out, config, executor)
        trials = grid_trials(config, out, memories, {n: p.to_dict() for n, p in profiles.items()}, calibrations)
        done = run_tasks(trials, RecordStore(out / "trials"), executor, desc="regression trials",
                         postfix=lambda r: f"solved {sum(x['solved'] for x in r.values())}/{len(r)}")  # fmt: skip
        done.raise_for_failures()
    summary = {
        "config": dataclasses.asdict(config),
        "memories": {name: file_sha256(path) for name, path in memories.items()},
        "trials": {t.key: fingerprint(done.records[t.key]) for t in trials},
        "wall_time_s": time.perf_counter() - begin,
    }
    write_json(out / "regression.json", summary)
    return summary


def grid_trials(
    config: RegressionGridConfig,
    out: Path,
    memories: dict[str, Path],
    profiles: dict[str, dict[str, Any]],
    calibrations: dict[str, dict[str, Any]],
) -> list[Task]:
    """Every trial of the grid (module docstring), keyed ``<profile>-<box>-s<seed>``, ``hard-<box>-p<p>`` and
    ``misreported-<box>-s<seed>`` (the hard boxes' specs cached in ``out/specs``)."""
    paper = paper_family("test", seed=0)

    def trial(key: str, spec: PuzzleSpec, seed: int, profile: str, memory: str, **extra: Any) -> Task:
        return trial_task(key, spec, seed, sim="twin", agent="memory", memory=str(memories[memory]),
                          reality=profiles[profile], calibration=calibrations[profile], **extra)  # fmt: skip

    tasks = [
        trial(f"{profile}-{spec.name}-s{seed}", spec, seed, profile, "paper", max_actions=config.max_actions)
        for profile in config.paper_profiles
        for spec in paper[: config.paper_boxes]
        for seed in range(config.paper_seeds)
    ]
    if config.hard_boxes:
        boxes = test_boxes("hard", config.hard_boxes, out / "specs")
        tasks += [
            trial(
                f"hard-{box.spec.name}-p{p}",
                box.spec,
                HardGridConfig.eval_seed + p,
                "realistic",
                "hard",
                max_actions=40,
                max_lockers=box.max_lockers,
            )  # fmt: skip
            for box in boxes
            for p in range(config.hard_placements)
        ]
    tasks += [
        trial(
            f"misreported-{paper[i % 3].name}-s{6000 + i}",
            paper[i % 3],
            6000 + i,
            "realistic",
            "paper",
            max_actions=config.max_actions,
            misreport_kind=True,
        )  # fmt: skip
        for i in range(config.misreported)
    ]
    return tasks


def _memories(out: Path, config: RegressionGridConfig, executor: Any) -> dict[str, Path]:
    """The grid's symbolic memories (runner tasks kept in ``out/memory``): ``paper`` and, if the grid has hard
    boxes, ``hard``."""
    sets: dict[str, list[Any]] = {"paper": [(s, 1) for s in paper_family("train", seed=0)]}
    if config.hard_boxes:
        sets["hard"] = [(b.spec, b.max_lockers) for b in training_boxes("hard", config.hard_train_boxes, out / "specs")]
    tasks = {
        name: Task(
            f"memory-{name}",
            memory_task,
            {
                "seed": 0,
                "max_actions": 40,
                "train": [spec.to_dict() for spec, _ in train],
                "train_max_lockers": [k for _, k in train],
            },
            context={"dir": str(out / "memory" / name)},
        )  # fmt: skip
        for name, train in sets.items()
    }
    done = run_tasks(list(tasks.values()), RecordStore(out / "memory" / "records"), executor, desc="memories")
    done.raise_for_failures()
    return {name: out / "memory" / name / done.records[task.key]["memory"] for name, task in tasks.items()}


def fingerprint(record: dict[str, Any]) -> dict[str, Any]:
    """What of a trial's record must not change (:data:`MUST_MATCH`), and each action's reason beside it."""
    return {
        "solved": record["solved"],
        "num_actions": record["num_actions"],
        "actions": [[a["component"], a["outcome"]] for a in record["actions"]],
        "sensed_sha256": record.get("sensed_sha256"),
        "reasons": [a.get("reason", "") for a in record["actions"]],
    }


def compare(results: dict[str, Any], reference: dict[str, Any]) -> list[str]:
    """Every difference between two grids' fingerprints (``regression.json`` contents), one line each: a trial
    missing from either, or a field of :data:`MUST_MATCH` that differs (the first differing action named)."""
    ours, theirs = results["trials"], reference["trials"]
    lines = [f"{key}: not in the results" for key in theirs if key not in ours]
    lines += [f"{key}: not in the reference" for key in ours if key not in theirs]
    for key in (k for k in theirs if k in ours):
        a, b = ours[key], theirs[key]
        for field in MUST_MATCH:
            if a.get(field) == b.get(field):
                continue
            if field == "actions":
                at = next((i for i, (x, y) in enumerate(zip(a["actions"], b["actions"], strict=False)) if x != y),
                          min(len(a["actions"]), len(b["actions"])))  # fmt: skip
                got = a["actions"][at] if at < len(a["actions"]) else "nothing"
                want = b["actions"][at] if at < len(b["actions"]) else "nothing"
                lines.append(f"{key}: action {at + 1} is {got}, the reference's {want}")
            else:
                lines.append(f"{key}: {field} {a.get(field)!r}, the reference's {b.get(field)!r}")
    return lines


def load_reference(path: Path) -> dict[str, Any]:
    """A reference grid (``regression.json`` of an earlier run); ``ValueError`` says what is wrong with it."""
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise ValueError(f"cannot read {path}: {err}") from err
    if not isinstance(data, dict) or not isinstance(data.get("trials"), dict):
        raise ValueError(f"{path} is not a regression grid's regression.json (no 'trials' object)")
    return data
