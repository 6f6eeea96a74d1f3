"""The success rate and mean actions of a sweep's cells, one bar each in grid order: the figure ``sweep.py`` saves
beside its results and ``report.py`` puts in its page."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any


def cell_bars(cells: Sequence[dict[str, Any]], height: float = 6.0) -> Any:
    """A matplotlib figure (Agg) of the cells that finished (those with a ``success_rate``): solved fraction above,
    mean actions below, each cell's name under its bars; ``height`` [in]."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    done = [c for c in cells if "success_rate" in c]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(max(6.0, 0.35 * len(done) + 2), height), sharex=True)
    x = range(len(done))
    ax1.bar(x, [c["success_rate"] for c in done], color="#2e9d4a")
    ax1.set_ylabel("solved")
    ax1.set_ylim(0, 1.05)
    ax2.bar(x, [c["mean_actions"] for c in done], color="#3b75af")
    ax2.set_ylabel("mean actions")
    ax2.set_xticks(list(x), [str(c.get("cell", i)) for i, c in enumerate(done)], rotation=70, ha="right", fontsize=7)
    fig.tight_layout()
    return fig
