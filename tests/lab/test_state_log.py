"""A twin trial's state log (issue 53, item 1): written beside the record, the same trial to the bit with or without
it, its rows the physics and the commands as they were."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.lab import TrialConfig, TrialConfigError, run_trial
from puzzlebox.lab.state_log import ARRAYS, load_state_log, save_state_log
from puzzlebox.lab.trial_task import without_timing
from puzzlebox.models.generator import generate_chain
from puzzlebox.models.toggle_log import PHASES

SPEC = generate_chain(["slide", "wheel"], seed=1)
"""Two parts: the wheel held while the slide is closed."""


@pytest.fixture(scope="module")
def logged(tmp_path_factory):
    path = tmp_path_factory.mktemp("states") / "trial.npz"
    config = TrialConfig(agent="oracle", seed=5, max_actions=4, reality="realistic")
    plain = run_trial(SPEC, config)
    with_log = run_trial(SPEC, config, state_log=path)
    return plain, with_log, *load_state_log(path)


def test_a_trial_with_its_state_log_is_the_same_trial(logged):
    plain, with_log, _, _ = logged
    assert with_log.sensed_sha256 == plain.sensed_sha256 and plain.solved
    assert without_timing(with_log.to_dict()) == without_timing(plain.to_dict())


def test_the_log_holds_every_tick_from_the_survey_to_the_last_try(logged):
    _, record, log, meta = logged
    n = len(log["time"])
    assert meta["spec"] == SPEC.name and meta["seed"] == 5 and meta["phases"] == list(PHASES)
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
    assert log["in_try"].any() and not log["in_try"][0] and set(np.unique(log["phase"])) <= set(range(len(PHASES)))


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
