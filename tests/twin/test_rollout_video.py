"""The multi-view rollout video: HD frames at ten per simulated second, captions where actions end, each look's
outlines on its own frame only, the box framed wherever it stands and seen in at least one view, the lid neither
washed out nor dark, drawn in a second process, and no frames at all without --video."""

import json
import math
from pathlib import Path

import _shared as shared
import imageio.v3 as iio
import numpy as np
import pytest

from puzzlebox.lab import TrialConfig, run_trial
from puzzlebox.lab.rollout_observers import scene_cameras
from puzzlebox.models.generator import generate_chain, paper_family
from puzzlebox.models.placement import placed
from puzzlebox.models.scene import SceneConfig, unreachable_handles
from puzzlebox.twin.errors import VideoError
from puzzlebox.twin.rollout_video import (
    BackgroundRollout,
    Caption,
    FrameCollector,
    Look,
    RolloutConfig,
    RolloutDrawer,
    RolloutFrame,
    frames_path,
)
from puzzlebox.twin.session import TwinSession


@pytest.fixture(scope="module")
def video_trial(tmp_path_factory):
    """One twin trial with --video and the same trial without (paper test box, oracle agent), shared with the
    report's tests."""
    out = shared.video_trial(tmp_path_factory)
    runs = {name: json.loads((out / name / "results.json").read_text())["runs"][0] for name in ("video", "plain")}
    return out, runs


def test_frames_are_hd_at_ten_per_simulated_second_and_match_the_index(video_trial):
    out, runs = video_trial
    video = out / "video" / "rollout.mp4"
    frames = iio.imread(video)
    index = json.loads(frames_path(video).read_text())
    config = RolloutConfig()
    width, height = config.frame_size
    assert width >= 1280 and config.period <= 0.1
    assert frames.shape[1:] == (height, width, 3)
    assert len(frames) == len(index["frames"])
    assert iio.immeta(video)["fps"] == pytest.approx(config.fps)
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
    height = RolloutConfig().views_height
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
    hidden (MuJoCo's segmentation rendering), on a five-kind box, every 20th frame (every 2 simulated seconds)."""
    from puzzlebox.lab import twin_trial as _twin_trial

    monkeypatch.setattr(_twin_trial, "BackgroundRollout", FrameCollector)
    spec = generate_chain(["lever", "slide", "door", "drawer", "wheel"], seed=0)
    entry = run_trial(spec, TrialConfig(agent="oracle", seed=1, max_actions=8), video=Path("unused.mp4")).to_dict()
    assert entry["solved"]
    kept = FrameCollector.last
    drawer = RolloutDrawer(kept.model, kept.cameras, kept.config)
    worst = [max(drawer.box_visibility(frame.qpos).values()) for frame in kept.frames[::20]]
    drawer.close()
    assert len(worst) >= 20 and min(worst) >= 0.9, sorted(worst)[:5]


def test_each_look_is_on_the_first_frame_after_its_capture_and_on_no_other(video_trial):
    out, _ = video_trial
    index = json.loads(frames_path(out / "video" / "rollout.mp4").read_text())["frames"]
    looks = [(k, view, t) for k, f in enumerate(index) for view, t in f["looks"].items()]
    assert {view for _, view, _ in looks} == {"overview", "wrist"}, "the survey looks through both cameras"
    for k, view, t in looks:
        assert (k == 0 or index[k - 1]["time"] <= t) and t <= index[k]["time"], (k, view, t)
    assert len({(view, t) for _, view, t in looks}) == len(looks), "a look drawn on two frames"


def _green(image: np.ndarray) -> int:
    image = image.astype(int)
    return int(((image[..., 1] > 180) & (image[..., 0] < 80) & (image[..., 2] < 80)).sum())


def test_a_detection_overlay_appears_only_on_the_frame_that_produced_it_and_the_caption_is_filled():
    spec = paper_family("test")[0]
    with TwinSession(spec, seed=0) as session:
        config = RolloutConfig()
        drawer = RolloutDrawer(session.model, scene_cameras(session), config)
        corners = np.array([[300, 200], [360, 200], [360, 260], [300, 260]], dtype=float)
        caption = Caption(action=2, component="door-0 (door)", sensed="moved", truth="moved", weight_info=0.3,
                          q_info=0.12, q_exploit=0.8)  # fmt: skip
        qpos = session.data.qpos.copy()
        look = Look(9.95, [(7, corners)], qpos)
        frames = [
            drawer.draw(RolloutFrame(10.0, qpos, caption, {session.scene.names.overview_camera: look})),
            drawer.draw(RolloutFrame(10.1, qpos, caption)),  # the same state: its views reused, not its outlines
            drawer.draw(RolloutFrame(10.2, qpos, caption, {session.scene.names.overview_camera: look})),
        ]
        drawer.close()
    x, y, w, h = config.layout()["overview"]
    green = [_green(f[y : y + h, x : x + w]) for f in frames]
    assert green[0] > 100 and green[1] == 0 and green[2] == green[0], green
    assert all(_green(f[: config.views_height]) == g for f, g in zip(frames, green, strict=True))  # nowhere else
    strip = frames[1][config.views_height : config.views_height + config.caption_height]
    assert (strip.max(axis=2) > 100).mean() > 0.01, "no caption text"


def test_the_part_tried_is_tinted_and_named_in_the_three_quarter_view():
    spec = paper_family("test")[0]
    with TwinSession(spec, seed=0) as session:
        config = RolloutConfig()
        drawer = RolloutDrawer(session.model, scene_cameras(session), config)
        qpos = session.data.qpos.copy()
        plain = drawer.draw(RolloutFrame(1.0, qpos, Caption()))
        tried = drawer.draw(RolloutFrame(1.1, qpos, Caption(action=1, component="door-0 (door)"), highlight="door-0"))
        drawer.pose(qpos)
        part = drawer.geom_mask("three-quarter", drawer.part_geoms("door-0"))
        drawer.close()
    w, h = config.main_size
    changed = np.abs(tried[:h, :w].astype(int) - plain[:h, :w].astype(int)).max(axis=2) > 40
    assert part.sum() > 500 and changed[part].mean() > 0.9, "the part is not tinted"
    label = changed & ~part
    assert 300 < label.sum() < 0.02 * label.size, "no label beside it, or more than a label changed"


def _extreme_placements(spec, count=6):
    """Reachable box poses at the corners and edges of the placement range (x 0.30-0.60 m, |y| <= 0.30 m)."""
    poses = []
    for x in (0.30, 0.60, 0.45):
        for y in (-0.30, 0.30, 0.0):
            for yaw in np.linspace(-math.pi, math.pi, 13)[:-1]:
                if not unreachable_handles(spec, (x, y, float(yaw)), SceneConfig()):
                    poses.append((x, y, float(yaw)))
                    break
    return sorted(poses, key=lambda p: -math.hypot(p[0] - 0.45, p[1]))[:count]


FIVE_KINDS = generate_chain(["lever", "slide", "door", "drawer", "wheel"], seed=0)


@pytest.mark.parametrize("spec", [paper_family("test")[0], FIVE_KINDS], ids=["paper", "five-kinds"])
def test_the_three_quarter_view_frames_the_box_at_extreme_placements_and_no_view_washes_out(spec):
    config = RolloutConfig()
    poses = _extreme_placements(spec)
    assert len(poses) >= 4 and max(abs(p[1]) for p in poses) >= 0.3
    low, high = config.lid_luminance
    for pose in poses:
        with TwinSession(placed(spec, pose), seed=0) as session:
            drawer = RolloutDrawer(session.model, scene_cameras(session), config)
            qpos = session.data.qpos.copy()
            drawer.pose(qpos)
            box = drawer.box_mask("three-quarter")
            lid = drawer.lid_luminance(qpos)
            drawer.close()
        edges = np.concatenate([box[0], box[-1], box[:, 0], box[:, -1]])
        assert not edges.any(), f"the box touches the three-quarter view's edge at {pose}"
        assert box.mean() >= 0.25, f"the box fills {box.mean():.0%} of the three-quarter view at {pose}"
        assert lid["three-quarter"] is not None and lid["overview"] is not None
        assert all(low <= v <= high for v in lid.values() if v is not None), (pose, lid)


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
