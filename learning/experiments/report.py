"""Figures (like the paper's Fig. 3 panels) and tables (ours beside the paper's) for protocol results."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless machines
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from puzzlebox.learning.experiments.paper_numbers import CONVERGED, PAPER, PAPER_EPISODES_TO_SOLVE  # noqa: E402

AGENT_STYLE = {
    "memory": "C0",
    "dual": "C1",
    "random": "C7",
    "oracle": "C2",
    "dqn": "C3",
    "model-based": "C4",
    "mt-dqn": "C5",
    "mt-model-based": "C6",
}


def _agents(result: dict[str, Any]) -> list[str]:
    """Every agent of any point, in order of first appearance."""
    x_key = result["x"]
    seen: dict[str, None] = {}
    for point in result["points"]:
        seen.update({k: None for k in point if k != x_key})
    return list(seen)


def plot(result: dict[str, Any], path: Path) -> Path:
    """Success rate and mean actions per agent against the protocol's x (error bars: std over seeds).
    Episode counts spanning the deep agents' hundreds are drawn on a symmetric-log axis."""
    x_key = result["x"]
    points = result["points"]
    agents = _agents(result)
    fig, (ax_success, ax_actions) = plt.subplots(1, 2, figsize=(11, 4), dpi=110)
    xs = [p[x_key] for p in points]
    categorical = isinstance(xs[0], str)
    width = 0.8 / max(len(agents), 1)
    for k, agent in enumerate(agents):
        mine = [(i, p[agent]) for i, p in enumerate(points) if agent in p]
        index = np.array([i for i, _ in mine])
        success = np.array([100 * e["success_rate"] for _, e in mine])
        success_std = np.array([100 * e["success_rate_std"] for _, e in mine])
        actions = np.array([e["mean_actions"] for _, e in mine])
        actions_std = np.array([e["mean_actions_std"] for _, e in mine])
        colour = AGENT_STYLE.get(agent)
        if categorical:
            offset = index + (k - (len(agents) - 1) / 2) * width
            ax_success.bar(offset, success, width, yerr=success_std, label=agent, color=colour)
            ax_actions.bar(offset, actions, width, yerr=actions_std, label=agent, color=colour)
        else:
            x = np.array([xs[i] for i in index], dtype=float)
            style = {"marker": "o", "ms": 3, "capsize": 2, "label": agent, "color": colour}
            ax_success.errorbar(x, success, yerr=success_std, **style)
            ax_actions.errorbar(x, actions, yerr=actions_std, **style)
    for ax in (ax_success, ax_actions):
        ax.set_xlabel(x_key.replace("_", " "))
        if categorical:
            ax.set_xticks(np.arange(len(xs)), xs, rotation=15)
        elif max(xs) > 100:
            ax.set_xscale("symlog", linthresh=10)
        ax.grid(alpha=0.3)
    ax_success.set_ylabel("unseen variants solved in < 15 actions [%]")
    ax_success.set_ylim(-2, 102)
    ax_actions.set_ylabel("mean actions (unsolved = budget)")
    ax_actions.axhline(5, color="0.5", ls=":", lw=1)
    ax_actions.legend(fontsize=8)
    fig.suptitle(
        f"protocol '{result['protocol']}' ({result['config']['runs_per_variant']} runs x 3 unseen variants, "
        f"{result['config']['training_seeds']} training seed(s))",
        fontsize=9,
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path


def _resolve_x(x: object, result: dict[str, Any]) -> object:
    if x == CONVERGED:
        return result.get("deep_schedule", {}).get("converged_episodes")
    return x


def comparison_table(result: dict[str, Any]) -> str:
    """Markdown table: ours beside the paper's, for every paper figure of this protocol whose agent ran."""
    x_key = result["x"]
    by_x = {p[x_key]: p for p in result["points"]}
    ran = set(_agents(result))
    lines = ["| figure | agent | ours | paper |", "|---|---|---|---|"]
    for row in PAPER.get(result["protocol"], []):
        if row["agent"] not in ran:
            continue
        x = _resolve_x(row["x"], result)
        point = by_x.get(x)
        entry = point.get(row["agent"]) if point else None
        what = str(row["what"]).replace(CONVERGED, f"converged ({x} episodes)")
        if entry is None:
            ours = "not run"
        elif row["key"] == "success_rate":
            ours = f"{100 * entry['success_rate']:.1f}% ± {100 * entry['success_rate_std']:.1f}"
        else:
            ours = f"{entry['mean_actions']:.2f} ± {entry['mean_actions_std']:.2f}"
        paper = f"{100 * row['paper']:.1f}%" if row["key"] == "success_rate" else f"{row['paper']}"
        lines.append(f"| {what} | {row['agent']} | {ours} | {paper} |")
    return "\n".join(lines)


def results_table(result: dict[str, Any]) -> str:
    """Markdown table of every point: success [%] / mean actions per agent (— where not evaluated)."""
    x_key = result["x"]
    agents = _agents(result)
    lines = [f"| {x_key} | " + " | ".join(agents) + " |", "|---" * (len(agents) + 1) + "|"]
    for p in result["points"]:
        cells = [f"{100 * p[a]['success_rate']:.0f}% / {p[a]['mean_actions']:.2f}" if a in p else "—" for a in agents]
        lines.append(f"| {p[x_key]} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def episodes_to_solve(result: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """From an ``episodes`` result: per agent and training seed, the first evaluated episode count at
    which every unseen run succeeded (None: never within the schedule), their mean and std, and the
    count from which every later evaluation stayed at 100% (``stays_per_seed``)."""
    if result["protocol"] != "episodes":
        raise ValueError(f"episodes to solve needs the 'episodes' protocol, not {result['protocol']!r}")
    out = {}
    for agent in _agents(result):
        rows = [(p["training_episodes"], p[agent]) for p in result["points"] if agent in p]
        if not rows or "success_rate_per_seed" not in rows[0][1]:
            continue
        seeds = len(rows[0][1]["success_rate_per_seed"])
        first: list[int | None] = []
        stays: list[int | None] = []
        for t in range(seeds):
            solved = [e["success_rate_per_seed"][t] >= 1.0 for _, e in rows]
            first.append(next((x for (x, _), ok in zip(rows, solved, strict=True) if ok), None))
            tail = next((i for i in range(len(rows)) if all(solved[i:])), None)
            stays.append(None if tail is None else rows[tail][0])
        reached = [f for f in first if f is not None]
        out[agent] = {
            "per_seed": first,
            "stays_per_seed": stays,
            "mean": float(np.mean(reached)) if len(reached) == seeds else None,
            "std": float(np.std(reached)) if len(reached) == seeds else None,
            "last_evaluated": max(x for x, _ in rows),
        }
    return out


def episodes_to_solve_table(result: dict[str, Any]) -> str:
    """Markdown: episodes to 100% on the unseen variants per agent (mean ± std over seeds) vs the paper."""
    lines = [
        "| agent | ours: episodes to 100% (mean ± std) | per seed | at 100% for good from (per seed) | paper |",
        "|---|---|---|---|---|",
    ]
    for agent, e in episodes_to_solve(result).items():
        if e["mean"] is not None:
            ours = f"{e['mean']:.0f} ± {e['std']:.0f}"
        else:
            ours = f"not all seeds within {e['last_evaluated']}"
        seeds = ", ".join("never" if f is None else str(f) for f in e["per_seed"])
        stays = ", ".join("—" if f is None else str(f) for f in e["stays_per_seed"])
        lines.append(f"| {agent} | {ours} | {seeds} | {stays} | {PAPER_EPISODES_TO_SOLVE.get(agent, '—')} |")
    return "\n".join(lines)
