"""A toggle log round-trips through its file, written atomically, and refuses what is not one."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.models.toggle_log import ARRAYS, PHASES, ToggleLog, load_toggles, save_toggles


def a_log(n: int = 7, seed: int = 0) -> ToggleLog:
    rng = np.random.default_rng(seed)
    return ToggleLog(
        component="door-0", marker=3, kind="door", joint="hinge", axis=np.array([0.0, -1.0, 0.0]),
        origin=rng.normal(size=3), grasp_point=rng.normal(size=3), pose=np.eye(4), travel=1.48, opening=True,
        outcome="moved", reason="", progress=0.98, time=np.arange(n) * 0.01, joints=rng.normal(size=(n, 7)),
        closure=rng.uniform(size=n), tcp=np.tile(np.eye(4), (n, 1, 1)), force=rng.normal(size=(n, 3)),
        torque=rng.normal(size=(n, 3)), joint_command=rng.normal(size=(n, 7)), gripper_command=rng.uniform(size=n),
        phase=rng.integers(len(PHASES), size=n), context={"spec": "paper-train-0", "seed": 4},
        truth={"kind_factors": {"joint_damping": {"door": 1.2}}},
    )  # fmt: skip


def test_toggles_round_trip_through_a_file_written_atomically(tmp_path):
    logs = [a_log(7, 0), a_log(3, 1)]
    path = save_toggles(tmp_path / "trial.npz", logs, {"spec": "paper-train-0"})
    loaded, context = load_toggles(path)
    assert context == {"spec": "paper-train-0"}
    assert [p.name for p in tmp_path.iterdir()] == ["trial.npz"]  # no temporary left behind
    for before, after in zip(logs, loaded, strict=True):
        assert after.header() == before.header()
        for name in ARRAYS:
            np.testing.assert_array_equal(getattr(after, name), getattr(before, name))


def test_a_log_whose_arrays_disagree_in_length_is_refused():
    log = a_log()
    with pytest.raises(ValueError, match="force"):
        ToggleLog(**{**log.__dict__, "force": log.force[:-1]})


def test_a_file_that_is_not_a_toggle_log_is_refused(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, header=np.frombuffer(b'{"format": "something-else"}', dtype=np.uint8))
    with pytest.raises(ValueError, match="something-else"):
        load_toggles(path)
