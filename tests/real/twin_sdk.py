"""A test double of ``xarm-python-sdk``'s ``XArmAPI`` backed by the MuJoCo twin: the real-arm driver
(:class:`real.XArmRobot`) runs on it exactly as it runs on an arm, on simulated time.

Each SDK call the driver makes is mapped onto a :class:`twin.session.TwinSession`'s robot interface
(``twin/robot_interface.py``), in the units and frames the SDK uses:

- joints [rad] (``is_radian=True``), streamed in servo mode (``set_servo_angle_j``);
- the gripper in the cell's units (``gripper_open`` .. ``gripper_closed``: 850 .. 0 for the xArm Gripper);
- the TCP pose as ``[x, y, z]`` [mm] and roll, pitch, yaw about the fixed base axes (``Rz @ Ry @ Rx``) [rad];
- the F/T reading in the TCP frame (the driver takes the sensor frame to be the TCP's): the twin's wrench,
  given in its sensor frame, is turned into the TCP frame;
- ``emergency_stop`` holds the arm where it is and refuses every later motion (SDK code 1, as a controller in
  the stop state does).

Time: :meth:`TwinSDK.sleep` advances the twin, :meth:`TwinSDK.clock` reads simulated time. The clock counts the
time asked for exactly and the twin follows it in whole physics steps (within half a step), so a wait of
``seconds`` ends when it should, not one step late. Cameras: :meth:`TwinSDK.camera` opens a capture whose
``read()`` gives ``(True, BGR image)`` from the twin's render (``(False, None)`` for a dropped frame), by the
devices :func:`twin_xarm_cell` gives the twin's cameras.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from puzzlebox.models.cell_config import CellConfig
from puzzlebox.skills.primitives import PrimitiveConfig
from puzzlebox.twin.cell_config import twin_cell_config
from puzzlebox.twin.session import TwinSession

STOPPED_CODE = 1
"""What a motion command returns once the arm was stopped (a controller in the stop state refuses it)."""


def twin_xarm_cell(session: TwinSession, **overrides: Any) -> CellConfig:
    """The twin's cell as a real xArm cell describes it: the twin's cameras (devices 0, 1, ...), the xArm
    Gripper's units (850 open .. 0 closed), the F/T sensor read at the primitives' 100 Hz control tick, the
    skills' force thresholds; ``overrides`` replace any field (``force_limit``, ``aruco_dictionary``...)."""
    defaults = PrimitiveConfig()
    cell = twin_cell_config(
        session, force_limit=defaults.sensing.force_limit, blocked_force=defaults.judgement.blocked_force
    )
    return replace(
        cell,
        name="twin-as-xarm",
        camera_devices={name: i for i, name in enumerate(cell.camera_names)},
        gripper_open=850.0,
        gripper_closed=0.0,
        ft_rate_hz=1.0 / defaults.motion.tick,
        **overrides,
    )


def rpy_of(R: np.ndarray) -> tuple[float, float, float]:
    """Roll, pitch, yaw [rad] with ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (the SDK's convention)."""
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    return math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0])


class TwinCapture:
    """``cv2.VideoCapture`` of one twin camera."""

    def __init__(self, sdk: TwinSDK, camera: str) -> None:
        self.sdk, self.camera = sdk, camera

    def read(self) -> tuple[bool, np.ndarray | None]:
        image = self.sdk.robot.capture(self.camera)
        if image is None:
            return False, None
        return True, np.ascontiguousarray(image.rgb[..., ::-1])  # a capture gives BGR

    def release(self) -> None:
        pass


class TwinSDK:
    """See the module docstring. ``cell`` is the cell config the driver is given (its gripper range and camera
    devices are read here)."""

    def __init__(self, session: TwinSession, cell: CellConfig) -> None:
        self.session, self.robot, self.cell = session, session.robot, cell
        self.calls: list[str] = []
        """Names of the SDK calls made, in order."""
        self.stopped = False
        self.connected = True
        self._now = session.time
        low_high = self.robot.joint_limits()
        self._low, self._high = low_high[:, 0], low_high[:, 1]
        self._camera_of = {device: name for name, device in cell.camera_devices.items()}

    def factory(self, ip: str) -> TwinSDK:
        """The driver's ``sdk_factory``: this double, whatever the address."""
        self.ip = ip
        return self

    def camera(self, device: int | str) -> TwinCapture:
        """The driver's ``camera_factory``."""
        return TwinCapture(self, self._camera_of[device])

    # -- time --------------------------------------------------------------------------------------
    def sleep(self, seconds: float) -> None:
        self._now += max(0.0, seconds)
        steps = round((self._now - self.session.time) / self.session.timestep)
        if steps > 0:
            self.session.step(steps)

    def clock(self) -> float:
        return self._now

    # -- set-up ------------------------------------------------------------------------------------
    def _call(self, name: str, code: int = 0) -> int:
        self.calls.append(name)
        return code

    def motion_enable(self, enable: bool = True) -> int:
        return self._call("motion_enable")

    def set_mode(self, mode: int = 0) -> int:
        return self._call("set_mode")

    def set_state(self, state: int = 0) -> int:
        if state == 4:
            return self.emergency_stop()
        return self._call("set_state")

    def set_ft_sensor_enable(self, on_off: int) -> int:
        return self._call("set_ft_sensor_enable")

    def disconnect(self) -> None:
        self.connected = False
        self._call("disconnect")

    # -- readings ----------------------------------------------------------------------------------
    def get_servo_angle(self, is_radian: bool = True) -> tuple[int, list[float]]:
        assert is_radian
        self.calls.append("get_servo_angle")
        return 0, self.robot.joint_positions().tolist()

    def get_joint_states(self, is_radian: bool = True) -> tuple[int, list[list[float]]]:
        assert is_radian
        self.calls.append("get_joint_states")
        return 0, [self.robot.joint_positions().tolist(), self.robot.joint_velocities().tolist(), [0.0] * 7]

    def get_gripper_position(self) -> tuple[int, float]:
        self.calls.append("get_gripper_position")
        return 0, self.cell.gripper_command(self.robot.gripper_opening())

    def get_position(self, is_radian: bool = True) -> tuple[int, list[float]]:
        assert is_radian
        self.calls.append("get_position")
        T = self.robot.tcp_pose_in_base()
        return 0, [*(1000.0 * T[:3, 3]).tolist(), *rpy_of(T[:3, :3])]

    def get_ft_sensor_data(self) -> tuple[int, list[float]]:
        self.calls.append("get_ft_sensor_data")
        w = self.robot.wrench()  # in the twin's sensor frame
        R_tcp_ft = self.robot.tcp_pose_in_base()[:3, :3].T @ self.robot.ft_rotation_in_base()
        return 0, [*(R_tcp_ft @ w[:3]).tolist(), *(R_tcp_ft @ w[3:]).tolist()]

    def set_ft_sensor_zero(self) -> int:
        self.robot.tare()
        return self._call("set_ft_sensor_zero")

    # -- commands ----------------------------------------------------------------------------------
    def set_servo_angle_j(self, angles: list[float], is_radian: bool = True, **kwargs: Any) -> int:
        assert is_radian
        if self.stopped:
            return self._call("set_servo_angle_j", STOPPED_CODE)
        # the controller's own ranges (the twin's actuators round the datasheet's 2 pi and pi in the 6th digit)
        self.robot.command_joint_positions(np.clip(np.asarray(angles, dtype=float), self._low, self._high))
        return self._call("set_servo_angle_j")

    def set_gripper_position(self, pos: float, wait: bool = False, **kwargs: Any) -> int:
        if self.stopped:
            return self._call("set_gripper_position", STOPPED_CODE)
        self.robot.command_gripper(self.cell.gripper_closure(float(pos)))
        return self._call("set_gripper_position")

    def emergency_stop(self) -> int:
        """Stop: hold the joints where they are, refuse every later motion."""
        if not self.stopped:
            self.robot.command_joint_positions(np.clip(self.robot.joint_positions(), self._low, self._high))
        self.stopped = True
        return self._call("emergency_stop")


__all__ = ["TwinCapture", "TwinSDK", "rpy_of", "twin_xarm_cell"]
