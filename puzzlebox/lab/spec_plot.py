"""Top view of a puzzle spec: the lid, each component's footprint, its x axis, and the lock rules."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: no display on these machines
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import FancyArrowPatch, Polygon, Rectangle  # noqa: E402

from puzzlebox.models import PuzzleSpec, get_kind  # noqa: E402
from puzzlebox.models.kinds import registered_kind  # noqa: E402


def plot_spec(spec: PuzzleSpec, path: Path) -> Path:
    """Write a PNG of the spec's layout in the lid frame [m]: arrows run from locker to locked,
    solid for 'locker closed keeps locked closed', dashed for every other state pair."""
    fig, ax = plt.subplots(figsize=(6.4, 5.2), dpi=110)
    if spec.box is not None:
        length, width, _ = spec.box.size
        ax.add_patch(Rectangle((-length / 2, -width / 2), length, width, fill=False, lw=1.5, color="0.3"))
    centres = {}
    for c in spec.components:
        template = get_kind(c.kind)
        polygon = template.footprint_in_lid(c.pose)
        goal = c.name == spec.goal.component
        ax.add_patch(
            Polygon(polygon, closed=True, alpha=0.35, color=registered_kind(c.kind).glyph, lw=2.5 if goal else 1)
        )
        x, y, yaw = c.pose[:3]
        centres[c.name] = np.array([x, y])
        ax.annotate("", (x + 0.025 * np.cos(yaw), y + 0.025 * np.sin(yaw)), (x, y), arrowprops={"arrowstyle": "->"})
        label = f"{c.name}\n#{c.marker}" + ("\nGOAL" if goal else "")
        ax.text(x, y - 0.012, label, ha="center", va="top", fontsize=7)
    for rule in spec.locks:
        a, b = centres[rule.locker], centres[rule.locked]
        solid = rule.locker_state == 0 and rule.locked_state == 0
        ax.add_patch(
            FancyArrowPatch(
                a, b, arrowstyle="-|>", mutation_scale=10, color="crimson" if solid else "0.4",
                linestyle="-" if solid else "--", connectionstyle="arc3,rad=0.15", shrinkA=8, shrinkB=8,
            )
        )  # fmt: skip
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x in lid frame [m]")
    ax.set_ylabel("y in lid frame [m]")
    ax.set_title(f"{spec.name}: {'-'.join(spec.kinds)}", fontsize=9)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)
    return path
