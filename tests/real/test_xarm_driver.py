"""The xArm driver sends the SDK what the protocol means, tares and guards the wrench, and refuses quickly
where no arm answers. Nothing real is contacted: a fake SDK records every call; only 127.0.0.1 is probed."""

import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from puzzlebox.models.cell_config import EXAMPLE, CellConfig, save_cell_config
from puzzlebox.models.robot import Robot
from puzzlebox.real import (
    ArmStopped,
    ArmUnreachable,
    CommandRefused,
    ForceLimitExceeded,
    SDKMissing,
    UnknownCamera,
    WorkspaceExceeded,
    XArmRobot,
    xarm_driver,
)

ROOT = Path(__file__).resolve().parents[2]
CELL = CellConfig.from_dict({**EXAMPLE, "name": "test-cell", "camera_devices": {"overview": 0, "wrist": 1}})


class FakeSDK:
    """Records every call; plays back scripted joint angles, gripper positions and F/T readings."""

    def __init__(self, ip, ft=None, angles=None, gripper=(850.0,)):
        self.ip, self.calls = ip, []
        self.ft = list(ft or [[0.0] * 6])
        self.angles = list(angles or [[0.1 * i for i in range(7)]])
        self.gripper = list(gripper)

    def _next(self, script):
        return script.pop(0) if len(script) > 1 else script[0]

    def __getattr__(self, name):  # any command: recorded, code 0
        def call(*args, **kwargs):
            self.calls.append((name, args, kwargs))
            return 0

        return call

    def _get(self, name, value, kwargs):
        self.calls.append((name, (), kwargs))
        return 0, value

    def get_servo_angle(self, **kwargs):
        return self._get("get_servo_angle", self._next(self.angles), kwargs)

    def get_joint_states(self, **kwargs):
        return self._get("get_joint_states", [self.angles[0], [0.5] * 7, [0.0] * 7], kwargs)

    def get_gripper_position(self, **kwargs):
        return self._get("get_gripper_position", self._next(self.gripper), kwargs)

    def get_ft_sensor_data(self, **kwargs):
        return self._get("get_ft_sensor_data", self._next(self.ft), kwargs)

    position = [300.0, -100.0, 200.0, 0.0, 0.0, np.pi / 2]  # 90 deg about z, at (300, -100, 200) mm

    def get_position(self, **kwargs):
        return self._get("get_position", list(self.position), kwargs)

    def names(self):
        return [c[0] for c in self.calls]


class FakeCapture:
    def __init__(self, frames):
        self.frames = list(frames)

    def read(self):
        frame = self.frames.pop(0) if self.frames else None
        return frame is not None, frame

    def release(self):
        pass


def make(clock=None, **sdk_kwargs):
    """A driver on a fake SDK; its clock, unless given, moves one F/T period (10 ms) per reading."""
    sdks = []
    ticks = [0.0]

    def ticking():
        ticks[0] += 0.01
        return ticks[0]

    def factory(ip):
        sdks.append(FakeSDK(ip, **sdk_kwargs))
        return sdks[-1]

    bgr = np.zeros((4, 6, 3), np.uint8)
    bgr[..., 0] = 255  # blue in OpenCV's BGR
    robot = XArmRobot(
        "10.0.0.5", CELL, sdk_factory=factory, probe=lambda ip: None, sleep=lambda s: None,
        camera_factory=lambda device: FakeCapture([bgr] if device == 0 else []), clock=clock or ticking,
    )  # fmt: skip
    return robot, sdks[0]


def test_driver_satisfies_the_robot_protocol_and_sets_servo_mode():
    robot, sdk = make()
    assert isinstance(robot, Robot)
    assert sdk.ip == "10.0.0.5"
    assert sdk.calls[:4] == [
        ("motion_enable", (True,), {}), ("set_mode", (1,), {}), ("set_state", (0,), {}),
        ("set_ft_sensor_enable", (1,), {}),
    ]  # fmt: skip


def test_joint_targets_stream_in_radians_and_readings_come_back_in_radians():
    robot, sdk = make(angles=[[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]])
    q = np.array([0.0, 0.1, 0.0, 1.0, 0.0, 1.2, 0.0])
    robot.command_joint_positions(q)
    name, args, kwargs = sdk.calls[-1]
    assert name == "set_servo_angle_j" and args[0] == q.tolist() and kwargs == {"is_radian": True}
    assert robot.joint_positions() == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7])
    assert robot.joint_velocities() == pytest.approx([0.5] * 7)
    T = robot.tcp_pose_in_base()
    assert T[:3, 3] == pytest.approx([0.3, -0.1, 0.2])  # mm -> m
    assert T[:3, :3] @ np.array([1.0, 0, 0]) == pytest.approx([0.0, 1.0, 0.0])
    for bad in (np.full(7, np.nan), np.zeros(6), np.array([0, 0, 0, -1.0, 0, 0, 0])):
        with pytest.raises(CommandRefused):
            robot.command_joint_positions(bad)
    assert sdk.names().count("set_servo_angle_j") == 1


def test_gripper_closure_maps_onto_the_cells_range():
    robot, sdk = make(gripper=[850.0, 212.5, 0.0])
    robot.command_gripper(0.25)
    assert sdk.calls[-1] == ("set_gripper_position", (637.5,), {"wait": False})
    assert [robot.gripper_opening() for _ in range(3)] == pytest.approx([0.0, 0.75, 1.0])
    with pytest.raises(CommandRefused):
        robot.command_gripper(1.5)


def test_wrench_is_tared_in_the_sensor_frame():
    bias = [1.0, -2.0, 7.37, 0.1, 0.0, -0.1]
    readings = [bias] * 10 + [[6.0, -2.0, 7.37, 0.1, 0.5, -0.1]]
    robot, sdk = make(ft=readings)
    robot.tare(samples=10)
    assert "set_ft_sensor_zero" in sdk.names()
    assert robot.wrench() == pytest.approx([5.0, 0.0, 0.0, 0.0, 0.5, 0.0])


def test_force_above_the_cells_stop_force_stops_the_arm_and_refuses_commands():
    # 61 N: past the skills' 60 N force limit, which ends a try on a filtered reading, not the driver's hard stop
    robot, sdk = make(ft=[[0.0] * 6, [0.0, 0.0, 61.0, 0, 0, 0], [0.0, 0.0, 91.0, 0, 0, 0]])
    robot.command_gripper(0.5)  # 0 N: accepted
    robot.command_gripper(0.6)  # 61 N: accepted
    assert "emergency_stop" not in sdk.names()
    with pytest.raises(ForceLimitExceeded, match="91.0 N > the cell's stop_force 90.0 N"):
        robot.command_joint_positions(np.array(CELL.rest_posture))
    assert "emergency_stop" in sdk.names() and "set_servo_angle_j" not in sdk.names()
    with pytest.raises(CommandRefused, match="stopped"):
        robot.command_gripper(0.0)


def test_a_tcp_outside_the_cells_workspace_stops_the_arm_and_refuses_commands():
    robot, sdk = make()
    robot.command_gripper(0.5)  # the TCP at (0.3, -0.1, 0.2) m: inside the example cell's box
    sdk.position = [300.0, -100.0, 650.0, 0.0, 0.0, 0.0]  # 0.65 m up: above the box's 0.58 m
    with pytest.raises(WorkspaceExceeded, match=r"z=0.650 not in \[0.000, 0.580\]"):
        robot.command_joint_positions(np.array(CELL.rest_posture))
    assert "emergency_stop" in sdk.names() and "set_servo_angle_j" not in sdk.names()
    with pytest.raises(CommandRefused, match="stopped"):
        robot.command_gripper(0.0)
    assert isinstance(WorkspaceExceeded("x"), ArmStopped) and isinstance(ForceLimitExceeded("x"), ArmStopped)


def test_a_ticks_commands_share_one_safety_check():
    """The F/T sensor has no newer reading within its sample period: the commands of one control tick read the
    wrench and the TCP once, the next period reads them again."""
    now = [5.0]
    robot, sdk = make(clock=lambda: now[0])
    robot.command_joint_positions(np.array(CELL.rest_posture))
    robot.command_gripper(0.5)
    assert sdk.names().count("get_ft_sensor_data") == 1 and sdk.names().count("get_position") == 1
    now[0] += 1.0 / CELL.ft_rate_hz
    robot.command_gripper(0.6)
    assert sdk.names().count("get_ft_sensor_data") == 2 and sdk.names().count("get_position") == 2


def test_cameras_give_rgb_frames_and_none_for_a_dropped_frame():
    robot, _ = make()
    image = robot.capture("overview")
    assert image.camera == "overview" and image.rgb[0, 0].tolist() == [0, 0, 255]
    assert robot.capture("wrist") is None
    with pytest.raises(UnknownCamera, match=r"Available cameras: \['overview', 'wrist'\]"):
        robot.capture("side")


def test_no_arm_at_the_address_is_refused_within_3_s():
    start = time.monotonic()
    with pytest.raises(ArmUnreachable, match="no xArm controller answers at 127.0.0.1:502"):
        XArmRobot("127.0.0.1", CELL, sdk_factory=FakeSDK)
    assert time.monotonic() - start < 3.0


def test_missing_sdk_is_a_typed_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "xarm", None)  # import xarm.wrapper fails as if not installed
    monkeypatch.setitem(sys.modules, "xarm.wrapper", None)
    with pytest.raises(SDKMissing, match=r"puzzlebox\[real\]"):
        XArmRobot("10.0.0.5", CELL, probe=lambda ip: None)


def test_module_imports_without_the_sdk():
    code = "import sys, real.xarm_driver; assert 'xarm' not in sys.modules, 'the SDK was imported'"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert xarm_driver.XARM_CONTROL_PORT == 502


def test_trial_with_xarm_and_no_arm_exits_2_with_one_line(tmp_path):
    cell = save_cell_config(CELL, tmp_path / "cell.json")
    common = [sys.executable, ROOT / "scripts/trial.py", "--specs", tmp_path / "none.json", "--sim", "twin", "--runs",
              "1", "--seed", "0", "--max-actions", "5", "--out", tmp_path / "out", "--robot", "xarm"]  # fmt: skip
    for extra, expected in (
        (["--ip", "127.0.0.1", "--cell", cell], "no xArm controller answers at 127.0.0.1:502"),
        (["--cell", cell], "--robot xarm needs --ip"),
    ):
        start = time.monotonic()
        result = subprocess.run([*map(str, common), *map(str, extra)], capture_output=True, text=True, timeout=60)
        assert result.returncode == 2 and expected in result.stderr, result.stderr
        assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr
        assert time.monotonic() - start < 10.0  # the interpreter's imports included
    assert not (tmp_path / "out").exists()
