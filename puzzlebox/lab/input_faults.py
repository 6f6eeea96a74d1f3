"""The fault suite's second round (``experiment.py faults``; issue 37), each class in real processes:

- ``second writer``: two ``trial.py`` (and two ``sweep.py``) with different seeds started together into one
  ``--out``: no summary may be lost (both exiting 0, or a directory whose ``config.json`` describes one experiment
  and whose ``results.json`` holds the other's) and the second writer must be refused in one line (the directory's
  lock names the holder; one started after the first ended finds its results and is refused too);
- ``names``: specs and components named with spaces, unicode, HTML, ``/`` and ``..`` run end to end;
- ``malformed inputs``: sweep files of wrong types, JSON nested too deep, seeds and sizes out of range, an
  ``--out`` that is a file or read-only, checkpoint metadata out of range, calibrations not rigid or lacking a
  camera, a profile's ``cell_seed`` below 0: each one line and exit 2 before any work;
- ``crafted memory``: a memory carrying a trigger, a view or an extra table: refused in one line, the file
  unchanged;
- ``experiment stopped``: ``experiment.py`` sent SIGTERM (and SIGINT, inherited as ignored) after its first saved
  job: one line, exit 130, the job kept and reused by the same command.

:func:`writer_races` is also what a development race script measured with.
"""

from __future__ import annotations

import json
import shutil
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.lab.cli import scripts_folder

SCRIPTS = scripts_folder()
READ_ONLY = Path("/sys/puzzlebox-faults-out")
"""A place nobody may write, root included (sysfs refuses to make anything there)."""


def _python(*args: Any, timeout: float = 900, **kwargs: Any) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=timeout,
                          **kwargs)  # fmt: skip


def one_line_refusal(result: subprocess.CompletedProcess) -> bool:
    """Exit 2, one ``error:`` line on stderr, no traceback."""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    return result.returncode == 2 and len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in (
        result.stderr)  # fmt: skip


# -- two writers into one --out ----------------------------------------------------------------------------------


def _whole(out: Path, starts: tuple[int, ...]) -> bool:
    """``config.json`` and ``results.json`` describe one experiment (one of ``starts``' seeds), finished."""
    try:
        config = json.loads((out / "config.json").read_text())
        results = json.loads((out / "results.json").read_text())
    except (OSError, ValueError):
        return False
    start = config["seed"] if "seed" in config else config["sweep"]["seeds"]["start"]
    seeds = {r["seed"] for r in results.get("runs", [])}
    return (start in starts and results.get("runs_done") == results.get("runs_planned") and bool(seeds)
            and min(seeds) == start)  # fmt: skip


def writer_races(out: Path, kind: str, races: int, spec: Path) -> dict[str, Any]:
    """``races`` races of two ``kind`` (``trial`` or ``sweep``) commands into one ``--out`` each, started together:
    summaries lost, second writers refused (by the lock, or finding the first one's results), tracebacks."""
    starts = (100, 200)
    rows = []
    for k in range(races):
        target = out / f"{kind}-{k}"
        commands = []
        for w, start in enumerate(starts):
            if kind == "trial":
                commands.append([SCRIPTS / "trial.py", "--specs", spec, "--sim", "symbolic", "--agent", "dual",
                                 "--runs", 20, "--seed", start, "--max-actions", 30, "--out", target])  # fmt: skip
            else:
                grid = out / f"{kind}-{k}-{w}.json"
                sweep = {"sim": "symbolic", "specs": [str(spec.resolve())], "max_actions": 30,
                         "agents": ["dual", "oracle"], "seeds": {"start": start, "count": 10}}  # fmt: skip
                grid.write_text(json.dumps(sweep))
                commands.append([SCRIPTS / "sweep.py", grid, "--out", target, "--workers", 1])
        procs = [subprocess.Popen([sys.executable, *map(str, c)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                  text=True) for c in commands]  # fmt: skip
        outputs = [p.communicate(timeout=900) for p in procs]
        done = [(p.returncode, stdout, stderr) for p, (stdout, stderr) in zip(procs, outputs, strict=True)]
        codes = [code for code, _, _ in done]
        refused = [err for code, _, err in done if code == 2]
        one_line = len(refused) == 1 and codes.count(0) == 1 and all(
            len(e.strip().splitlines()) == 1 and "Traceback" not in e for e in refused)  # fmt: skip
        rows.append({
            "codes": codes, "whole": _whole(target, starts), "refused_in_one_line": one_line,
            "by_lock": sum("in use by another process" in e for e in refused),
            "holding_results": sum("already holds results" in e for e in refused),
            "tracebacks": sum("Traceback" in err for _, _, err in done),
            "said": [err.strip().splitlines()[-1] if err.strip() else "" for _, _, err in done],
        })  # fmt: skip
    return {
        "races": races,
        "summaries_lost": sum(r["codes"].count(0) > 1 or not r["whole"] for r in rows),
        "second_refused": sum(r["refused_in_one_line"] for r in rows),
        "refused_by_lock": sum(r["by_lock"] for r in rows),
        "refused_holding_results": sum(r["holding_results"] for r in rows),
        "tracebacks": sum(r["tracebacks"] for r in rows),
        "rows": rows,
    }


# -- names, malformed inputs, crafted memories ----------------------------------------------------------------

NAMES = ("a box with spaces", "ünïcödé ✓ 箱", "dir/sub/name", "../../escape", "<b>bold</b> & 'quoted'")


def renamed(spec: dict[str, Any], name: str) -> dict[str, Any]:
    """``spec`` (a spec's JSON) named ``name``, each component ``name`` plus its own name."""
    new = {c["name"]: f"{name} {c['name']}" for c in spec["components"]}
    return {**spec, "name": name, "components": [dict(c, name=new[c["name"]]) for c in spec["components"]],
            "locks": [dict(r, locker=new[r["locker"]], locked=new[r["locked"]]) for r in spec["locks"]],
            "goal": dict(spec["goal"], component=new[spec["goal"]["component"]])}  # fmt: skip


def names_run(out: Path, spec: Path) -> tuple[int, int, bool]:
    """Every name of :data:`NAMES` run by ``trial.py`` (two runs each): (runs planned, runs done, no traceback)."""
    data = json.loads(spec.read_text())
    files = []
    for k, name in enumerate(NAMES):
        files.append(out / "names" / f"s{k}.json")
        files[-1].parent.mkdir(parents=True, exist_ok=True)
        files[-1].write_text(json.dumps(renamed(data, name), ensure_ascii=False), encoding="utf-8")
    result = _python(SCRIPTS / "trial.py", "--specs", *files, "--sim", "symbolic", "--agent", "dual", "--runs", 2,
                     "--seed", 0, "--max-actions", 30, "--out", out / "names" / "trial", "--force")  # fmt: skip
    path = out / "names" / "trial" / "results.json"
    done = json.loads(path.read_text())["runs_done"] if path.exists() else 0
    return 2 * len(NAMES), done, result.returncode == 0 and "Traceback" not in result.stderr


def ideal_cell_calibration(spec: Path) -> dict[str, Any]:
    """A calibration file's contents for ``spec``'s box in the ideal twin cell: the nominal pinhole on every camera,
    the poses the identity (only its form matters: the fault cases edit it and it is refused before use)."""
    from puzzlebox.lab.cells import TWIN_CAMERAS
    from puzzlebox.models.calibration import CameraCalibration, CellCalibration

    K = np.array([[600.0, 0, 319.5], [0, 600.0, 239.5], [0, 0, 1]])
    cameras = {name: CameraCalibration(K, np.zeros(5), (640, 480), T_base_camera=None if on_arm else np.eye(4),
                                       T_tcp_camera=np.eye(4) if on_arm else None)
               for name, on_arm in TWIN_CAMERAS.items()}  # fmt: skip
    height = json.loads(spec.read_text())["box"]["size"][2]
    return CellCalibration(cameras, cell={"profile": "ideal", "cell_seed": 0, "box_height": height}).to_dict()


QUICK_MALFORMED = (
    "sweep: 'specs': 5", "sweep nested 70000 deep", "calibration: rotation x 1.5", "profile cell_seed -1",
    "train --seed 2**70", "generate chain --seed -1", "trial --runs 1e9", "render --out read-only",
    "experiment --out a file", "bench --out a directory",
)  # fmt: skip
"""The quick suite's malformed inputs: one of each command and loader (tests/scripts/test_input_checks.py checks
every case in process)."""


def malformed_inputs(out: Path, spec: Path, only: tuple[str, ...] | None = None) -> dict[str, bool]:
    """Each malformed input of issue 37 (``only``: these), run in its own process: was it one line and exit 2?"""
    where = out / "inputs"
    where.mkdir(parents=True, exist_ok=True)
    a_file = where / "a-file"
    a_file.write_text("x")
    deep = where / "deep.json"
    deep.write_text("[" * 70_000 + "]" * 70_000)
    good = {"sim": "symbolic", "generate": {"generator": "random", "components": 4, "count": 1}, "max_actions": 20,
            "agents": ["oracle"]}  # fmt: skip
    globbed = {k: v for k, v in good.items() if k != "generate"}
    sweeps = {
        "sweep: 'specs': 5": globbed | {"specs": 5},
        "sweep: 'specs' a glob string": globbed | {"specs": "dir/*.json"},
        "sweep: seeds 'a'": good | {"seeds": "a"},
        "sweep: agents [5]": good | {"agents": [5]},
        "sweep: agents []": good | {"agents": []},
        "sweep: profiles []": good | {"sim": "twin", "profiles": []},
        "sweep: 1e9 seeds": good | {"seeds": {"start": 0, "count": 10**9}},
    }
    calibrations = {
        "calibration: camera null": lambda d: d["cameras"].update(overview=None),
        "calibration: rotation x 1.5": lambda d: d["cameras"]["overview"].update(
            T_base_camera=(np.eye(4) * [1.5, 1.5, 1.5, 1]).tolist()),
        "calibration: a camera missing": lambda d: d["cameras"].pop("overview"),
        "calibration: cell_seed -1": lambda d: d["cell"].update(cell_seed=-1),
    }  # fmt: skip
    trial = [SCRIPTS / "trial.py", "--specs", spec, "--sim", "symbolic", "--agent", "dual", "--runs", 1, "--seed", 0,
             "--max-actions", 5]  # fmt: skip
    twin = [SCRIPTS / "trial.py", "--specs", spec, "--sim", "twin", "--agent", "oracle", "--runs", 1, "--seed", 0,
            "--max-actions", 5]  # fmt: skip
    cases: dict[str, list[Any]] = {}
    for name, content in sweeps.items():
        path = where / f"sweep-{len(cases)}.json"
        path.write_text(json.dumps(content))
        cases[name] = [SCRIPTS / "sweep.py", path, "--out", where / "o-sweep"]
    for name, edit in calibrations.items():
        data = ideal_cell_calibration(spec)
        edit(data)
        path = where / f"calibration-{len(cases)}.json"
        path.write_text(json.dumps(data))
        cases[name] = [*twin, "--calibration", path, "--out", where / "o-cal"]
    profile = where / "profile.json"
    profile.write_text(json.dumps({"name": "mine", "cell_seed": -1}))
    cases |= {
        "spec nested 70000 deep": [*trial[:2], deep, *trial[3:], "--out", where / "o1"],
        "sweep nested 70000 deep": [SCRIPTS / "sweep.py", deep, "--out", where / "o2"],
        "reality profile nested 70000 deep": [*twin, "--reality", deep, "--out", where / "o3"],
        "calibration nested 70000 deep": [*twin, "--calibration", deep, "--out", where / "o4"],
        "profile cell_seed -1": [*twin, "--reality", profile, "--out", where / "o5"],
        "train --seed 2**70": [SCRIPTS / "train.py", "--specs", spec, "--episodes", 1, "--memory", where / "m.sqlite",
                               "--seed", 2**70],
        "generate chain --seed -1": [SCRIPTS / "generate.py", "chain", "--kinds", "door,slide", "--seed", -1, "--out",
                                     where / "c.json"],
        "calibrate --seed -1": [SCRIPTS / "calibrate.py", "--seed", -1, "--out", where / "cal.json"],
        "trial --runs 1e9": [*trial[:8], 10**9, *trial[9:], "--out", where / "o6"],
        "train --episodes 1e9": [SCRIPTS / "train.py", "--specs", spec, "--episodes", 10**9, "--memory",
                                 where / "m.sqlite"],
        "render 100000 x 100000": [SCRIPTS / "render.py", spec, "--out", where / "o7", "--width", 100_000, "--height",
                                   100_000],
        "render --out read-only": [SCRIPTS / "render.py", spec, "--out", READ_ONLY],
        "experiment --out a file": [SCRIPTS / "experiment.py", "variants", "--agents", "dual", "--quick", "--out",
                                    a_file],
        "calibrate --out read-only": [SCRIPTS / "calibrate.py", "--out", READ_ONLY / "c.json"],
        "bench --out a directory": [SCRIPTS / "bench.py", "--quick", "--out", where],
    }  # fmt: skip
    unknown = set(only or ()) - set(cases)
    if unknown:
        raise ValueError(f"unknown malformed inputs {sorted(unknown)}; the cases: {list(cases)}")
    return {name: one_line_refusal(_python(*args)) for name, args in cases.items() if only is None or name in only}


CRAFTED = {
    "a trigger": "CREATE TRIGGER wipe AFTER INSERT ON episodes BEGIN DELETE FROM pair_entries; END",
    "a view": "CREATE VIEW everything AS SELECT * FROM pair_entries",
    "an extra table": "CREATE TABLE notes (text TEXT)",
}


def crafted_memories(out: Path, spec: Path) -> dict[str, bool]:
    """A trained memory given a trigger, a view, an extra table, then trained on: refused in one line, the file
    byte for byte as it was (nothing ran on it)?"""
    base = out / "crafted" / "memory.sqlite"
    base.parent.mkdir(parents=True, exist_ok=True)
    base.unlink(missing_ok=True)
    _python(SCRIPTS / "train.py", "--specs", spec, "--episodes", 2, "--memory", base).check_returncode()
    verdicts = {}
    for k, (name, statement) in enumerate(CRAFTED.items()):
        path = base.with_name(f"crafted-{k}.sqlite")
        shutil.copy(base, path)
        conn = sqlite3.connect(path)
        with conn:
            conn.execute(statement)
        conn.close()
        before = path.read_bytes()
        result = _python(SCRIPTS / "train.py", "--specs", spec, "--episodes", 2, "--memory", path)
        verdicts[name] = one_line_refusal(result) and path.read_bytes() == before
    return verdicts


# -- experiment.py stopped --------------------------------------------------------------------------------------


def experiment_stopped(out: Path) -> dict[str, Any]:
    """``experiment.py variants --agents dqn --quick --seeds 2`` stopped by SIGTERM, then by a SIGINT it inherited
    as ignored, each after its first saved job; then run again to the end."""
    target = out / "experiment"
    shutil.rmtree(target, ignore_errors=True)
    command = [sys.executable, str(SCRIPTS / "experiment.py"), "variants", "--agents", "dqn", "--quick", "--workers",
               "1", "--seeds", "2", "--out", str(target)]  # fmt: skip

    def saved() -> int:  # jobs whose records are saved (KEY.json; KEY.pt and KEY.pt.json are their checkpoints)
        return sum(not p.name.endswith(".pt.json") for p in (target / "jobs").glob("*.json"))

    stops = {}
    for sig in (signal.SIGTERM, signal.SIGINT):
        jobs = saved()
        proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))  # fmt: skip
        deadline = time.monotonic() + 900
        while time.monotonic() < deadline and proc.poll() is None and saved() <= jobs:
            time.sleep(0.2)
        proc.send_signal(sig)
        _, stderr = proc.communicate(timeout=300)
        kept = saved()
        clean = "Traceback" not in stderr and "stopped" in stderr
        stops[sig.name] = {"exit": proc.returncode, "said": stderr.strip().splitlines()[-1:], "one_line": clean,
                           "jobs_kept": kept}  # fmt: skip
    final = subprocess.run(command, capture_output=True, text=True, timeout=1800)
    reused = [line for line in final.stdout.splitlines() if "reused" in line]
    return {"stops": stops, "final_exit": final.returncode, "reused": reused}
