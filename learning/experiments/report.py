"""Figures (like the paper's Fig. 3 panels) and tables (ours beside the paper's) for protocol results."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless machines
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from learning.experiments.paper_numbers import PAPER  # noqa: E402

AGENT_STYLE = {"memory": "C0", "dual": "C1", "random": "C7", "oracle": "C2", "dqn": "C3", "model-based": "C4"}


def _agents(result: dict[str, Any]) -> list[str]:
    x_key = result["x"]
    return [k for k in result["points"][0] if k != x_key]


def plot(result: dict[str, Any], path: Path) -> Path:
    """Success rate and mean actions per agent against the protocol's x (error bars: std over seeds)."""
    x_key = result["x"]
    points = result["points"]
    agents = _agents(result)
    fig, (ax_success, ax_actions) = plt.subplots(1, 2, figsize=(10, 3.8), dpi=110)
    xs = [p[x_key] for p in points]
    categorical = isinstance(xs[0], str)
    positions = np.arange(len(xs)) if categorical else np.array(xs, dtype=float)
    width = 0.8 / max(len(agents), 1)
    for k, agent in enumerate(agents):
        success = np.array([100 * p[agent]["success_rate"] for p in points])
        success_std = np.array([100 * p[agent]["success_rate_std"] for p in points])
        actions = np.array([p[agent]["mean_actions"] for p in points])
        actions_std = np.array([p[agent]["mean_actions_std"] for p in points])
        colour = AGENT_STYLE.get(agent)
        if categorical:
            offset = positions + (k - (len(agents) - 1) / 2) * width
            ax_success.bar(offset, success, width, yerr=success_std, label=agent, color=colour)
            ax_actions.bar(offset, actions, width, yerr=actions_std, label=agent, color=colour)
        else:
            ax_success.errorbar(
                positions, success, yerr=success_std, marker="o", ms=3, capsize=2, label=agent, color=colour
            )
            ax_actions.errorbar(
                positions, actions, yerr=actions_std, marker="o", ms=3, capsize=2, label=agent, color=colour
            )
    for ax in (ax_success, ax_actions):
        ax.set_xlabel(x_key.replace("_", " "))
        if categorical:
            ax.set_xticks(positions, xs, rotation=15)
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


def comparison_table(result: dict[str, Any]) -> str:
    """Markdown table: ours beside the paper's, for every paper figure of this protocol."""
    x_key = result["x"]
    by_x = {p[x_key]: p for p in result["points"]}
    lines = ["| figure | agent | ours | paper |", "|---|---|---|---|"]
    for row in PAPER.get(result["protocol"], []):
        point = by_x.get(row["x"])
        entry = point.get(row["agent"]) if point else None
        if entry is None:
            ours = "not run"
        elif row["key"] == "success_rate":
            ours = f"{100 * entry['success_rate']:.1f}% ± {100 * entry['success_rate_std']:.1f}"
        else:
            ours = f"{entry['mean_actions']:.2f} ± {entry['mean_actions_std']:.2f}"
        paper = f"{100 * row['paper']:.1f}%" if row["key"] == "success_rate" else f"{row['paper']}"
        lines.append(f"| {row['what']} | {row['agent']} | {ours} | {paper} |")
    return "\n".join(lines)


def results_table(result: dict[str, Any]) -> str:
    """Markdown table of every point: success [%] / mean actions per agent."""
    x_key = result["x"]
    agents = _agents(result)
    lines = [f"| {x_key} | " + " | ".join(agents) + " |", "|---" * (len(agents) + 1) + "|"]
    for p in result["points"]:
        cells = [f"{100 * p[a]['success_rate']:.0f}% / {p[a]['mean_actions']:.2f}" for a in agents]
        lines.append(f"| {p[x_key]} | " + " | ".join(cells) + " |")
    return "\n".join(lines)
