"""Trials on a real xArm-7 through the same pipeline, proven against the twin standing in for the arm: the driver
(``real.XArmRobot``) runs on :class:`twin_sdk.TwinSDK`, a double of the SDK backed by a twin session, on
simulated time. The pipeline (``puzzlebox/lab/real_trial.py``) sees only what the driver gives; these tests read the
session's truth beside it."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from twin_sdk import TwinSDK, rpy_of, twin_xarm_cell

from puzzlebox.lab import RealCell, TrialConfig, TrialRecord, run_trial
from puzzlebox.lab.real_trial import cell_configs, run_real_trial
from puzzlebox.models.cell_config import EXAMPLE, CellConfig, save_cell_config
from puzzlebox.models.generator import paper_family
from puzzlebox.models.spec import save_spec
from puzzlebox.real import XArmRobot
from puzzlebox.real.xarm_driver import XARM7_JOINT_LIMITS, rpy_matrix
from puzzlebox.scripts import trial
from puzzlebox.skills.errors import MarkersNotFound
from puzzlebox.skills.perception import MarkerDetector, PerceptionConfig
from puzzlebox.skills.robot_world import RobotWorld
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.session import TwinSession

SPEC = paper_family("test")[0]


def arm_on(session: TwinSession, cell) -> tuple[XArmRobot, TwinSDK]:
    """The real driver over the twin, as ``trial.py --robot xarm`` makes it over an arm."""
    sdk = TwinSDK(session, cell)
    robot = XArmRobot(
        "twin", cell, sdk_factory=sdk.factory, camera_factory=sdk.camera, probe=lambda ip: None,
        sleep=sdk.sleep, clock=sdk.clock,
    )  # fmt: skip
    return robot, sdk


EXAMPLE_CELL = CellConfig.from_dict({**EXAMPLE, "camera_devices": {"overview": 0, "wrist": 1}})
"""The example cell with capture devices (for the driver without cameras)."""


class _QuietSDK:
    """Every command succeeds; the F/T sensor reads zero, the TCP stands at (0.3, 0, 0.2) m."""

    def __init__(self, ip):
        pass

    def __getattr__(self, name):
        return lambda *args, **kwargs: 0

    def get_ft_sensor_data(self):
        return 0, [0.0] * 6

    def get_position(self, **kwargs):
        return 0, [300.0, 0.0, 200.0, 0.0, 0.0, 0.0]


def test_the_driver_runs_on_an_injected_clock():
    now = [100.0]
    sleeps: list[float] = []

    def sleep(dt):
        sleeps.append(dt)
        now[0] += dt

    robot = XArmRobot("10.0.0.5", EXAMPLE_CELL, sdk_factory=_QuietSDK, probe=lambda ip: None, sleep=sleep,
                      clock=lambda: now[0])  # fmt: skip
    assert robot.time == 0.0
    robot.wait(0.035)
    assert robot.time == pytest.approx(0.035) and sleeps == pytest.approx([0.01, 0.01, 0.01, 0.005])


def test_the_double_gives_the_twins_readings_in_the_sdks_units_and_frames():
    with TwinSession(SPEC, seed=0, reality="ideal") as session:
        cell = twin_xarm_cell(session)
        robot, sdk = arm_on(session, cell)
        twin = session.robot
        robot.command_joint_positions(np.array(cell.rest_posture) + 0.2)
        robot.command_gripper(0.4)
        robot.wait(1.0)
        assert robot.time == pytest.approx(1.0) and session.time == pytest.approx(1.0, abs=1e-9)
        np.testing.assert_allclose(robot.joint_positions(), twin.joint_positions())
        np.testing.assert_allclose(robot.tcp_pose_in_base(), twin.tcp_pose_in_base(), atol=1e-12)
        assert robot.gripper_opening() == pytest.approx(twin.gripper_opening())
        # untared, the same load in the base frame (the gripper's weight, 7.37 N down) through the driver's
        # TCP-frame reading as through the twin's sensor-frame one
        force_real = robot.ft_rotation_in_base() @ robot.wrench()[:3]
        force_twin = twin.ft_rotation_in_base() @ twin.wrench()[:3]
        np.testing.assert_allclose(force_real, force_twin, atol=1e-9)
        assert force_real[2] == pytest.approx(-7.37, abs=0.05)
        robot.tare()
        assert np.linalg.norm(robot.wrench()[:3]) < 0.05
        image = robot.capture(cell.overview_camera)
        np.testing.assert_array_equal(image.rgb, twin.capture(cell.overview_camera).rgb)
    R = rpy_matrix(0.3, -0.4, 2.5)
    np.testing.assert_allclose(rpy_matrix(*rpy_of(R)), R, atol=1e-12)
    assert "emergency_stop" not in sdk.calls


@pytest.mark.parametrize("reality", ["ideal", "realistic"])
def test_a_paper_box_is_solved_through_the_real_driver_and_every_sensed_outcome_is_the_truth(reality):
    """Under ``realistic`` the double passes the profile's imperfections (sensor noise and bias, latency, the
    cameras' calibration error, friction, the box placed elsewhere) through the SDK's units and frames."""
    with TwinSession(SPEC, seed=0, reality=reality) as session:
        cell = twin_xarm_cell(session)
        robot, sdk = arm_on(session, cell)
        truth: list[np.ndarray] = [session.component_states().copy()]  # the test reads the session, the trial not
        trial = run_trial(  # the library's one entry: the real cell is where the trial runs
            session.spec, TrialConfig(agent="oracle", seed=0, max_actions=12),
            cell=RealCell(robot, cell, nominal_calibration(session)),
            on_action=lambda _: truth.append(session.component_states().copy()),
        )  # fmt: skip
        record = trial.to_dict()
        final = session.component_states()
        goal = session.spec.index_of(session.spec.goal.component)
        elapsed = session.time
        placed = session.spec  # where the profile placed the box
    assert record["solved"] and not record["stopped"] and record["ended"] == ""
    assert TrialRecord.from_dict(record) == trial and trial.outcome_agreement is None  # no truth on a real cell
    assert int(final[goal]) == SPEC.goal.state  # solved as perceived, and truly
    index = {c.name: i for i, c in enumerate(SPEC.components)}
    assert len(record["timeline"]) == record["num_actions"] == len(truth) - 1 >= 1
    for k, action in enumerate(record["timeline"]):
        i = index[action["component"]]
        assert action["moved"] == bool(truth[k + 1][i] != truth[k][i]), action
        assert "true_moved" not in action  # nothing of the simulator's in the record
    assert "emergency_stop" not in sdk.calls and "set_servo_angle_j" in sdk.calls
    # the oracle's optimum: every component once, in the spec's order, none failed or retried
    assert [a["component"] for a in record["actions"]] == list(SPEC.component_names)
    assert all(a["attempts"] == 1 for a in record["timeline"])
    # the driver's time is the simulated time the trial took (its clock), and holds every try's
    assert record["robot_time_s"] == pytest.approx(elapsed, abs=0.01)
    assert sum(a["sim_time"] for a in record["timeline"]) < record["robot_time_s"]
    # the closed poses the pipeline perceived through the driver's cameras are the spec's
    truth = dict(zip(placed.component_names, placed.poses_in_world(), strict=True))
    assert set(record["perceived_closed_poses"]) == set(truth)
    for name, pose in record["perceived_closed_poses"].items():
        assert np.linalg.norm(np.asarray(pose[:2]) - truth[name][:2]) < 0.005, name


def test_a_low_stop_force_in_the_cell_config_stops_the_arm_and_ends_the_trial(tmp_path, capsys):
    with TwinSession(SPEC, seed=0, reality="ideal") as session:
        # the primitives keep their pulls below the 36 N force limit, so a bump does it: 60 s in (after the survey
        # and a first try), someone pushes the hand down with 80 N for two seconds (long enough to span a phase in
        # which the arm only looks, reading no wrench); the driver's hard stop at 36.5 N, on the raw reading, stops
        # the arm
        cell = twin_xarm_cell(session, force_limit=36.0, stop_force=36.5)
        files = _cli_files(tmp_path, session, cell)
        sdks: list[TwinSDK] = []
        hand = session.data.body("xarm7/gripper/xarm_gripper_base_link")

        def connect(ip, cell_read):
            sdk = TwinSDK(session, cell_read)
            advance = sdk.sleep

            def sleep(seconds):  # the arm's clock, with the bump
                hand.xfrc_applied[2] = -80.0 if 60.0 <= session.time < 62.0 else 0.0
                advance(seconds)

            sdks.append(sdk)
            return XArmRobot(
                "twin", cell_read, sdk_factory=sdk.factory, camera_factory=sdk.camera, probe=lambda ip: None,
                sleep=sleep, clock=sdk.clock,
            )  # fmt: skip

        code = trial.main([*files, "--agent", "random", "--max-actions", "15"], arm=connect)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1
    assert len(err) == 1 and "the arm was stopped after" in err[0] and "stop_force 36.5 N" in err[0], err
    assert "emergency_stop" in sdks[0].calls and sdks[0].stopped
    after = sdks[0].calls[sdks[0].calls.index("emergency_stop") + 1 :]
    assert "set_servo_angle_j" not in after and "set_gripper_position" not in after  # nothing moved after it
    record = json.loads(next((tmp_path / "out/runs").glob("*.json")).read_text())["record"]
    assert record["stopped"].startswith("wrist force") and record["ended"].startswith("ForceLimitExceeded")
    assert not record["solved"] and record["num_actions"] == len(record["timeline"]) >= 1  # what was done is kept
    results = json.loads((tmp_path / "out/results.json").read_text())
    assert results["runs_done"] == 1 and results["runs"][0]["stopped"] == record["stopped"]


def test_trial_py_runs_a_real_trial_and_writes_what_was_sensed(tmp_path, capsys):
    with TwinSession(SPEC, seed=0, reality="ideal") as session:
        cell = twin_xarm_cell(session)
        files = _cli_files(tmp_path, session, cell)
        rest = np.array(cell.rest_posture)

        def connect(ip, cell_read):  # an arm handed over away from the cell's rest posture
            robot, _ = arm_on(session, cell_read)
            for k in range(1, 101):
                robot.command_joint_positions(rest + k / 100 * np.array([0.6, 0.3, 0.0, 0.3, 0.0, -0.2, 0.4]))
                robot.wait(0.02)
            return robot

        code = trial.main([*files, "--agent", "oracle", "--max-actions", "10"], arm=connect)
        np.testing.assert_allclose(session.robot.joint_positions(), rest, atol=0.01)  # back at rest at the end
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "oracle on the arm at twin: solved (as perceived) in 5 action(s)" in out.out
    results = json.loads((tmp_path / "out/results.json").read_text())
    assert results["success_rate"] == 1.0 and results["runs_done"] == 1
    config = json.loads((tmp_path / "out/config.json").read_text())
    assert config["robot"] == "xarm" and config["cell"]["name"] == "twin-as-xarm"


def test_the_detector_reads_the_cells_dictionary_only():
    with TwinSession(SPEC, seed=0, reality="ideal") as session:
        other = twin_xarm_cell(session, aruco_dictionary="DICT_6X6_250")
        image = session.robot.capture(other.overview_camera)
        assert len(MarkerDetector(PerceptionConfig.for_cell(twin_xarm_cell(session))).detect_pixels(image.rgb)) == 5
        assert MarkerDetector(PerceptionConfig.for_cell(other)).detect_pixels(image.rgb) == []
        assert PerceptionConfig.for_cell(twin_xarm_cell(session)) == PerceptionConfig()  # the twin's: the defaults
        robot, _ = arm_on(session, other)
        record = run_real_trial(robot, nominal_calibration(session), session.spec, other, "oracle", 0, 5)
    assert not record["solved"] and record["num_actions"] == 0 and not record["stopped"]
    cameras = [other.overview_camera, other.wrist_camera]
    missing = f"missing marker ids [0, 1, 2, 3, 4] after looking from {cameras}"
    assert record["ended"] == f"{MarkersNotFound.__name__}: {missing}"


def test_trial_py_refuses_more_than_one_spec_and_a_missing_calibration(tmp_path, capsys):
    with TwinSession(SPEC, seed=0, reality="ideal") as session:
        cell = twin_xarm_cell(session)
        files = _cli_files(tmp_path, session, cell)
    spec = files[files.index("--specs") + 1]
    without_calibration = files[: files.index("--calibration")] + files[files.index("--calibration") + 2 :]
    for argv, expected in (
        ([*files[:2], spec, *files[2:]], "--robot xarm tries the one box on the table: give one spec, got 2"),
        (without_calibration, "--robot xarm needs --calibration FILE"),
    ):
        with pytest.raises(SystemExit) as stop:
            trial.main([*argv, "--agent", "oracle", "--max-actions", "5"], arm=lambda ip, c: pytest.fail("connected"))
        err = capsys.readouterr().err.strip().splitlines()
        assert stop.value.code == 2 and len(err) == 1 and expected in err[0], err
    assert not (tmp_path / "out").exists()


def _cli_files(tmp_path: Path, session: TwinSession, cell) -> list[str]:
    """``trial.py --robot xarm`` arguments with the session's spec, the cell config and its nominal calibration."""
    spec = save_spec(session.spec, tmp_path / "box.json")
    calibration = nominal_calibration(session).save(tmp_path / "calibration.json")
    cell_file = save_cell_config(cell, tmp_path / "cell.json")
    return ["--specs", str(spec), "--sim", "twin", "--runs", "1", "--seed", "0", "--out", str(tmp_path / "out"),
            "--robot", "xarm", "--ip", "twin", "--cell", str(cell_file), "--calibration", str(calibration)]  # fmt: skip


def test_the_worlds_primitives_run_the_cells_thresholds():
    with TwinSession(SPEC, seed=0, reality="ideal") as session:
        cell = twin_xarm_cell(session, force_limit=45.0, blocked_force=15.0)
        world_config, perception = cell_configs(cell)
        spec = session.spec
        world = RobotWorld(
            session.robot, nominal_calibration(session), {c.marker: c.kind for c in spec.components},
            spec.components[spec.index_of(spec.goal.component)].marker, config=world_config,
            detector=MarkerDetector(perception),
        )  # fmt: skip
    assert (
        world.toggler.config.sensing.force_limit,
        world.toggler.config.judgement.blocked_force,
        world.toggler.watch.limit,
    ) == (45, 15, 45)
    assert world.survey.toggler is world.toggler  # the survey moved the arm with them too


def test_blocked_tries_are_sensed_as_the_twin_holds_them():
    """The random agent pulls latched parts: every ``blocked`` and ``moved`` the driver's F/T and cameras gave is
    the twin's truth."""
    with TwinSession(paper_family("test")[1], seed=1, reality="ideal") as session:
        cell = twin_xarm_cell(session)
        robot, _ = arm_on(session, cell)
        truth: list[np.ndarray] = [session.component_states().copy()]
        record = run_real_trial(
            robot, nominal_calibration(session), session.spec, cell, "random", 1, 15,
            on_action=lambda _: truth.append(session.component_states().copy()),
        )  # fmt: skip
        index = {c.name: i for i, c in enumerate(session.spec.components)}
    outcomes = [a["outcome"] for a in record["timeline"]]
    assert "blocked" in outcomes and "moved" in outcomes and len(outcomes) == len(truth) - 1
    for k, action in enumerate(record["timeline"]):
        i = index[action["component"]]
        assert action["moved"] == bool(truth[k + 1][i] != truth[k][i]), action


def test_the_drivers_joint_ranges_are_the_twins():
    """The driver refuses targets outside the ranges the skills' IK plans in: the twin's arm model's."""
    with TwinSession(SPEC, seed=0, reality="ideal") as session:
        np.testing.assert_allclose(XARM7_JOINT_LIMITS, session.robot.joint_limits(), atol=1e-4)
