"""The optimum beside every figure of ``experiment.py twin-learning``: per point of the curve, the test boxes' mean
optimum (the fewest actions that solve them), the ratio of the mean actions to it, the peak true wrist force of its
trials, and the same figures per box family (the hard sets' ``random8``, ``multi8``, ``chain8``)."""

from __future__ import annotations

import statistics
from collections.abc import Mapping, Sequence
from typing import Any

from puzzlebox.lab.learning_boxes import LearningBox


def with_optimum(
    summary: dict[str, Any],
    trials: Mapping[str, dict[str, Any]],
    where: Mapping[str, tuple[str, int, float]],
    tests: Sequence[LearningBox],
    max_actions: int,
) -> dict[str, Any]:
    """``summary`` with each point's ``optimum``, ``ratio_to_optimum``, ``peak_true_wrist_force_n`` and ``sets``
    (per family: trials, success rate, mean actions — an unsolved trial counts ``max_actions`` — and optimum), and
    the test boxes with their optimum under ``test_boxes``. ``where`` maps a trial's key to its (start, seed, hours).
    """
    best = {b.spec.name: b for b in tests}
    for point in summary["points"]:
        runs = [
            trials[k] for k, (start, _, hours) in where.items() if start == point["start"] and hours == point["hours"]
        ]
        if not runs:
            continue
        point["optimum"] = statistics.fmean(best[r["spec"]].optimum for r in runs)
        point["ratio_to_optimum"] = point["mean_actions"] / point["optimum"]
        forces = [r["peak_true_wrist_force_n"] for r in runs if r.get("peak_true_wrist_force_n") is not None]
        point["peak_true_wrist_force_n"] = max(forces) if forces else None
        point["sets"] = {}
        for family in dict.fromkeys(b.family for b in tests):
            mine = [r for r in runs if best[r["spec"]].family == family]
            point["sets"][family] = {
                "trials": len(mine),
                "success_rate": statistics.fmean(r["solved"] for r in mine),
                "mean_actions": statistics.fmean(r["num_actions"] if r["solved"] else max_actions for r in mine),
                "optimum": statistics.fmean(best[r["spec"]].optimum for r in mine),
            }
    summary["test_boxes"] = [
        {"spec": b.spec.name, "family": b.family, "optimum": b.optimum, "max_lockers": b.max_lockers} for b in tests
    ]
    return summary


def family_table(summary: dict[str, Any]) -> list[str]:
    """Markdown lines: per start and checkpoint, each family's solved / mean actions / optimum (empty with one
    family: the main table says it all)."""
    families = list(dict.fromkeys(b["family"] for b in summary.get("test_boxes", [])))
    if len(families) < 2:
        return []
    lines = [
        "Per family (solved, mean actions / optimum, all seeds):",
        "",
        "| start | robot hours | " + " | ".join(families) + " |",
        "|---|---|" + "---|" * len(families),
    ]
    for p in summary["points"]:
        if "sets" not in p:
            continue
        cells = [
            f"{s['success_rate']:.0%}, {s['mean_actions']:.2f} / {s['optimum']:.2f}"
            for s in (p["sets"][f] for f in families)
        ]
        lines.append(f"| {p['start']} | {p['hours']:g} | " + " | ".join(cells) + " |")
    return [*lines, ""]
