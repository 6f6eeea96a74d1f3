"""Run a grid of trials — specs (or a generator recipe) x placements x seeds x agents x reality profiles — and
aggregate it.

    python scripts/sweep.py SWEEP.json --out DIR [--workers K | --ray auto|ADDRESS] [--resume | --force]

The sweep file's format is in ``puzzlebox/lab/sweep_grid.py``. Writes ``DIR/results.json`` (the contract of
``trial.py``: success rate, mean actions, every run; plus ``cells``, one summary per spec, placement, agent
and profile), ``DIR/cells.md`` (the per-cell table) and ``DIR/cells.png`` (success and mean actions per
cell). Every trial is a task of ``puzzlebox.lab.runner``, its record in ``DIR/runs/`` the moment it ends: a
kill keeps every finished trial, and the same command with ``--resume`` computes only what is missing.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from puzzlebox.lab.cell_bars import cell_bars
from puzzlebox.lab.cli import OneLineParser, fail, one_line, run_script
from puzzlebox.lab.errors import RunStoreError
from puzzlebox.lab.inputs import MAX_WORKERS
from puzzlebox.lab.interrupt import StopRequests
from puzzlebox.lab.run_store import Periodic, RunStore
from puzzlebox.lab.runner import RunnerError, make_executor, run_tasks
from puzzlebox.lab.sweep_grid import Cell, SweepError, grid, load_sweep
from puzzlebox.learning import LearningError, summarise
from puzzlebox.models import ModelsError
from puzzlebox.twin.errors import TwinError


def cell_summaries(records: dict[str, dict], cells: dict[str, Cell], max_actions: int) -> list[dict[str, Any]]:
    """One summary per cell, in grid order: runs done, success rate, mean actions (an unsolved run counts
    ``max_actions``) and, for twin runs, outcome agreement and the largest true wrist force [N]."""
    grouped: dict[Cell, list[dict]] = {}
    for key, cell in cells.items():
        grouped.setdefault(cell, [])
        if key in records:
            grouped[cell].append(records[key])
    out = []
    for cell, runs in grouped.items():
        row: dict[str, Any] = {"cell": cell.label, "spec": cell.spec, "placement": cell.placement,
                               "box_pose": cell.box_pose, "agent": cell.agent, "profile": cell.profile,
                               "runs_done": len(runs)}  # fmt: skip
        if runs:
            s = summarise(list(runs), max_actions)
            row.update(success_rate=s["success_rate"], mean_actions=s["mean_actions"])
            timeline = [a for r in runs for a in r.get("timeline", [])]
            if timeline:
                row["outcome_agreement"] = sum(a["moved"] == a["true_moved"] for a in timeline) / len(timeline)
                row["peak_true_wrist_force_n"] = max(r["peak_true_wrist_force_n"] for r in runs)
        out.append(row)
    return out


def cells_table(rows: list[dict[str, Any]]) -> str:
    lines = ["| spec | placement | agent | profile | runs | solved | mean actions | agreement |", "|---" * 8 + "|"]
    for r in rows:
        pose = (
            "profile's" if r["placement"] is None else f"p{r['placement']} {tuple(round(v, 3) for v in r['box_pose'])}"
        )
        solved = f"{r['success_rate']:.0%}" if "success_rate" in r else "-"
        mean = f"{r['mean_actions']:.2f}" if "mean_actions" in r else "-"
        agree = f"{r['outcome_agreement']:.1%}" if "outcome_agreement" in r else "-"
        cells = (r["spec"], pose, r["agent"], r["profile"], r["runs_done"], solved, mean, agree)
        lines.append("| " + " | ".join(map(str, cells)) + " |")
    return "\n".join(lines) + "\n"


def cells_plot(rows: list[dict[str, Any]], path: Path) -> Path:
    """Success rate and mean actions per cell, one bar each, grouped as the grid is."""
    import matplotlib.pyplot as plt

    fig = cell_bars(rows)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("sweep", help="sweep file (JSON)")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--workers", type=int, default=None, help="worker processes (default: one per core)")
    parser.add_argument("--ray", default=None, metavar="auto|ADDRESS", help="run on Ray: auto = a local cluster")
    parser.add_argument("--resume", action="store_true", help="continue the trials already in --out (same sweep)")
    parser.add_argument("--force", action="store_true", help="delete the results already in --out first")
    args = parser.parse_args(argv)
    if args.workers is not None and (args.workers < 1 or args.ray is not None):
        fail("--workers must be >= 1, and goes without --ray" if args.workers < 1 else "give --workers or --ray")
    if args.workers is not None and args.workers > MAX_WORKERS:  # each one a process: fork them all, then fail
        fail(f"--workers must be <= {MAX_WORKERS}, got {args.workers}")
    path = Path(args.sweep)
    try:
        sweep = load_sweep(path)
        tasks, cells = grid(sweep, path.resolve().parent)
        executor = make_executor(args.workers, args.ray)
    except (SweepError, ModelsError, LearningError, TwinError, OSError) as err:  # a calibration's is a ModelsError
        fail(f"{path}: {one_line(err)}" if not str(err).startswith(("sweep", "cannot read")) else one_line(err))
    out = Path(args.out)
    try:
        store = RunStore(out, {"command": "sweep", "sweep": sweep, "sweep_file": str(path)}, args.resume, args.force)
    except RunStoreError as err:
        fail(one_line(err))
    keys = [t.key for t in tasks]
    found: dict[str, dict] = {}

    def results() -> dict[str, Any]:
        runs = [found[k] for k in keys if k in found]
        summary = summarise(list(runs), sweep["max_actions"])
        summary.update(runs_done=len(runs), runs_planned=len(tasks),
                       cells=cell_summaries(found, cells, sweep["max_actions"]))  # fmt: skip
        return summary

    rewrite = Periodic(lambda: store.write_results(results()))

    def keep(task, record) -> None:
        found[task.key] = record
        rewrite()

    try:
        with store.keeping(), StopRequests("trial") as stop, executor:  # a full disk: one line, what is kept
            report = run_tasks(tasks, store.records, executor, stop=lambda: stop.requested, on_record=keep,
                               postfix=lambda r: f"solved {sum(x['solved'] for x in r.values())}/{len(r)}",
                               desc=f"sweep {path.stem}")  # fmt: skip
        found.update(report.records)
        summary = results()
        store.write_results(summary)
        with store.keeping():
            (out / "cells.md").write_text(cells_table(summary["cells"]), encoding="utf-8")
            cells_plot(summary["cells"], out / "cells.png")
    except RunnerError as err:
        fail(str(err))
    except RunStoreError as err:
        fail(one_line(err))
    n_cells = len(set(cells.values()))
    print(f"{len(report.records)} of {len(tasks)} trials ({len(report.reused)} reused) in {n_cells} cells: "
          f"success {summary['success_rate']:.1%}, mean actions {summary['mean_actions']:.2f} -> {out}")  # fmt: skip
    if report.failures:
        key, error = next(iter(report.failures.items()))
        print(f"error: {len(report.failures)} trial(s) failed (first: {key}: {error.splitlines()[0]}); "
              "--resume retries them", file=sys.stderr)  # fmt: skip
        return 1
    if report.stopped:
        print("stopped: continue with the same command and --resume", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    run_script(main)
