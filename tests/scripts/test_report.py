"""report.py turns a trial or sweep directory into one well-formed, self-contained HTML page: every run with a
timeline of one block per action, a mark exactly where the sensed outcome disagrees with the truth, videos linked
(not inlined) by paths that resolve, small and fast to load; anything else is refused in one line."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlparse

import _shared as shared
import imageio.v3 as iio
import pytest

ROOT = Path(__file__).resolve().parents[2]
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}
MAX_BYTES = 20_000_000


def script(name: str, *args, cwd: Path | None = None, timeout: float = 600) -> subprocess.CompletedProcess:
    command = [sys.executable, str(ROOT / "scripts" / name), *map(str, args)]
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, cwd=cwd)


def ok(result: subprocess.CompletedProcess) -> subprocess.CompletedProcess:
    assert result.returncode == 0, result.stderr
    return result


class Page(HTMLParser):
    """A page parsed: tag balance, every src/href, and each timeline (its run key, actions and marks)."""

    def __init__(self, text: str) -> None:
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.errors: list[str] = []
        self.links: list[tuple[str, str]] = []
        self.keys: list[str] = []
        self.timelines: list[dict] = []
        self.tables: list[str] = []
        self._in_key = False
        self._in_tl, self._tl_at = False, 0
        self.feed(text)
        self.close()
        if self.stack:
            self.errors.append(f"unclosed at the end: {self.stack}")

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for name in ("src", "href"):
            if a.get(name):
                self.links.append((tag, a[name]))
        classes = (a.get("class") or "").split()
        if tag == "table":
            self.tables.append(a.get("class") or "")
        if "key" in classes:
            self._in_key = True
        if tag == "div" and "tl" in classes:
            self.timelines.append({"key": self.keys[-1] if self.keys else None, "declared": int(a["data-actions"]),
                                   "actions": []})  # fmt: skip
            self._in_tl, self._tl_at = True, len(self.stack)
        if self._in_tl and "act" in classes:
            self.timelines[-1]["actions"].append({"i": int(a["data-i"]), "outcome": a["data-outcome"], "mark": False})
        if self._in_tl and "mark" in classes:
            self.timelines[-1]["actions"][-1]["mark"] = True
        if tag not in VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        pass  # <path .../> in the SVG figures: balanced by itself

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes {self.stack[-1] if self.stack else 'nothing'}")
            return
        self.stack.pop()
        if tag == "div" and self._in_tl and len(self.stack) == self._tl_at:
            self._in_tl = False

    def handle_data(self, data):
        if self._in_key:
            self.keys.append(data.strip())
            self._in_key = False


def check_page(page: Path) -> Page:
    """Well-formed, under 20 MB, no network, and every link resolves to a file relative to the page."""
    text = page.read_text(encoding="utf-8")
    assert page.stat().st_size < MAX_BYTES
    parsed = Page(text)
    assert parsed.errors == [], parsed.errors[:5]
    assert text.startswith("<!DOCTYPE html>")
    assert "base64" not in text, "videos and figures are not inlined as base64 (figures are SVG)"
    for tag, link in parsed.links:
        url = urlparse(link)
        if link.startswith("#"):
            assert f'id="{link[1:]}"' in text, link
            continue
        assert url.scheme == "" and url.netloc == "", f"{tag} links outside the page: {link}"
        target = (page.parent / unquote(url.path)).resolve()
        assert target.is_file(), f"<{tag}> {link} does not resolve from {page.parent}"
    return parsed


def records(directory: Path) -> dict[str, dict]:
    return {
        json.loads(p.read_text())["key"]: json.loads(p.read_text())["record"]
        for p in sorted((directory / "runs").glob("*.json"))
    }


def check_timelines(parsed: Page, runs: dict[str, dict]) -> None:
    """Every run once, as many blocks as actions, a mark exactly where sensed != truth."""
    assert sorted(t["key"] for t in parsed.timelines) == sorted(runs)
    for t in parsed.timelines:
        record = runs[t["key"]]
        actions = record.get("timeline", record["actions"])
        assert t["declared"] == len(t["actions"]) == len(actions) == record["num_actions"], t["key"]
        assert [a["i"] for a in t["actions"]] == list(range(len(actions)))
        assert [a["outcome"] for a in t["actions"]] == [a["outcome"] for a in actions]
        expected = [a.get("true_moved") is not None and a["moved"] != a["true_moved"] for a in actions]
        assert [a["mark"] for a in t["actions"]] == expected, t["key"]


@pytest.fixture(scope="module")
def made(tmp_path_factory) -> Path:
    """Specs, a symbolic trial (3 runs) and a symbolic sweep of 30 runs, made by the project's own commands."""
    base = tmp_path_factory.mktemp("report")
    ok(script("generate.py", "paper", "--split", "test", "--out", base / "specs"))
    ok(script("trial.py", "--specs", base / "specs/paper-test-0.json", "--sim", "symbolic", "--agent", "dual",
              "--runs", 3, "--seed", 0, "--max-actions", 30, "--out", base / "trial"))  # fmt: skip
    sweep = {"sim": "symbolic", "specs": ["specs/paper-test-*.json"], "seeds": {"start": 0, "count": 5},
             "agents": ["oracle", "dual"], "max_actions": 30}  # fmt: skip
    (base / "sweep.json").write_text(json.dumps(sweep))
    ok(script("sweep.py", base / "sweep.json", "--out", base / "sweep", "--workers", 1))
    return base


def test_a_symbolic_trial_report_shows_every_run_with_one_block_per_action(made):
    result = ok(script("report.py", made / "trial"))
    page = made / "trial" / "report.html"
    assert f"({page.stat().st_size} bytes" in result.stdout
    assert not list((made / "trial").glob(".report.html.*")), "the temporary of the atomic write is gone"
    parsed = check_page(page)
    check_timelines(parsed, records(made / "trial"))
    assert "summary" in parsed.tables
    text = page.read_text()
    assert "success rate" in text and "100.0%" in text
    assert "<img" not in text and not (made / "trial" / "gallery").exists(), "a symbolic trial renders no picture"


def test_a_30_run_sweep_report_has_a_row_per_cell_and_every_run_under_its_cell(made):
    result = ok(script("report.py", made / "sweep", "--out", made / "elsewhere" / "sweep.html"))
    page = made / "elsewhere" / "sweep.html"
    parsed = check_page(page)
    runs = records(made / "sweep")
    assert len(runs) == 30
    check_timelines(parsed, runs)
    text = page.read_text()
    cells = json.loads((made / "sweep" / "results.json").read_text())["cells"]
    table = text[text.index('<table class="cells">') : text.index("</table>", text.index('<table class="cells">'))]
    assert table.count("<tr>") == len(cells) + 1 == 7
    for i, cell in enumerate(cells):  # each cell's section holds exactly its 5 runs
        start = text.index(f'<h3 id="cell-{i}">')
        end = text.index("<h3", start + 1) if i + 1 < len(cells) else text.index('<h2 id="config">')
        keys = re.findall(r'<span class="key">([^<]+)</span>', text[start:end])
        assert len(keys) == 5 and all(
            f"-{cell['spec']}-p0-{cell['agent']}-{cell['profile']}-seed" in k for k in keys
        ), keys
    assert page.stat().st_size < 2_000_000
    print(result.stdout)


def crafted_twin_copy(source: Path, target: Path, flips: dict[str, set[int]]) -> dict[str, dict]:
    """A copy of a results directory whose runs carry twin timelines (from their actions when they have none),
    with the truth flipped at the given action indices: sensed != truth exactly there."""
    shutil.copytree(source, target)
    out = {}
    for path in sorted((target / "runs").glob("*.json")):
        stored = json.loads(path.read_text())
        record = stored["record"]
        timeline = record.get("timeline") or [
            {**a, "index": i, "kind": a["component"].split("-")[0], "peak_force": 5.0 + i, "sim_time": 1.0 + i % 3,
             "true_moved": a["moved"]}
            for i, a in enumerate(record["actions"])
        ]  # fmt: skip
        for i in flips.get(stored["key"], set()):
            timeline[i]["true_moved"] = not timeline[i]["moved"]
        record["timeline"] = timeline
        record.setdefault("sim_time_s", sum(a["sim_time"] for a in timeline))
        record.setdefault("peak_true_wrist_force_n", max((a["peak_force"] for a in timeline), default=0.0))
        path.write_text(json.dumps(stored))
        out[stored["key"]] = record
    (target / "results.json").unlink()  # the records alone make a report too
    return out


def test_a_mark_appears_exactly_where_the_sensed_outcome_disagrees_with_the_truth(made, tmp_path):
    keys = sorted(records(made / "trial"))
    flips = {keys[0]: {0, 3}, keys[2]: {5}}
    runs = crafted_twin_copy(made / "trial", tmp_path / "crafted", flips)
    ok(script("report.py", tmp_path / "crafted"))
    parsed = check_page(tmp_path / "crafted" / "report.html")
    check_timelines(parsed, runs)
    marks = {t["key"]: {a["i"] for a in t["actions"] if a["mark"]} for t in parsed.timelines}
    assert marks == {keys[0]: {0, 3}, keys[1]: set(), keys[2]: {5}}
    widths = re.findall(r'data-i="(\d+)" data-outcome="[^"]*" style="width:([\d.]+)%', (tmp_path / "crafted" /
                        "report.html").read_text())  # fmt: skip
    first = [float(w) for i, w in widths[: runs[keys[0]]["num_actions"]]]
    times = [a["sim_time"] for a in runs[keys[0]]["timeline"]]
    assert all(abs(w / first[0] - t / times[0]) < 1e-2 for w, t in zip(first, times, strict=True)), "width ~ sim time"


def test_data_strings_are_escaped(made, tmp_path):
    shutil.copytree(made / "trial", tmp_path / "t")
    path = sorted((tmp_path / "t" / "runs").glob("*.json"))[0]
    stored = json.loads(path.read_text())
    stored["record"]["ended"] = '<script>alert("x")</script>'
    stored["record"]["actions"][0]["component"] = 'a"><b>'
    path.write_text(json.dumps(stored))
    ok(script("report.py", tmp_path / "t"))
    text = (tmp_path / "t" / "report.html").read_text()
    assert '<script>alert("x")' not in text and "&lt;script&gt;alert(&quot;x&quot;)" in text
    assert 'a"><b>' not in text
    check_page(tmp_path / "t" / "report.html")


def test_a_twin_trial_report_links_its_video_and_draws_its_timeline(tmp_path, tmp_path_factory):
    out = shared.private_copy(shared.video_trial(tmp_path_factory) / "video", tmp_path / "twin")  # paper-test-1
    assert (out / "rollout.mp4").is_file()
    ok(script("report.py", out))
    page = out / "report.html"
    parsed = check_page(page)
    runs = records(out)
    check_timelines(parsed, runs)
    videos = [link for tag, link in parsed.links if tag == "video"]
    assert videos == ["rollout.mp4"]
    # the page opens with the box's annotated top view: a PNG beside the run, linked before the summary
    text = page.read_text()
    assert [link for tag, link in parsed.links if tag == "img"] == ["gallery/paper-test-1/top-annotated.png"]
    assert text.index("<img") < text.index('id="summary"')
    top = iio.imread(out / "gallery/paper-test-1/top-annotated.png")
    assert top.shape[1] == 640 and top.shape[0] > 480  # the view, and the legend of lock rules below it
    stamp = (out / "gallery/paper-test-1/top-annotated.png").stat().st_mtime_ns
    ok(script("report.py", out, "--out", tmp_path / "again.html"))
    assert (out / "gallery/paper-test-1/top-annotated.png").stat().st_mtime_ns == stamp, "drawn once, then reused"
    assert page.stat().st_size < (out / "rollout.mp4").stat().st_size, "the video is linked, not inlined"
    text = page.read_text()
    assert "outcome agreement" in text and "Peak wrist force per action" in text
    record = next(iter(runs.values()))  # its placement and reality profile, and each block named by its part
    x, y, _ = record["box_pose"]
    assert f"x {x:.3f} y {y:.3f} m" in text and f"<td>{record['reality']}</td>" in text
    assert record["timeline"] and all(f'<span class="nm">{a["component"]}</span>' in text for a in record["timeline"])
    # the same run with its truth flipped on the second action: one mark there, none elsewhere
    key = next(iter(runs))
    crafted = crafted_twin_copy(out, tmp_path / "flipped", {key: {1}})
    ok(script("report.py", tmp_path / "flipped", "--out", tmp_path / "pages" / "flipped.html"))
    parsed = check_page(tmp_path / "pages" / "flipped.html")  # the video resolves from another directory too
    check_timelines(parsed, crafted)
    assert [a["mark"] for a in parsed.timelines[0]["actions"]] == [i == 1 for i in range(len(record["timeline"]))]
    assert [link for tag, link in parsed.links if tag == "video"] == ["../flipped/rollout.mp4"]


def test_the_force_plot_counts_actions_on_integer_ticks():
    from puzzlebox.lab.report_html import force_figure

    fig = force_figure([({"outcome": "moved", "moved": True, "true_moved": True}, 20.0 + i) for i in range(3)])
    ax = fig.axes[0]
    fig.canvas.draw()
    low, high = ax.get_xlim()
    ticks = [t for t in ax.get_xticks() if low <= t <= high]
    assert len(ticks) >= 2 and all(float(t).is_integer() for t in ticks), ticks


@pytest.mark.parametrize("what", ["missing", "file", "empty", "specs", "bad json", "no runs"])
def test_anything_but_a_trial_or_sweep_directory_is_refused_in_one_line(made, tmp_path, what):
    target = tmp_path / "x"
    if what == "file":
        target.write_text("{}")
    elif what == "empty":
        target.mkdir()
    elif what == "specs":
        target = made / "specs"
    elif what == "bad json":
        shutil.copytree(made / "trial", target)
        (target / "results.json").write_text("{not json")
        (target / "report.html").unlink(missing_ok=True)  # from an earlier test's report
    elif what == "no runs":
        target.mkdir()
        (target / "results.json").write_text("{}")
    result = script("report.py", target)
    assert result.returncode == 2
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1, result.stderr
    assert "Traceback" not in result.stderr
    assert not (target / "report.html").exists()


def test_help_describes_the_command():
    result = ok(script("report.py", "--help"))
    assert "self-contained HTML report" in result.stdout and "--out FILE.html" in result.stdout


@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium is not installed (apt-get install chromium)")
def test_the_sweep_page_loads_in_headless_chromium_and_shows_every_run(made, tmp_path):
    """A browser loads the page to its ``load`` event (its script stamps the load time on the page) and the DOM it
    builds holds the summary, the cells and every run's timeline with its blocks and marks; ``--measure-load`` reads
    that stamp back. How fast is not asserted here (speed is scripts/bench.py's)."""
    ok(script("report.py", made / "sweep", "--out", tmp_path / "sweep.html"))
    page = tmp_path / "sweep.html"
    command = ["chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--dump-dom", page.as_uri()]
    dom = subprocess.run(command, capture_output=True, text=True, timeout=120).stdout
    assert re.search(r'<html[^>]* data-load-ms="\d+"', dom), dom[:300]
    parsed = Page(dom)
    assert parsed.errors == [], parsed.errors[:5]
    assert {"summary", "cells"} <= set(parsed.tables)
    check_timelines(parsed, records(made / "sweep"))
    result = ok(script("report.py", made / "sweep", "--out", tmp_path / "again.html", "--measure-load"))
    assert re.search(r"; load \d+ ms in headless Chromium \([\d.]+ s with browser start\)$", result.stdout.strip())


def test_a_box_whose_spec_file_is_gone_gets_no_top_view_and_the_report_says_why(tmp_path):
    from types import SimpleNamespace

    from puzzlebox.lab.report_gallery import directory_specs

    gone = tmp_path / "gone.json"
    data = SimpleNamespace(config={"command": "trial", "sim": "twin", "specs": [str(gone)]}, runs=[])
    told: list[str] = []
    assert directory_specs(data, told.append) == []  # type: ignore[arg-type]
    assert len(told) == 1 and str(gone) in told[0]
