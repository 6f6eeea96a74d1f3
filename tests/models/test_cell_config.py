"""A cell config round-trips, lists every problem at once, refuses unknown keys, and the twin's matches the twin."""

import json

import pytest

from puzzlebox.models.cell_config import EXAMPLE, CellConfig, CellConfigError, load_cell_config, save_cell_config

GOOD = EXAMPLE


def test_config_round_trips_through_its_file(tmp_path):
    config = CellConfig.from_dict(GOOD)
    path = save_cell_config(config, tmp_path / "cell.json")
    assert load_cell_config(path) == config
    assert json.loads(path.read_text()) == GOOD
    assert config.gripper_command(0.0) == 850.0 and config.gripper_command(1.0) == 0.0
    assert config.gripper_closure(425.0) == pytest.approx(0.5)


def test_every_problem_is_listed_in_one_error(tmp_path):
    bad = dict(
        GOOD,
        format="puzzlebox-cell/0",
        wrist_camera="hand",
        aruco_dictionary="DICT_9X9_1",
        marker_size=-0.01,
        force_limit=10.0,
        gripper_closed=850.0,
        rest_posture=[0.0] * 6,
        workspace_max=[0.62, -0.7, 0.58],
        ft_rate_hz=float("nan"),
    )
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(CellConfigError) as caught:
        load_cell_config(path)
    text = "\n".join(caught.value.problems)
    for expected in ("format", "'hand' is not a camera", "DICT_9X9_1", "marker_size", "force_limit (10.0 N)",
                     "gripper_open and gripper_closed", "rest_posture", "workspace_min", "ft_rate_hz"):  # fmt: skip
        assert expected in text, expected
    assert len(caught.value.problems) == 9 and str(path) in str(caught.value)


def test_unknown_and_missing_keys_are_refused():
    data = {k: v for k, v in GOOD.items() if k != "ft_rate_hz"}
    with pytest.raises(CellConfigError, match=r"unknown key\(s\) \['force_limt'\]; known keys") as caught:
        CellConfig.from_dict(dict(data, force_limt=60.0))
    assert any("missing key(s) ['ft_rate_hz']" in p for p in caught.value.problems)


def test_a_camera_device_for_no_camera_is_refused():
    with pytest.raises(CellConfigError, match="'side' is not a camera of the cell"):
        CellConfig.from_dict(dict(GOOD, camera_devices={"side": 1}))


def test_twin_config_matches_the_constants_twin_and_skills_use(tmp_path):
    from puzzlebox.models.generator.paper import paper_family
    from puzzlebox.models.kinds import MARKER_SIZE
    from puzzlebox.models.markers import ARUCO_DICTIONARY
    from puzzlebox.models.xarm7 import HOME_QPOS
    from puzzlebox.skills.primitives import PrimitiveConfig
    from puzzlebox.twin.cell_config import twin_cell_config
    from puzzlebox.twin.robot_interface import GRIPPER_CTRL_MAX
    from puzzlebox.twin.session import TwinSession

    skills = PrimitiveConfig()
    with TwinSession(paper_family("test")[0], seed=0, reality="realistic") as session:
        config = twin_cell_config(
            session, force_limit=skills.sensing.force_limit, blocked_force=skills.judgement.blocked_force
        )
        robot = session.robot
        assert config.camera_names == robot.camera_names
        assert {config.overview_camera, config.wrist_camera} == set(robot.camera_names)
        assert all(robot.capture(name) is not None for name in config.camera_names)
        assert config.ft_rate_hz == session.ft.config.rate_hz == 100.0
    assert load_cell_config(save_cell_config(config, tmp_path / "puzzlebox.twin.json")) == config
    assert config.rest_posture == HOME_QPOS
    assert (config.force_limit, config.blocked_force) == (60.0, 20.0)  # the skills' values, unchanged
    assert (config.gripper_open, config.gripper_closed) == (0.0, GRIPPER_CTRL_MAX)
    assert config.marker_size == MARKER_SIZE
    import cv2

    assert getattr(cv2.aruco, config.aruco_dictionary) == ARUCO_DICTIONARY


def test_the_drivers_stop_force_stands_above_the_skills_force_limit():
    cell = CellConfig.from_dict(EXAMPLE)
    assert cell.force_limit < cell.hard_stop_force == 90.0
    without = {k: v for k, v in EXAMPLE.items() if k != "stop_force"}  # a file written before the key existed
    assert CellConfig.from_dict(without).hard_stop_force == 1.5 * EXAMPLE["force_limit"]
    with pytest.raises(CellConfigError, match=r"stop_force \(60.0 N\) must exceed force_limit \(60.0 N\)"):
        CellConfig.from_dict({**EXAMPLE, "stop_force": 60.0})
    with pytest.raises(CellConfigError, match="stop_force: expected a finite number"):
        CellConfig.from_dict({**EXAMPLE, "stop_force": "high"})
