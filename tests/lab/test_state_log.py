"""A twin trial's state log (issue 53, item 1): written beside the record, the same trial to the bit with or without
it, its rows the physics and the commands as they were."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.lab import TrialConfig, TrialConfigError, run_trial, twin_trial
from puzzlebox.lab.state_log import (
    ARRAYS,
    SURVEYING,
    load_state_log,
    replay_frames,
    replay_session,
    save_state_log,
)
from puzzlebox.lab.trial_task import without_timing
from puzzlebox.models.generator import generate_chain
from puzzlebox.models.toggle_log import PHASES
from puzzlebox.twin.rollout_video import FrameCollector

SPEC = generate_chain(["slide", "wheel"], seed=1)
"""Two parts: the wheel held while the slide is closed."""


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    """The trial plain, then with its state log and its video's frames (kept, not drawn)."""
    path = tmp_path_factory.mktemp("states") / "trial.npz"
    config = TrialConfig(agent="oracle", seed=5, max_actions=4, reality="realistic")
    plain = run_trial(SPEC, config)
    drawing = twin_trial.BackgroundRollout
    twin_trial.BackgroundRollout = FrameCollector  # the frames' states kept, not drawn
    try:
        with_log = run_trial(SPEC, config, state_log=path, video=path.with_suffix(".mp4"))
    finally:
        twin_trial.BackgroundRollout = drawing
    assert FrameCollector.last is not None
    return plain, with_log, *load_state_log(path), FrameCollector.last.frames


def test_a_trial_with_its_state_log_is_the_same_trial(logged):
    plain, with_log, *_ = logged
    assert with_log.sensed_sha256 == plain.sensed_sha256 and plain.solved
    assert without_timing(with_log.to_dict()) == without_timing(plain.to_dict())


def test_the_log_holds_every_tick_from_the_survey_to_the_last_try(logged):
    _, record, log, meta, _ = logged
    n = len(log["time"])
    assert meta["spec"] == SPEC.name and meta["seed"] == 5 and meta["phases"] == list(PHASES)
    assert log["phase"][0] == SURVEYING and np.isnan(log["force_sensed"][0]) and meta["end_time"] == record.sim_time_s
    assert all(len(log[name]) == n for name in ARRAYS) and log["qpos"].shape == (n, meta["nq"])
    assert np.all(np.diff(log["time"]) > 0) and log["time"][-1] <= record.sim_time_s + 1e-9
    assert abs(np.median(np.diff(log["time"])) - 0.01) < 1e-9  # the control rate
    # the parts' states step where the tries moved them, and the log ends in the record's final state
    assert log["part_states"][0].tolist() == [0, 0]
    assert log["action"][-1] == record.num_actions - 1 and log["in_try"][-1]  # (the last tick is the last try's)
    changes = int(np.sum(np.any(np.diff(log["part_states"], axis=0) != 0, axis=1)))
    assert changes >= sum(a["true_moved"] for a in record.to_dict()["timeline"])
    goal = SPEC.index_of(SPEC.goal.component)
    assert log["part_states"][-1][goal] == SPEC.goal.state
    # commands: none before the first, the arm's targets within its reach after; the wrench as sensed
    first = int(np.argmax(~np.isnan(log["joint_command"][:, 0])))
    assert np.all(np.isnan(log["joint_command"][:first])) and not np.any(np.isnan(log["joint_command"][first:]))
    assert np.all(np.abs(log["joint_command"][first:]) < 2 * np.pi)
    assert np.nanmax(np.linalg.norm(log["wrench"][:, :3], axis=1)) > 5.0  # a try pressed on something
    assert (
        log["in_try"].any()
        and not log["in_try"][0]
        and set(np.unique(log["phase"])) <= {SURVEYING, *range(len(PHASES))}
    )


def test_a_state_log_is_read_back_or_refused_in_one_line(tmp_path):
    arrays = {name: np.zeros(3) for name in ARRAYS}
    path = save_state_log(tmp_path / "log.npz", arrays, {"format": "puzzlebox-state-log/1"})
    assert set(load_state_log(path)[0]) == set(ARRAYS)
    np.savez(tmp_path / "other.npz", x=np.zeros(2))
    with pytest.raises(ValueError, match="not a state log"):
        load_state_log(tmp_path / "other.npz")


def test_a_state_log_is_of_a_twin_trial():
    with pytest.raises(TrialConfigError, match="state log is of a twin trial"):
        run_trial(SPEC, TrialConfig(sim="symbolic"), state_log="x.npz")


def test_the_rollout_s_frames_replayed_from_the_log_are_the_frames_the_trial_made_live(logged):
    _, record, log, meta, live = logged
    replayed = replay_frames(log, meta)
    assert len(replayed) == len(live) > 10 * record.sim_time_s - 2
    for a, b in zip(live, replayed, strict=True):
        assert a.time == b.time and np.array_equal(a.qpos, b.qpos) and a.caption == b.caption, a.time
        assert a.highlight == b.highlight and np.array_equal(a.forces, b.forces), a.time
        assert a.looks.keys() == b.looks.keys(), a.time
        for camera, look in a.looks.items():
            other = b.looks[camera]
            assert look.time == other.time and [m for m, _ in look.found] == [m for m, _ in other.found]
            assert all(np.array_equal(c, d) for (_, c), (_, d) in zip(look.found, other.found, strict=True))
            if look.qpos is None or other.qpos is None:
                assert look.qpos is None and other.qpos is None
            else:
                assert np.array_equal(look.qpos, other.qpos)
    assert sum(bool(f.looks) for f in live) >= 2 and {f.caption.action for f in live} >= {1, 2}


def test_the_log_s_scene_builds_the_trial_s_model_again(logged):
    _, record, _, meta, _ = logged
    with replay_session(meta) as session:
        assert session.spec.name == SPEC.name and tuple(session.box_pose) == tuple(record.box_pose)
        assert session.model.nq == meta["nq"]
