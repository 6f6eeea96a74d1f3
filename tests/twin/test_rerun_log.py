"""trial.py --record: a Rerun recording of a twin trial, read back with Rerun's own reader."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("rerun")

from puzzlebox.twin.rerun_log import RecordingError, TrialRecording, read_counts  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def trial(*args):
    return subprocess.run([sys.executable, str(ROOT / "scripts/trial.py"), *map(str, args)], capture_output=True,
                          text=True, timeout=600)  # fmt: skip


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    out = tmp_path_factory.mktemp("record")
    subprocess.run([sys.executable, str(ROOT / "scripts/generate.py"), "chain", "--kinds", "slide,door,lever",
                    "--seed", "2", "--out", str(out / "box.json")], check=True, capture_output=True)  # fmt: skip
    runs = {}
    for name, extra in (("recorded", ["--record", out / "trial.rrd"]), ("plain", [])):
        done = trial("--specs", out / "box.json", "--sim", "twin", "--agent", "dual", "--runs", "1", "--seed", "1",
                     "--max-actions", "10", "--out", out / name, "--workers", "1", *extra)  # fmt: skip
        assert done.returncode == 0, done.stderr[-2000:]
        runs[name] = json.loads((out / name / "results.json").read_text())["runs"][0]
    return out, runs


def test_the_recording_holds_cameras_poses_path_wrench_belief_and_decisions(recorded):
    out, runs = recorded
    counts = read_counts(out / "trial.rrd")
    run = runs["recorded"]
    actions = run["num_actions"]
    assert counts["/agent/decisions"] == 2 * actions  # each try: the decision, then its outcome
    assert counts["/agent/belief"] == actions and counts["/agent/w"] == actions
    for component in ("slide-0", "door-1", "lever-2"):
        assert counts[f"/world/components/{component}"] == counts["/world/tcp"]
    samples = counts["/world/tcp"]
    grid = run["sim_time_s"] / 0.1  # a sample every 0.1 s of simulated time, but within a long wait (a look)
    assert 0.9 * grid <= samples <= grid + 1
    assert counts["/world/arm/link7"] == samples and counts["/world/tcp_path"] == 1
    assert 0 < counts["/robot/force/norm"] <= samples
    assert counts["/cameras/overview"] >= 1 and counts["/cameras/xarm7_gripper_wrist_camera"] >= 1
    assert counts["/cameras/overview/markers"] == counts["/cameras/overview"]  # each look's detections


def test_recording_changes_nothing_the_pipeline_sensed_and_leaves_no_temporary(recorded):
    out, runs = recorded
    assert runs["recorded"]["sensed_sha256"] == runs["plain"]["sensed_sha256"]
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_record_mistakes_are_one_line(tmp_path):
    spec = tmp_path / "box.json"
    subprocess.run([sys.executable, str(ROOT / "scripts/generate.py"), "chain", "--kinds", "door,slide", "--seed",
                    "0", "--out", str(spec)], check=True, capture_output=True)  # fmt: skip
    common = ["--specs", spec, "--agent", "dual", "--runs", "1", "--seed", "0", "--max-actions", "5"]
    for extra, message in (
        (["--sim", "symbolic", "--record", tmp_path / "a.rrd"], "--record needs --sim twin"),
        (["--sim", "twin", "--record", tmp_path / "a.txt"], "ends in .rrd"),
        (["--sim", "twin", "--record", tmp_path / "missing" / "a.rrd"], "does not exist"),
    ):
        done = trial(*common, "--out", tmp_path / "out", *extra)
        assert done.returncode == 2 and message in done.stderr and done.stderr.count("\n") == 1, done.stderr


def test_an_aborted_recording_leaves_no_file_and_a_bad_directory_is_refused(tmp_path):
    recording = TrialRecording(tmp_path / "a.rrd", "test")
    recording.at(0.5)
    recording.decision("action 1: try x", 0.5)
    recording.abort()
    assert not list(tmp_path.iterdir())
    with pytest.raises(RecordingError, match="does not exist"):
        TrialRecording(tmp_path / "nope" / "b.rrd", "test")
