"""Figure and tables of the disassembly experiment (:mod:`learning.experiments.disassembly`), beside the paper."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless machines
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"memory": "tab:blue", "memory-k2": "tab:cyan", "memory-k3": "tab:purple", "dual": "tab:gray",
           "dqn": "tab:red", "model-based": "tab:orange"}  # fmt: skip


def split_label(summary: dict[str, Any]) -> str:
    """What the tests were: the test computer and its variants, or (``validation``) variants of the training
    computer; and the hypothesis space when it is not the default."""
    config, tests = summary["config"], len(summary["tests"])
    if config.get("validation"):
        label = f"validation on {tests} variants of {config['train_scene']}"
    else:
        label = f"tested on {config['test_scene']} and {tests - 1} variants"
    if not config.get("holding_rule", True):
        label += ", removed parts may hold (the paper's hypotheses)"
    return label


def plot(summary: dict[str, Any], path: Path) -> Path:
    """Success rate and mean actions against training episodes on ``lab-computer-a``, one line per agent
    (shaded: +- one standard deviation over training seeds), with the optimum and the paper's memory agent."""
    fig, (ax_success, ax_actions) = plt.subplots(1, 2, figsize=(11, 4.2))
    for curve, rows in summary["curves"].items():
        x = [max(r["episodes"], 0.5) for r in rows]  # the untrained point (0) shown at 0.5 on the log axis
        colour = COLOURS.get(curve)
        for ax, key in ((ax_success, "success_rate"), (ax_actions, "mean_actions")):
            y = [r[key] * (100 if key == "success_rate" else 1) for r in rows]
            s = [r[f"{key}_std"] * (100 if key == "success_rate" else 1) for r in rows]
            ax.plot(x, y, "o-", color=colour, label=curve, markersize=4)
            ax.fill_between(x, [a - b for a, b in zip(y, s, strict=True)], [a + b for a, b in zip(y, s, strict=True)],
                            color=colour, alpha=0.15)  # fmt: skip
    budget = summary["config"]["max_actions"]
    ax_actions.axhline(summary["optimum"]["mean"], color="k", ls=":", label="optimum (mean over tests)")
    ax_actions.axhline(budget, color="k", ls="--", lw=0.8, label=f"budget ({budget})")
    paper = summary["paper"]["memory"]
    ax_actions.plot([1, paper["converged by"]], [paper["after one episode"], paper["converged"]], "*", color="tab:blue",
                    markersize=11, label="paper, memory (1 and 20 episodes)")  # fmt: skip
    for ax, label in ((ax_success, "success [%]"), (ax_actions, "mean actions (unsolved: budget)")):
        ax.set_xscale("log")
        ticks = [0.5, 1, 2, 5, 10, 20, 50, 100, 200]
        ax.set_xticks(ticks, ["0", "1", "2", "5", "10", "20", "50", "100", "200"])
        ax.minorticks_off()
        ax.set_xlabel(f"training episodes on {summary['config']['train_scene']}")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    ax_success.set_ylim(-3, 103)
    ax_actions.legend(fontsize=7, loc="upper right")
    fig.suptitle(f"Disassembly: {split_label(summary)} (motherboard out within {budget})")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def table(summary: dict[str, Any]) -> str:
    """Markdown: every curve's points, then ours beside the paper."""
    lines = [f"{split_label(summary).capitalize()}.", "",
             "| agent | training episodes | success | mean actions | seeds |", "|---|---|---|---|---|"]  # fmt: skip
    for curve, rows in summary["curves"].items():
        for r in rows:
            lines.append(
                f"| {curve} | {r['episodes']} | {100 * r['success_rate']:.1f} % +- {100 * r['success_rate_std']:.1f} "
                f"| {r['mean_actions']:.2f} +- {r['mean_actions_std']:.2f} | {r['seeds']} |"
            )
    optimum = summary["optimum"]
    lines += ["", f"Optimum (the oracle's shortest solution): {optimum['mean']:.2f} actions on average "
              f"({', '.join(f'{k} {v}' for k, v in optimum['per_test'].items())}).", ""]  # fmt: skip
    lines += ["| | paper | ours |", "|---|---|---|"]
    for curve in (c for c in summary["curves"] if c.startswith("memory")):
        by_episodes = {r["episodes"]: r for r in summary["curves"][curve]}
        for episodes, paper in ((1, "100 %, 20 actions"), (20, "100 %, 17 actions")):
            ours = by_episodes.get(episodes)
            text = f"{100 * ours['success_rate']:.1f} %, {ours['mean_actions']:.2f} actions" if ours else "not run"
            lines.append(f"| {curve} after {episodes} episode{'s' * (episodes > 1)} | {paper} | {text} |")
    for deep, paper in (("dqn", "dense rewards; briefly 100 % at ~150 episodes, not reliably"),
                        ("model-based", "dense rewards; did not converge reliably")):  # fmt: skip
        rows = summary["curves"].get(deep)
        if rows:
            best = max(rows, key=lambda r: (r["success_rate"], -r["mean_actions"]))
            text = f"best {100 * best['success_rate']:.1f} %, {best['mean_actions']:.2f} actions at {best['episodes']}"
            lines.append(f"| {deep} | {paper} | {text} |")
    return "\n".join(lines) + "\n"
