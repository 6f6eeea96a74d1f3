"""Faults run on purpose, in real processes: the fault suite itself, and the faults not tested elsewhere.

Where each fault class of issue 11 is tested:
- a trial SIGKILLed / SIGTERMed and resumed; an output of another configuration; CLI mistakes:
  ``tests/scripts/test_trial_cli.py``, ``tests/scripts/test_generate_cli.py``;
- concurrent trainers on one memory, a memory truncated or read-only: ``tests/learning/test_memory_log.py``;
- a task that raises, a pool worker that dies: ``tests/lab/test_runner.py`` and here (a real worker of a
  real ``trial.py``);
- physics that diverges, a video killed in mid-write: here;
- the twin's faults (frames dropped, F/T noise, jams, slips): ``tests/skills/test_robustness.py`` and the suite.

And those of issue 56 (`puzzlebox/lab/third_round_faults.py`, in the suite): each also has its own test in
`tests/scripts/test_input_checks.py`, `tests/learning/test_try_outcomes.py`, `tests/learning/test_memory.py`.

And those of issue 37: two writers into one ``--out``: ``tests/lab/test_out_lock.py`` and the suite; names of every
kind: ``tests/scripts/test_spec_names.py``; malformed inputs and a full disk: ``tests/scripts/test_input_checks.py``;
crafted memories: ``tests/learning/test_memory_schema.py``; ``experiment.py`` stopped by a signal:
``tests/scripts/test_experiment_signals.py``.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def python(*args, timeout=900):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=timeout)


@pytest.fixture(scope="module")
def specs(tmp_path_factory):
    out = tmp_path_factory.mktemp("specs")
    assert python(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", out).returncode == 0
    return out


def test_the_quick_fault_suite_detects_survives_and_keeps_every_case(tmp_path):
    """Every class at full marks, in one table (symbolic kills, the quick twin faults)."""
    out = tmp_path / "faults"
    result = python(ROOT / "scripts/experiment.py", "faults", "--out", out, "--quick")
    assert result.returncode == 0, result.stderr
    rows = {r["fault"]: r for r in json.loads((out / "faults.json").read_text())["rows"]}
    # 7 classes of the tools + the quick suite's 2 twin faults + issue 37's 5 (quick) + issue 56's 7
    assert len(rows) == 21
    for row in rows.values():
        for figure in (row["detected"], row["survived"], row["data_kept"]):
            for done, of in re.findall(r"(\d+)/(\d+)", figure):
                assert done == of, row
    assert "0 runs lost, 0 duplicated" in rows["trial.py killed (SIGKILL) and resumed"]["data_kept"]
    assert "0 runs lost, 0 duplicated" in rows["a trial.py pool worker killed (SIGKILL)"]["data_kept"]
    assert (out / "faults.md").read_text().count("\n| ") == 22  # header + 21 rows
    for kind in ("trial", "sweep"):
        race = rows[f"two {kind}.py into one --out, started together"]
        assert race["data_kept"] == "0 summaries lost" and race["detected"].startswith("2/2 second writers refused")
    assert rows["memory with a trigger, a view, an extra table"]["detected"] == "3/3 refused in one line (exit 2)"
    assert rows["malformed inputs"]["detected"] == "10/10 one line, exit 2"  # one of each command and loader
    third = (
        "an agent that misbehaves",
        "inputs that are not regular files",
        "a reader that closes stdout early",
        "the environment and odd paths",
        "a memory whose contents are bad",
        "boxes given twice",
        "absurd values",
    )
    assert all(rows[f]["detected"].split(" ")[0] in ("1/1", "2/2", "3/3") for f in third)  # each case said so
    blank = rows["twin: camera: every frame dropped"]
    assert blank["detected"].startswith("ended: MarkersNotFound") and blank["data_kept"] == "1/1 run recorded"
    bad = python(ROOT / "scripts/experiment.py", "faults", "--out", out, "--runs", "1")
    assert bad.returncode == 2 and "--runs must be >= 2" in bad.stderr


def test_a_killed_pool_worker_is_replaced_and_no_run_is_lost(specs, tmp_path):
    from puzzlebox.lab.faults import pool_workers

    def trial(out, *flags):
        return [sys.executable, ROOT / "scripts/trial.py", "--specs", *sorted(specs.glob("*.json")), "--sim",
                "symbolic", "--agent", "dual", "--runs", 120, "--seed", 4, "--max-actions", 30, "--out", out,
                *flags]  # fmt: skip

    assert subprocess.run(list(map(str, trial(tmp_path / "whole", "--workers", 1)))).returncode == 0
    proc = subprocess.Popen(
        list(map(str, trial(tmp_path / "killed", "--workers", 2))), stderr=subprocess.PIPE, text=True
    )
    workers: list[int] = []
    while proc.poll() is None and not workers:
        workers = pool_workers(proc.pid)
        time.sleep(0.01)
    time.sleep(0.5)  # let it record a few runs
    assert proc.poll() is None, "the trial ended before a worker could be killed"
    os.kill(workers[0], signal.SIGKILL)
    _, stderr = proc.communicate(timeout=600)
    assert proc.returncode == 0 and "a worker died" in stderr and "Traceback" not in stderr
    got, want = (json.loads((tmp_path / d / "results.json").read_text()) for d in ("killed", "whole"))
    assert got["runs_done"] == got["runs_planned"] == 360
    assert [r["seed"] for r in got["runs"]] == [r["seed"] for r in want["runs"]]
    assert [r["actions"] for r in got["runs"]] == [r["actions"] for r in want["runs"]]


def test_physics_that_diverges_ends_the_run_with_its_name_and_keeps_the_record(specs, tmp_path, monkeypatch):
    """Velocities made infinite mid-survey: MuJoCo flags it at the next step, the session raises
    SimulationDiverged, and the trial records the run as ended for that reason (no traceback)."""
    monkeypatch.chdir(tmp_path)  # MuJoCo logs each warning to MUJOCO_LOG.TXT in the working directory
    from puzzlebox.lab import TrialConfig, run_trial
    from puzzlebox.models import load_spec
    from puzzlebox.twin.errors import SimulationDiverged
    from puzzlebox.twin.session import TwinSession

    spec = load_spec(specs / "paper-test-0.json")
    with TwinSession(spec, seed=0) as session:
        session.advance(0.1)
        session.data.qvel[:] = np.inf
        with pytest.raises(SimulationDiverged, match="BADQVEL"):
            session.advance(0.01)

    after_steps = TwinSession._after_steps

    def diverging(self):
        if self.data.time > 2.0 and not getattr(self, "_diverged", False):
            self._diverged = True
            self.data.qvel[:] = np.inf
        after_steps(self)

    TwinSession._after_steps = diverging
    try:
        record = run_trial(spec, TrialConfig(agent="oracle", seed=0, max_actions=6)).to_dict()
    finally:
        TwinSession._after_steps = after_steps
    assert record["ended"].startswith("SimulationDiverged: MuJoCo warning") and not record["solved"]
    assert record["sim_time_s"] < 2.1 and json.dumps(record), "the record is whole and JSON"


def test_a_video_killed_in_mid_write_never_appears_under_its_final_name(specs, tmp_path):
    """SIGKILL while the rollout is being drawn and encoded (in its second process): no video under the final name,
    the orphaned drawing process discards its partial file and exits, and the resume publishes a whole video."""
    import imageio_ffmpeg

    from puzzlebox.twin.rollout_video import RolloutConfig

    out = tmp_path / "out"
    command = [sys.executable, ROOT / "scripts/trial.py", "--specs", specs / "paper-test-0.json", "--sim", "twin",
               "--agent", "oracle", "--runs", 1, "--seed", 0, "--max-actions", 1, "--video", "--out", out]  # fmt: skip
    proc = subprocess.Popen(list(map(str, command)), stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while time.monotonic() < deadline and proc.poll() is None and not list(out.glob(".rollout.*.mp4")):
        time.sleep(0.05)
    time.sleep(1.0)  # frames are being written
    assert proc.poll() is None, "the trial ended before the kill"
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert not (out / "rollout.mp4").exists(), "a killed trial's video never appears under its final name"
    deadline = time.monotonic() + 30  # the drawing process sees its queue close, discards its file and exits
    while time.monotonic() < deadline and list(out.glob(".rollout*")):
        time.sleep(0.1)
    assert not list(out.glob(".rollout*")), "the orphaned drawing process left its partial files"
    resumed = python(*command[1:], "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert not list(out.glob(".rollout*"))
    reader = imageio_ffmpeg.read_frames(str(out / "rollout.mp4"))
    meta = next(reader)
    assert meta["size"] == RolloutConfig().frame_size
    assert sum(1 for _ in reader) > 50, "a whole video: every frame decodes"


def test_ctrl_c_to_a_pool_trial_stops_after_the_runs_in_flight_and_keeps_them(specs, tmp_path):
    """Ctrl-C at a terminal signals the whole process group: the workers leave it to the driver, which stops
    handing out runs, keeps the ones in flight and says how to resume."""
    out = tmp_path / "out"
    command = [sys.executable, ROOT / "scripts/trial.py", "--specs", *sorted(specs.glob("*.json")), "--sim",
               "symbolic", "--agent", "dual", "--runs", 60, "--seed", 0, "--max-actions", 30, "--out", out,
               "--workers", 2]  # fmt: skip
    proc = subprocess.Popen(list(map(str, command)), stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list(out.glob("runs/*.json"))) < 5:
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGINT)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 130 and "--resume" in stderr and "Traceback" not in stderr, stderr
    results = json.loads((out / "results.json").read_text())
    assert 5 <= results["runs_done"] == len(list(out.glob("runs/*.json"))) < results["runs_planned"] == 180
    resumed = python(*command[1:], "--resume")
    assert resumed.returncode == 0 and json.loads((out / "results.json").read_text())["runs_done"] == 180
