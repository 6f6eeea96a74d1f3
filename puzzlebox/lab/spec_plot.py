"""Top view of a puzzle spec: the lid, each component's footprint, its x axis, the goal and the lock rules, with a
legend that says what each arrow and colour means."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")  # headless: no display on these machines
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import FancyArrowPatch, Patch, Polygon, Rectangle  # noqa: E402

from puzzlebox.models import PuzzleSpec, get_kind  # noqa: E402
from puzzlebox.models.kinds import registered_kind  # noqa: E402

STATE_WORDS = ("closed", "open")
"""What states 0 and 1 are called in the legend."""
RULE_STYLES: dict[tuple[int, int], tuple[str, Any]] = {
    (0, 0): ("crimson", "-"),
    (1, 1): ("0.4", "--"),
    (0, 1): ("tab:blue", ":"),
    (1, 0): ("tab:purple", "-."),
}
"""Colour and line style of a lock rule's arrow by (locker state, locked state)."""


def _state(state: int) -> str:
    return STATE_WORDS[state] if 0 <= state < len(STATE_WORDS) else f"state {state}"


def rule_style(locker_state: int, locked_state: int) -> tuple[str, Any]:
    """The arrow's colour and line style for a rule "locker in ``locker_state`` keeps locked in ``locked_state``"."""
    return RULE_STYLES.get((locker_state, locked_state), ("tab:olive", (0, (1, 3))))


def plot_spec(spec: PuzzleSpec, path: Path) -> Path:
    """Write :func:`spec_figure` of ``spec`` as a PNG at ``path``."""
    fig = spec_figure(spec)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
    return path


def spec_figure(spec: PuzzleSpec) -> Figure:
    """The spec's layout in the lid frame [m]: each component's footprint in its kind's colour (the goal's outlined
    thick), an arrow from locker to locked per lock rule, its colour and line style by the two states
    (:data:`RULE_STYLES`), and a legend of the kinds, the goal, the parts' axes and the arrow styles present."""
    fig, ax = plt.subplots(figsize=(7.6, 5.2), dpi=110)
    if spec.box is not None:
        length, width, _ = spec.box.size
        ax.add_patch(Rectangle((-length / 2, -width / 2), length, width, fill=False, lw=1.5, color="0.3"))
    centres = {}
    handles: list = []
    kinds_seen: list[str] = []
    for c in spec.components:
        template = get_kind(c.kind)
        polygon = template.footprint_in_lid(c.pose)
        goal = c.name == spec.goal.component
        colour = registered_kind(c.kind).glyph
        ax.add_patch(Polygon(polygon, closed=True, alpha=0.35, color=colour, lw=0))
        ax.add_patch(
            Polygon(polygon, closed=True, fill=False, edgecolor="black" if goal else colour, lw=2.5 if goal else 1)
        )
        if c.kind not in kinds_seen:
            kinds_seen.append(c.kind)
            handles.append(Patch(facecolor=colour, alpha=0.5, label=f"{c.kind}"))
        x, y, yaw = c.pose[:3]
        centres[c.name] = np.array([x, y])
        ax.annotate("", (x + 0.025 * np.cos(yaw), y + 0.025 * np.sin(yaw)), (x, y), arrowprops={"arrowstyle": "->"})
        label = f"{c.name}\n#{c.marker}" + ("\nGOAL" if goal else "")
        ax.text(x, y - 0.012, label, ha="center", va="top", fontsize=7)
    handles.append(
        Patch(facecolor="white", edgecolor="black", lw=2.5,
              label=f"goal: {spec.goal.component} {_state(spec.goal.state)}")
    )  # fmt: skip
    handles.append(Line2D([], [], color="black", lw=1, marker=">", markevery=[-1], label="a part's x axis"))
    styles_seen: list[tuple[int, int]] = []
    for rule in spec.locks:
        a, b = centres[rule.locker], centres[rule.locked]
        colour, style = rule_style(rule.locker_state, rule.locked_state)
        ax.add_patch(
            FancyArrowPatch(
                a, b, arrowstyle="-|>", mutation_scale=10, color=colour, linestyle=style,
                connectionstyle="arc3,rad=0.15", shrinkA=8, shrinkB=8,
            )
        )  # fmt: skip
        states = (rule.locker_state, rule.locked_state)
        if states not in styles_seen:
            styles_seen.append(states)
            words = f"locker {_state(states[0])} keeps locked {_state(states[1])}"
            handles.append(Line2D([], [], color=colour, linestyle=style, marker=">", markevery=[-1], label=words))
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x in lid frame [m]")
    ax.set_ylabel("y in lid frame [m]")
    ax.set_title(f"{spec.name}: {'-'.join(spec.kinds)}", fontsize=9)
    legend_title = "arrows: locker -> locked" if spec.locks else "no lock rules"
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7, title=legend_title,
              title_fontsize=7, frameon=False)  # fmt: skip
    return fig
