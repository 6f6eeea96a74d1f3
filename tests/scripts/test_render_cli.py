"""render.py writes the camera image and the scripted sweep video."""

import json
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio

ROOT = Path(__file__).resolve().parents[2]


def run(*args):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=600)


def test_render_writes_png_and_a_sweep_video_that_opens_the_chain(tmp_path):
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", tmp_path).returncode == 0
    result = run(ROOT / "scripts/render.py", tmp_path / "paper-test-1.json", "--out", tmp_path / "r", "--video")
    assert result.returncode == 0, result.stderr
    image = iio.imread(tmp_path / "r" / "overview.png")
    assert image.shape == (480, 640, 3) and image.std() > 10
    frames = iio.imread(tmp_path / "r" / "sweep.mp4")
    assert frames.shape[0] > 20 and frames.shape[1:] == (480, 640, 3)
    steps = json.loads((tmp_path / "r" / "sweep.json").read_text())
    assert [s["component"] for s in steps if s["opened"]][-1] == "slide-4"  # the goal, opened last


def test_render_refuses_an_unknown_camera(tmp_path):
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", tmp_path)
    result = run(ROOT / "scripts/render.py", tmp_path / "paper-test-0.json", "--out", tmp_path / "r", "--camera", "top")
    assert result.returncode == 2 and "overview" in result.stderr and "Traceback" not in result.stderr


def test_render_writes_the_views_and_the_turntable_of_a_box(tmp_path):
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", tmp_path).returncode == 0
    out = tmp_path / "g"
    result = run(
        ROOT / "scripts/render.py", tmp_path / "paper-test-1.json", "--out", out, "--views", "--turntable",
        "--frames", "12", "--width", "320", "--height", "240",
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    components = [c["name"] for c in json.loads((tmp_path / "paper-test-1.json").read_text())["components"]]
    for name in ["top", "three-quarter", *(f"component-{c}" for c in components)]:
        image = iio.imread(out / f"{name}.png")
        assert image.shape == (240, 320, 3) and image.std() > 10, name
    for name in ("top-annotated", "three-quarter-annotated"):  # labels on the view, the lock rules' legend below it
        image = iio.imread(out / f"{name}.png")
        assert image.shape[1] == 320 and image.shape[0] > 240 + 14 * 9, name  # paper-test-1: 8 rules and the goal
    assert iio.imread(out / "turntable.mp4").shape == (12, 240, 320, 3)
    config = json.loads((out / "render.config.json").read_text())
    assert config["views"] and config["turntable"] and config["frames"] == 12
    assert not (out / "overview.png").exists()  # the gallery draws the box alone, not the twin's cameras


def test_render_refuses_command_line_mistakes_on_one_line(tmp_path):
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", tmp_path)
    (tmp_path / "broken.json").write_text("{not json")
    scene = {
        "format": "puzzlebox-spec/1", "name": "one-screw",
        "components": [{"name": "s1", "kind": "screw", "pose": [0.0, 0.0, 0.0, 0, 0, 0]}],
        "locks": [], "goal": {"component": "s1", "state": 1},
    }  # fmt: skip
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    box = tmp_path / "paper-test-0.json"
    cases = [
        ([tmp_path / "missing.json", "--views"], "missing.json"),
        ([tmp_path / "broken.json", "--turntable"], "JSON"),
        ([tmp_path / "scene.json", "--views"], "no box"),
        ([box, "--views", "--video"], "--video"),
        ([box, "--turntable", "--width", "321"], "even"),
    ]
    for args, expected in cases:
        result = run(ROOT / "scripts/render.py", *args, "--out", tmp_path / "r")
        assert result.returncode == 2, (args, result.stderr)
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error:") and expected in lines[0], (args, result.stderr)


def test_replay_draws_a_logged_trial_s_rollout_without_its_physics_and_refuses_what_is_not_a_log(tmp_path):
    from puzzlebox.lab import TrialConfig, run_trial
    from puzzlebox.models.generator import generate_chain

    log = tmp_path / "states" / "trial.npz"
    record = run_trial(generate_chain(["slide", "wheel"], seed=1), TrialConfig(agent="oracle", seed=5, max_actions=1),
                       state_log=log)  # fmt: skip
    out = tmp_path / "replay.mp4"
    result = run(ROOT / "scripts/render.py", "replay", log, "--out", out, "--period", "1.0", "--fps", "10")
    assert result.returncode == 0, result.stderr
    frames = int(result.stdout.split()[0])
    assert frames == int(record.sim_time_s) + 2  # one a simulated second from 0, and the last
    assert iio.imread(out).shape[0] == frames
    not_a_log = tmp_path / "x.npz"
    not_a_log.write_bytes(b"not an npz")
    for bad, said in ((not_a_log, "x.npz"), (tmp_path / "missing.npz", "no such state log")):
        refused = run(ROOT / "scripts/render.py", "replay", bad, "--out", tmp_path / "r.mp4")
        assert refused.returncode == 2 and "Traceback" not in refused.stderr and said in refused.stderr
        assert not (tmp_path / "r.mp4").exists()
    wrong = run(ROOT / "scripts/render.py", "replay", log, "--out", tmp_path / "r.gif")
    assert wrong.returncode == 2 and ".mp4" in wrong.stderr
