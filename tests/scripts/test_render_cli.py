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
