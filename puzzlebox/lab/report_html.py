"""The HTML page of ``scripts/report.py``: a trial or sweep directory read, checked and drawn as one page.

:func:`load_results_dir` reads a directory written by ``scripts/trial.py --out DIR`` (``config.json``,
``results.json``, ``runs/KEY.json``) or ``scripts/sweep.py SWEEP.json --out DIR`` (the same, with
``results.json``'s ``cells`` and ``config.json``'s ``"command": "sweep"``) and every ``*.mp4`` under it;
:func:`build_page` turns that into one HTML page: all CSS, the figures (matplotlib, inline SVG) and the small
script inline, nothing fetched from the network; videos are linked (``<video src>``, relative to the page), never
inlined. Every string that comes from the data is escaped (:func:`html.escape`).

The page opens with the annotated top view of each box a twin directory ran (linked PNGs that
:mod:`puzzlebox.lab.report_gallery` renders), then holds a summary table (a sweep: one row per cell with its
settings), the figures, the videos and every
run as a row (a twin run's with its box placement and reality profile) with a compact timeline: one block per
action, named by the part it tried, coloured by the sensed outcome, as wide as the action's simulated time (twin
runs; symbolic runs have no time: equal blocks), and a mark on each action whose sensed outcome (``moved``)
disagrees with the simulator's truth (``true_moved``).
"""

from __future__ import annotations

import html
import io
import json
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import quote

from puzzlebox.lab.cell_bars import cell_bars
from puzzlebox.lab.cli import one_line
from puzzlebox.models.json_input import JsonInputError, read_json

OUTCOME_COLOURS = {"moved": "#2e9d4a", "blocked": "#9aa3ad", "failed": "#d1495b"}
OTHER_COLOUR = "#8e6bbf"
"""Colour of a sensed outcome not in :data:`OUTCOME_COLOURS`."""


class ReportError(ValueError):
    """A directory that is not a trial or sweep directory, or one whose files cannot be read."""


@dataclass
class ResultsDir:
    """A trial or sweep directory as read: ``runs`` are ``(key, record)`` in key order; ``videos`` are the
    ``*.mp4`` files under ``path`` (absolute)."""

    path: Path
    kind: str  # "trial" or "sweep"
    config: dict[str, Any]
    results: dict[str, Any]
    runs: list[tuple[str, dict[str, Any]]]
    videos: list[Path] = field(default_factory=list)

    @property
    def cells(self) -> list[dict[str, Any]]:
        return list(self.results.get("cells") or [])


def _read_json(path: Path) -> Any:
    try:  # the shared reader: bounded in size and depth (a file nested thousands deep is one line, not a traceback)
        return read_json(path, allow_non_finite=True)
    except JsonInputError as err:
        raise ReportError(f"cannot read {path}: {one_line(err)}") from None


def load_results_dir(path: str | Path) -> ResultsDir:
    """Read a trial or sweep directory (see the module docstring); :class:`ReportError` says why not."""
    path = Path(path)
    if not path.is_dir():
        raise ReportError(f"{path} is not a directory (give a trial or sweep directory: --out of trial.py or sweep.py)")
    results_path, config_path, runs_dir = path / "results.json", path / "config.json", path / "runs"
    run_files = sorted(runs_dir.glob("*.json")) if runs_dir.is_dir() else []
    if not results_path.is_file() and not run_files:
        raise ReportError(
            f"{path} is not a trial or sweep directory: no results.json and no runs/*.json "
            "(written by scripts/trial.py or scripts/sweep.py --out DIR)"
        )
    config = _read_json(config_path) if config_path.is_file() else {}
    results = _read_json(results_path) if results_path.is_file() else {}
    if not isinstance(config, dict) or not isinstance(results, dict):
        raise ReportError(f"{path}: config.json and results.json must hold JSON objects")
    runs: list[tuple[str, dict[str, Any]]] = []
    for file in run_files:
        stored = _read_json(file)
        if not isinstance(stored, dict) or not isinstance(stored.get("record"), dict):
            raise ReportError(f"{file}: not a run record (expected an object with 'key' and 'record')")
        runs.append((str(stored.get("key", file.stem)), stored["record"]))
    if not runs:  # results.json alone (an older layout): its runs, keyed by position
        listed = results.get("runs", [])
        if not isinstance(listed, list) or not all(isinstance(r, dict) for r in listed):
            raise ReportError(f"{results_path}: 'runs' must be a list of run objects")
        runs = [(f"run-{i:03d}", r) for i, r in enumerate(listed)]
    if not runs:
        raise ReportError(f"{path} holds no runs: its results.json lists none and runs/ has no record")
    for key, record in runs:
        for name in ("solved", "num_actions"):
            if name not in record:
                raise ReportError(f"{path}: run {key} has no {name!r}: not a trial or sweep run record")
    kind = "sweep" if config.get("command") == "sweep" or "cells" in results else "trial"
    videos = sorted(
        p for p in path.rglob("*.mp4") if not any(part.startswith(".") for part in p.relative_to(path).parts)
    )
    return ResultsDir(path, kind, config, results, runs, videos)


# --- small formatting helpers ------------------------------------------------------------------------------------


def esc(value: object) -> str:
    """Any value as escaped HTML text (quotes too: safe inside attributes)."""
    return html.escape(str(value), quote=True)


def fmt(value: object, unit: str = "", digits: int = 2) -> str:
    """A number or value for a table cell (escaped); ``-`` for missing."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return esc(f"{value:.{digits}f}{unit}")
    if isinstance(value, int):
        return esc(f"{value}{unit}")
    return esc(value)


def pct(value: object) -> str:
    return esc(f"{value:.1%}") if isinstance(value, (int, float)) and not isinstance(value, bool) else "-"


def href(target: Path, page: Path) -> str:
    """``target`` as a URL relative to the page's directory (percent-encoded, then escaped)."""
    rel = os.path.relpath(target.resolve(), page.resolve().parent)
    return esc(quote(Path(rel).as_posix()))


def _table(head: list[str], rows: list[list[str]], cls: str = "") -> str:
    """A table from already escaped cells."""
    out = [f'<table class="{esc(cls)}"><thead><tr>' + "".join(f"<th>{esc(h)}</th>" for h in head) + "</tr></thead>"]
    out.append("<tbody>")
    out.extend("<tr>" + "".join(f"<td>{c}</td>" for c in row) + "</tr>" for row in rows)
    out.append("</tbody></table>")
    return "\n".join(out)


# --- summaries ---------------------------------------------------------------------------------------------------

SUMMARY_FIELDS = [
    ("success_rate", "success rate", pct),
    ("mean_actions", "mean actions", fmt),
    ("max_actions", "max actions", fmt),
    ("runs_done", "runs done", fmt),
    ("runs_planned", "runs planned", fmt),
    ("outcome_agreement", "outcome agreement (sensed = truth)", pct),
    ("actions_total", "actions (twin)", fmt),
    ("perceived_position_error_max_m", "perceived position error, max", lambda v: fmt(v * 1000, " mm", 1)),
    ("perceived_position_error_mean_m", "perceived position error, mean", lambda v: fmt(v * 1000, " mm", 1)),
    ("peak_true_wrist_force_n", "peak true wrist force", lambda v: fmt(v, " N", 1)),
    ("wall_time_per_trial_s_max", "wall time per trial, max", lambda v: fmt(v, " s", 1)),
    ("wall_time_per_trial_s_mean", "wall time per trial, mean", lambda v: fmt(v, " s", 1)),
    ("sim_over_wall", "simulated / wall time", lambda v: fmt(v, "x", 2)),
]


def summary_table(data: ResultsDir) -> str:
    """The results' headline figures, whatever they hold (missing ones are left out)."""
    res = data.results
    rows = [[esc(label), show(res[key])] for key, label, show in SUMMARY_FIELDS if res.get(key) is not None]
    if not rows:  # no results.json: from the records
        solved = [r["solved"] for _, r in data.runs]
        rows = [[esc("success rate"), pct(sum(solved) / len(solved))], [esc("runs"), fmt(len(solved))]]
    if res.get("failed_tries_by_reason"):
        reasons = res["failed_tries_by_reason"].items()
        rows.append([esc("failed tries by reason"), esc(", ".join(f"{k}: {v}" for k, v in reasons))])
    for line in res.get("unsolved_reasons") or []:
        rows.append([esc("unsolved"), esc(line)])
    return _table(["figure", "value"], rows, "summary")


def cell_runs(data: ResultsDir) -> list[list[str]]:
    """The run keys of each of the sweep's cells (in ``results.json``'s order): a sweep's run key is
    ``{spec index:03d}-{spec}-p{placement}-{agent}-{profile}-seed{seed}`` (``puzzlebox/lab/sweep_grid.py``)."""
    cells = data.cells
    spec_index: dict[str, int] = {}
    for c in cells:
        spec_index.setdefault(str(c.get("spec")), len(spec_index))
    out: list[list[str]] = []
    for c in cells:
        middle = f"{c.get('spec')}-p{c.get('placement') or 0}-{c.get('agent')}-{c.get('profile')}-seed"
        pattern = re.compile(rf"^\d{{3}}-{re.escape(middle)}\d+$")
        exact = f"{spec_index[str(c.get('spec'))]:03d}-{middle}"
        keys = [k for k, _ in data.runs if pattern.match(k)]
        preferred = [k for k in keys if k.startswith(exact)]
        out.append(preferred or keys)
    return out


def cells_table(data: ResultsDir) -> str:
    """One row per cell: its settings, then what its runs did."""
    rows = []
    for i, c in enumerate(data.cells):
        pose = c.get("box_pose")
        where = (
            "profile's"
            if c.get("placement") is None
            else f"p{c['placement']} " + ("(" + ", ".join(f"{v:.3f}" for v in pose) + ")" if pose else "")
        )
        force = c.get("peak_true_wrist_force_n")
        rows.append([
            f'<a href="#cell-{i}">{esc(c.get("cell", i))}</a>', esc(c.get("spec", "-")), esc(where),
            esc(c.get("agent", "-")), esc(c.get("profile", "-")), fmt(c.get("runs_done")),
            pct(c.get("success_rate")), fmt(c.get("mean_actions")), pct(c.get("outcome_agreement")),
            fmt(force, " N", 1) if force is not None else "-",
        ])  # fmt: skip
    head = ["cell", "spec", "placement", "agent", "profile", "runs", "solved", "mean actions", "agreement", "peak F"]
    return _table(head, rows, "cells")


# --- timelines ---------------------------------------------------------------------------------------------------


def actions_of(record: dict[str, Any]) -> tuple[list[dict[str, Any]], bool]:
    """A run's actions and whether they are a twin ``timeline`` (with truth, force and time)."""
    if isinstance(record.get("timeline"), list):
        return record["timeline"], True
    return list(record.get("actions") or []), False


def disagrees(action: dict[str, Any]) -> bool:
    """Whether the sensed outcome (``moved``) disagrees with the simulator's truth (``true_moved``)."""
    truth = action.get("true_moved")
    return truth is not None and "moved" in action and bool(action["moved"]) != bool(truth)


def timeline_html(record: dict[str, Any], scale: float) -> str:
    """One run as a horizontal bar: one block per action, ``sim_time / scale`` of the bar wide (twin) or
    ``1 / scale`` (symbolic, ``scale`` = most actions of a run), coloured by the sensed outcome, with a mark
    where the sensed outcome disagrees with the truth."""
    actions, twin = actions_of(record)
    blocks = []
    for i, a in enumerate(actions):
        outcome = str(a.get("outcome", "?"))
        colour = OUTCOME_COLOURS.get(outcome, OTHER_COLOUR)
        size = float(a.get("sim_time") or 0.0) if twin else 1.0
        width = max(100.0 * size / scale, 0.15) if scale > 0 else 0.15
        tip = [f"#{i + 1} {a.get('component', '?')}"]
        if a.get("kind"):
            tip.append(f"kind {a['kind']}")
        tip.append(f"sensed {outcome}" + (f" ({a['reason']})" if a.get("reason") else ""))
        if twin:
            tip.append(f"truth {'moved' if a.get('true_moved') else 'not moved'}"
                       if a.get("true_moved") is not None else "truth unknown")  # fmt: skip
            if a.get("peak_force") is not None:
                tip.append(f"peak force {float(a['peak_force']):.1f} N")
            if a.get("sim_time") is not None:
                tip.append(f"sim {float(a['sim_time']):.2f} s")
            if a.get("attempts", 1) != 1:
                tip.append(f"{a['attempts']} attempts")
        mark = ""
        if disagrees(a):
            sensed = "moved" if a.get("moved") else "not moved"
            truth = "moved" if a.get("true_moved") else "not moved"
            mark = f'<span class="mark" title="{esc(f"sensed {sensed}, truth {truth}")}">!</span>'
        name = f'<span class="nm">{esc(a.get("component", ""))}</span>'
        blocks.append(
            f'<span class="act" data-i="{i}" data-outcome="{esc(outcome)}" style="width:{width:.3f}%;'
            f'background:{colour}" title="{esc("; ".join(tip))}">{name}{mark}</span>'
        )
    return f'<div class="tl" data-actions="{len(actions)}">' + "".join(blocks) + "</div>"


def timeline_scale(runs: list[tuple[str, dict[str, Any]]]) -> tuple[float, float]:
    """The common scales of the page's timelines: (most simulated time of a twin run [s], most actions of a
    symbolic run), so runs compare at a glance."""
    sim, count = 0.0, 0.0
    for _, record in runs:
        actions, twin = actions_of(record)
        if twin:
            sim = max(sim, sum(float(a.get("sim_time") or 0.0) for a in actions))
        else:
            count = max(count, float(len(actions)))
    return sim, count


def placement(pose: object) -> str:
    """A box pose ``[x, y, yaw]`` [m, m, rad] as table text (escaped): ``x 0.338 y -0.046 m, yaw 53°``."""
    if not isinstance(pose, (list, tuple)) or len(pose) != 3:
        return "-"
    try:
        x, y, yaw = (float(v) for v in pose)
    except (TypeError, ValueError):
        return "-"
    return esc(f"x {x:.3f} y {y:.3f} m, yaw {math.degrees(yaw):.0f}\u00b0")


def run_video(record: dict[str, Any], videos: list[Path], base: Path, single: bool) -> Path | None:
    """The video ``trial.py --video`` wrote for this run, if it is there."""
    names = [f"rollout-{record.get('spec')}-s{record.get('seed')}.mp4"] + (["rollout.mp4"] if single else [])
    for name in names:
        for v in videos:
            if v.name == name and v.parent == base:
                return v
    return None


def runs_table(data: ResultsDir, keys: list[str], page: Path) -> str:
    by_key = dict(data.runs)
    sim_scale, count_scale = timeline_scale(data.runs)
    twin_any = any(actions_of(r)[1] for _, r in data.runs)
    rows = []
    for key in keys:
        r = by_key[key]
        actions, twin = actions_of(r)
        video = run_video(r, data.videos, data.path, single=len(data.runs) == 1)
        link = f' <a href="{href(video, page)}">video</a>' if video is not None else ""
        ended = f'<div class="ended">{esc(r["ended"])}</div>' if r.get("ended") else ""
        row = [
            f'<span class="key">{esc(key)}</span>{link}', esc(r.get("spec", "-")), fmt(r.get("seed")),
            '<span class="ok">yes</span>' if r.get("solved") else '<span class="no">no</span>',
            fmt(r.get("num_actions")), fmt(r.get("wall_time_s"), " s", 2),
        ]  # fmt: skip
        if twin_any:
            mism = sum(disagrees(a) for a in actions)
            row += [
                placement(r.get("box_pose")) if twin else "-",
                fmt(r.get("reality")) if twin else "-",
                fmt(r.get("sim_time_s"), " s", 1),
                fmt(r.get("peak_true_wrist_force_n"), " N", 1),
                fmt(mism) if twin else "-",
            ]
        row.append(timeline_html(r, sim_scale if twin else count_scale) + ended)
        rows.append(row)
    head = ["run", "spec", "seed", "solved", "actions", "wall"]
    if twin_any:
        head += ["placement", "reality", "sim", "peak F", "disagree"]
    head.append("timeline")
    return _table(head, rows, "runs")


# --- figures -----------------------------------------------------------------------------------------------------


def _svg(fig: Any, salt: str) -> str:
    import matplotlib.pyplot as plt

    buffer = io.StringIO()
    with plt.rc_context({"svg.fonttype": "none", "svg.hashsalt": salt}):
        fig.savefig(buffer, format="svg", bbox_inches="tight")
    plt.close(fig)
    text = buffer.getvalue()
    return text[text.index("<svg") :]  # no XML declaration or doctype inside HTML


def force_figure(forces: list[tuple[dict[str, Any], float]]) -> Any:
    """The peak wrist force of each action (all runs, in order) [N], coloured by its sensed outcome, circled where
    the sensed outcome disagrees with the truth; the actions on integer ticks."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    fig, ax = plt.subplots(figsize=(5, 2.6))
    for outcome in sorted({str(a.get("outcome")) for a, _ in forces}):
        pts = [(i, f) for i, (a, f) in enumerate(forces) if str(a.get("outcome")) == outcome]
        ax.scatter([p[0] for p in pts], [p[1] for p in pts], s=14, label=outcome,
                   color=OUTCOME_COLOURS.get(outcome, OTHER_COLOUR))  # fmt: skip
    bad = [(i, f) for i, (a, f) in enumerate(forces) if disagrees(a)]
    if bad:
        ax.scatter([p[0] for p in bad], [p[1] for p in bad], s=60, facecolors="none", edgecolors="black",
                   label="sensed != truth")  # fmt: skip
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # actions are counted, never halved
    ax.set_xlabel("action (all runs, in order)")
    ax.set_ylabel("peak wrist force [N]")
    ax.legend(fontsize=7)
    return fig


def figures(data: ResultsDir) -> list[tuple[str, str]]:
    """(caption, inline SVG) of each figure the data allows."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    out = []
    counts = [int(r.get("num_actions", 0)) for _, r in data.runs]
    solved = [bool(r.get("solved")) for _, r in data.runs]
    if counts:
        fig, ax = plt.subplots(figsize=(5, 2.6))
        top = max(counts) + 1
        bins = range(0, top + 1)
        ax.hist([c for c, s in zip(counts, solved, strict=True) if s], bins=bins, color="#2e9d4a", label="solved")
        ax.hist([c for c, s in zip(counts, solved, strict=True) if not s], bins=bins, color="#d1495b",
                label="unsolved", alpha=0.8)  # fmt: skip
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("actions per run")
        ax.set_ylabel("runs")
        ax.legend(fontsize=8)
        out.append(("Actions per run", _svg(fig, "actions")))
    if any("success_rate" in c for c in data.cells):
        fig = cell_bars(data.cells, height=4.5)
        out.append(("Success and mean actions per cell", _svg(fig, "cells")))
    timeline = [a for _, r in data.runs for a in actions_of(r)[0] if actions_of(r)[1]]
    forces = [(a, float(a["peak_force"])) for a in timeline if a.get("peak_force") is not None]
    if forces:
        fig = force_figure(forces)
        out.append(("Peak wrist force per action", _svg(fig, "forces")))
    return out


# --- the page ----------------------------------------------------------------------------------------------------

CSS = """
body{font:14px/1.4 system-ui,sans-serif;margin:1.5em auto;max-width:1300px;padding:0 1em;color:#222}
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;margin:.5em 0}th,td{border:1px solid #ddd;padding:2px 6px;text-align:left;
vertical-align:middle;white-space:nowrap}th{background:#f4f4f4}table.runs td:last-child{width:60%;white-space:normal}
table.summary td,.ended{white-space:normal}
.tl{display:flex;height:16px;background:#f7f7f7;border:1px solid #ccc;overflow:hidden;min-width:300px}
.act{position:relative;display:inline-block;height:100%;box-sizing:border-box;border-right:1px solid #fff;
overflow:hidden}.nm{display:block;color:#fff;font:10px/16px sans-serif;padding-left:2px;white-space:nowrap;
overflow:hidden;text-overflow:clip}
.mark,.flag{position:absolute;left:0;right:0;top:0;bottom:0;color:#fff;background:repeating-linear-gradient(45deg,
#000 0 2px,transparent 2px 5px);font:bold 11px/16px sans-serif;text-align:center}
.legend>span{display:inline-block;padding:0 6px;margin-right:6px;color:#fff;border-radius:2px}
.sample{position:relative;width:2em;height:14px;background:#666;vertical-align:middle}
.ok{color:#2e7d32;font-weight:bold}.no{color:#c62828;font-weight:bold}.key{font-family:monospace;font-size:12px}
.ended{color:#c62828;font-size:12px}figure{display:inline-block;margin:0 1em 1em 0;vertical-align:top}
figure svg{max-width:100%;height:auto}figure.box img{width:560px;max-width:100%;height:auto;display:block}
figure.many img{width:360px}figure.box figcaption{max-width:560px}figure.many figcaption{max-width:360px}
video{max-width:640px;display:block}pre{background:#f7f7f7;padding:.5em;
overflow:auto;max-height:20em}.muted{color:#777}
"""

SCRIPT = (
    "window.addEventListener('load',function(){document.documentElement.setAttribute("
    "'data-load-ms',String(Math.round(performance.now())));});"
)
"""Records the page's load time (ms from navigation to ``load``) on ``<html data-load-ms>``: a headless
browser's ``--dump-dom`` shows it."""


def legend() -> str:
    items = [f'<span style="background:{c}">{esc(o)}</span>' for o, c in OUTCOME_COLOURS.items()]
    items.append(f'<span style="background:{OTHER_COLOUR}">other</span>')
    items.append('<span class="sample"><span class="flag">!</span></span> sensed outcome disagrees with the truth')
    return (
        '<p class="legend">Blocks: one per action, named by the part it tried, coloured by the sensed outcome: '
        + "".join(items)
        + "</p>"
    )


def top_views_html(top_views: dict[str, Path], page: Path) -> str:
    """The boxes' annotated top views (:mod:`puzzlebox.lab.report_gallery`), linked, each captioned by its spec."""
    size = "box" if len(top_views) == 1 else "box many"  # several boxes: side by side, smaller
    figures = [
        f'<figure class="{size}"><img src="{href(path, page)}" alt="annotated top view of {esc(name)}">'
        f"<figcaption>{esc(name)}: parts named, the goal ringed, each lock feature in its locker's colour"
        "</figcaption></figure>"
        for name, path in top_views.items()
    ]
    return '<h2 id="boxes">The box' + ("es" if len(figures) > 1 else "") + "</h2>" + "".join(figures)


def build_page(data: ResultsDir, page: Path, top_views: dict[str, Path] | None = None) -> str:
    """The whole page (a string) for ``data``, its links relative to ``page`` (where it will be written); with
    ``top_views`` (spec name -> annotated top view, :func:`puzzlebox.lab.report_gallery.write_top_views`) they open
    the page."""
    config = data.config
    title = f"{data.kind} report: {data.path.resolve().name}"
    what = []
    if config.get("command") == "trial":
        what = [f"sim {config.get('sim')}", f"agent {config.get('agent')}", f"{config.get('runs')} run(s) per spec",
                f"seed {config.get('seed')}", f"max actions {config.get('max_actions')}"]  # fmt: skip
        if config.get("sim") == "twin":
            what.append(f"reality {config.get('reality')}")
    elif config.get("command") == "sweep" and isinstance(config.get("sweep"), dict):
        sweep = config["sweep"]
        what = [f"sweep {config.get('sweep_file', '')}", f"sim {sweep.get('sim')}",
                f"max actions {sweep.get('max_actions')}", f"{len(data.cells)} cell(s)"]  # fmt: skip
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{esc(title)}</title><style>{CSS}</style><script>{SCRIPT}</script></head><body>",
        f"<h1>{esc(title)}</h1>",
        f'<p class="muted">{esc(data.path)} &middot; {esc(", ".join(str(w) for w in what))} &middot; '
        f"{len(data.runs)} run(s)</p>",
        top_views_html(top_views, page) if top_views else "",
        '<h2 id="summary">Summary</h2>',
        summary_table(data),
    ]
    if data.kind == "sweep" and data.cells:
        parts += ['<h2 id="cells">Cells</h2>', cells_table(data)]
    figs = figures(data)
    if figs:
        parts.append('<h2 id="figures">Figures</h2>')
        parts += [f"<figure>{svg}<figcaption>{esc(caption)}</figcaption></figure>" for caption, svg in figs]
    if data.videos:
        parts.append('<h2 id="videos">Videos</h2>')
        for v in data.videos:
            rel = esc(Path(os.path.relpath(v, data.path)).as_posix())
            parts.append(f'<figure><video controls preload="metadata" src="{href(v, page)}"></video>'
                         f"<figcaption>{rel}</figcaption></figure>")  # fmt: skip
    parts += ['<h2 id="runs">Runs</h2>', legend()]
    if data.kind == "sweep" and data.cells:
        placed: set[str] = set()
        for i, (cell, keys) in enumerate(zip(data.cells, cell_runs(data), strict=True)):
            parts.append(f'<h3 id="cell-{i}">{esc(cell.get("cell", i))}</h3>')
            parts.append(runs_table(data, keys, page) if keys else '<p class="muted">no runs yet</p>')
            placed.update(keys)
        rest = [k for k, _ in data.runs if k not in placed]
        if rest:
            parts += ["<h3>Runs in no cell</h3>", runs_table(data, rest, page)]
    else:
        parts.append(runs_table(data, [k for k, _ in data.runs], page))
    parts += [
        '<h2 id="config">Configuration</h2>',
        f"<details><summary>config.json</summary><pre>{esc(json.dumps(config, indent=2))}</pre></details>",
        "</body></html>",
    ]
    return "\n".join(parts) + "\n"
