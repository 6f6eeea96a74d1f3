"""The multi-view rollout video: frames at a fixed simulated rate, captions where actions end, the box seen in
at least one view, drawn in a second process, and no frames at all without --video."""

import json
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]

from puzzlebox.lab import TrialConfig, run_trial  # noqa: E402
from puzzlebox.lab.rollout_observers import scene_cameras  # noqa: E402
from puzzlebox.models.generator import generate_chain, paper_family  # noqa: E402
from puzzlebox.twin.errors import VideoError  # noqa: E402
from puzzlebox.twin.rollout_video import (  # noqa: E402
    BackgroundRollout,
    Caption,
    FrameCollector,
    RolloutConfig,
    RolloutDrawer,
    RolloutFrame,
    frames_path,
)
from puzzlebox.twin.session import TwinSession  # noqa: E402


@pytest.fixture(scope="module")
def video_trial(tmp_path_factory):
    """One twin trial with --video and the same trial without (paper test box, oracle agent)."""
    out = tmp_path_factory.mktemp("rollout")
    spec_dir = out / "specs"
    subprocess.run([sys.executable, str(ROOT / "scripts/generate.py"), "paper", "--split", "test", "--out",
                    str(spec_dir)], check=True, capture_output=True)  # fmt: skip
    runs = {}
    for name, extra in (("video", ["--video"]), ("plain", [])):
        done = subprocess.run(
            [sys.executable, str(ROOT / "scripts/trial.py"), "--specs", str(spec_dir / "paper-test-1.json"), "--sim",
             "twin", "--agent", "oracle", "--runs", "1", "--seed", "3", "--max-actions", "8", "--out",
             str(out / name), "--workers", "1", *extra],
            capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr[-2000:]
        runs[name] = json.loads((out / name / "results.json").read_text())["runs"][0]
    return out, runs


def test_frames_come_at_the_fixed_simulated_rate_and_match_the_index(video_trial):
    out, runs = video_trial
    video = out / "video" / "rollout.mp4"
    frames = iio.imread(video)
    index = json.loads(frames_path(video).read_text())
    config = RolloutConfig()
    width, height = config.view_size
    assert frames.shape[1:] == (height + config.caption_height + config.plot_height, 3 * width, 3)
    assert len(frames) == len(index["frames"])
    times = np.array([f["time"] for f in index["frames"]])
    on_grid, last = times[:-1], times[-1]  # and one last frame when the trial ends, whatever the time
    grid = np.arange(len(on_grid)) * config.period  # frame k at k periods of simulated time
    np.testing.assert_allclose(on_grid, grid, atol=1e-9)
    assert on_grid[-1] <= last < on_grid[-1] + config.period
    assert len(frames) == pytest.approx(runs["video"]["sim_time_s"] / config.period, abs=3)


def test_captions_name_each_action_and_show_its_sensed_outcome_once_it_ends(video_trial):
    out, runs = video_trial
    index = json.loads(frames_path(out / "video" / "rollout.mp4").read_text())["frames"]
    frames = iio.imread(out / "video" / "rollout.mp4")
    timeline = runs["video"]["timeline"]
    height = RolloutConfig().view_size[1]
    for action, entry in enumerate(timeline, start=1):
        shown = [k for k, f in enumerate(index) if f["action"] == action]
        assert shown, f"no frame of action {action}"
        assert entry["component"] in index[shown[0]]["component"]
        # the frame after the try ends: the next action's first (its caption says how this one ended), or the last
        after = next((k for k, f in enumerate(index) if f["action"] == action + 1), len(index) - 1)
        truth = "moved" if entry["true_moved"] else "did not move"
        said = index[after]["previous"] or f"{index[after]['sensed']} (truth: {index[after]['truth']})"
        assert said.endswith(f"{entry['outcome']} (truth: {truth})"), said
        line = frames[after, height + 30 : height + 50]  # the caption's second line: values and outcome
        assert (line.max(axis=2) > 100).mean() > 0.01, "no caption text on the frame where the action ended"


def test_the_video_trial_is_the_same_trial_and_a_trial_without_video_writes_no_frames(video_trial):
    out, runs = video_trial
    assert runs["video"]["sensed_sha256"] == runs["plain"]["sensed_sha256"]  # the recorder reads no sensor
    assert runs["video"]["num_actions"] == runs["plain"]["num_actions"]
    assert not list((out / "plain").rglob("*.mp4")) and not list((out / "plain").rglob("*.frames.json"))
    assert not [p for p in (out / "video").iterdir() if p.name.startswith(".")]  # no temporary left


def test_every_sampled_frame_shows_the_box_unoccluded_in_at_least_one_view(monkeypatch):
    """The target: in every frame at least one view shows >= 90 % of the box's pixels it shows with the arm
    hidden (MuJoCo's segmentation rendering), on a five-kind box, every fourth frame."""
    from puzzlebox.lab import twin_trial as _twin_trial

    monkeypatch.setattr(_twin_trial, "BackgroundRollout", FrameCollector)
    spec = generate_chain(["lever", "slide", "door", "drawer", "wheel"], seed=0)
    entry = run_trial(spec, TrialConfig(agent="oracle", seed=1, max_actions=8), video=Path("unused.mp4")).to_dict()
    assert entry["solved"]
    kept = FrameCollector.last
    drawer = RolloutDrawer(kept.model, kept.cameras, kept.config)
    worst = [max(drawer.box_visibility(frame.qpos).values()) for frame in kept.frames[::4]]
    drawer.close()
    assert len(worst) >= 20 and min(worst) >= 0.9, sorted(worst)[:5]


def test_the_drawer_outlines_only_recent_detections_and_fills_the_caption():
    spec = paper_family("test")[0]
    with TwinSession(spec, seed=0) as session:
        drawer = RolloutDrawer(session.model, scene_cameras(session), RolloutConfig())
        corners = np.array([[100, 100], [200, 100], [200, 200], [100, 200]], dtype=float)
        caption = Caption(action=2, component="door-0 (door)", sensed="moved", truth="moved", weight_info=0.3,
                          q_info=0.12, q_exploit=0.8)  # fmt: skip
        fresh = RolloutFrame(10.0, session.data.qpos.copy(), caption, {"overview": (9.5, [(7, corners)])})
        stale = RolloutFrame(10.0, session.data.qpos.copy(), caption, {"overview": (5.0, [(7, corners)])})
        views = [drawer.draw(f)[:240, :320].astype(int) for f in (fresh, stale)]
        drawer.close()
    green = [int(((v[..., 1] > 150) & (v[..., 0] < 60) & (v[..., 2] < 60)).sum()) for v in views]
    assert green[0] > 50 and green[1] == 0, green  # the outline (drawn at half scale: 640 px captures, 320 px view)


def test_a_failed_drawing_is_a_video_error_and_an_abort_leaves_no_file(tmp_path):
    spec = paper_family("test")[0]
    with TwinSession(spec, seed=0) as session:
        cameras = scene_cameras(session)
        rollout = BackgroundRollout(tmp_path / "a.mp4", session.model, cameras)
        rollout.add(RolloutFrame(0.0, session.data.qpos.copy(), Caption()))
        rollout.abort()
        assert not list(tmp_path.iterdir())
        broken = BackgroundRollout(tmp_path / "b.mp4", session.model, cameras)
        broken.add(RolloutFrame(0.0, np.zeros(3), Caption()))  # the wrong number of joint positions
        with pytest.raises(VideoError, match="drawing the rollout video failed"):
            broken.close()
        assert not list(tmp_path.glob("*.mp4"))
    with pytest.raises(VideoError, match="does not exist"):
        BackgroundRollout(tmp_path / "missing" / "c.mp4", session.model, cameras)
