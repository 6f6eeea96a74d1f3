"""A real UFactory xArm-7 cell behind the :class:`models.robot.Robot` protocol, over ``xarm-python-sdk``.

The SDK (``from xarm.wrapper import XArmAPI``) is imported inside :class:`XArmRobot`'s constructor only, so
importing this module needs no SDK (``pip install puzzlebox[real]`` installs it). Before the SDK object is
made, the controller's TCP port (:data:`XARM_CONTROL_PORT`, the SDK's ``SocketConf.TCP_CONTROL_PORT``) is
probed with a short timeout: an address where no arm answers is refused in about a second, not after the
SDK's own retries.

How the protocol maps onto the SDK (``(code, value)`` returns; a non-zero code raises :class:`SDKCallFailed`):

- joints: ``get_servo_angle(is_radian=True)`` [rad], ``get_joint_states(is_radian=True)`` velocities [rad/s];
  commands stream in servo mode (``set_mode(1)``, ``set_state(0)`` at connection) through
  ``set_servo_angle_j(q, is_radian=True)``: the controller runs only the latest target.
- gripper: ``set_gripper_position(pos)`` / ``get_gripper_position()`` in the gripper's units, mapped from
  closure 0..1 onto the cell's ``gripper_open`` .. ``gripper_closed``.
- TCP pose: ``get_position(is_radian=True)`` = ``[x, y, z]`` [mm] and roll/pitch/yaw [rad] about the fixed
  base axes x, y, z; the controller's TCP offset must be set to the point between the finger pads.
- wrench: ``get_ft_sensor_data()`` (the controller's filtered, load-compensated F/T reading, sensor frame)
  minus this driver's last tare; ``tare`` also zeroes the controller's offset (``set_ft_sensor_zero``). The
  sensor frame is taken to be aligned with the TCP frame (a TCP offset without rotation).
- safety: every wrench read checks the tared force magnitude against the cell's hard stop (``stop_force``, by
  default 1.5 times the skills' ``force_limit``, which ends a try first on a filtered reading), and every
  command and every slice of :meth:`XArmRobot.wait` both it and the TCP's position against the cell's workspace
  box (``workspace_min`` .. ``workspace_max``), on readings at most one F/T sample period old (the sensor's
  rate: a control tick's commands and wait share one check); past either the arm is stopped
  (``emergency_stop``, i.e. ``set_state(4)``), :class:`ForceLimitExceeded` or :class:`WorkspaceExceeded` is
  raised and every later command refused.
- cameras: one ``cv2.VideoCapture(device)`` per camera, devices from the cell's ``camera_devices``; a failed
  read is a dropped frame (None). Robot time is the driver's clock since connection [s]: the host's monotonic
  clock, or an injected one (``clock``, with ``sleep``: a test double runs the driver on simulated time).
"""

from __future__ import annotations

import math
import socket
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from puzzlebox.models.cell_config import CellConfig
from puzzlebox.models.robot import CameraImage
from puzzlebox.real.errors import (
    ArmStopped,
    ArmUnreachable,
    CommandRefused,
    ForceLimitExceeded,
    SDKCallFailed,
    SDKMissing,
    UnknownCamera,
    WorkspaceExceeded,
)

XARM_CONTROL_PORT = 502
"""The xArm controller's TCP command port (``xarm.core.config.x_config.XCONF.SocketConf.TCP_CONTROL_PORT``)."""
PROBE_TIMEOUT = 1.0
"""How long the port probe waits for the controller [s]: a controller on the cell's LAN answers in ms."""
XARM7_JOINT_LIMITS = np.array(
    [
        [-2 * math.pi, 2 * math.pi],
        [-2.059, 2.0944],
        [-2 * math.pi, 2 * math.pi],
        [-0.19198, 3.927],
        [-2 * math.pi, 2 * math.pi],
        [-1.69297, math.pi],
        [-2 * math.pi, 2 * math.pi],
    ]
)
"""Joint ranges of the xArm-7 [rad], as the twin's model (Menagerie ``ufactory_xarm7``) and the skills' IK use them.
(The SDK's own table gives joint 4 as -3.927..0.192: its sign must be checked on the arm before a first motion.)"""


def probe_controller(ip: str, port: int = XARM_CONTROL_PORT, timeout: float = PROBE_TIMEOUT) -> None:
    """Refuse an address where no controller accepts a TCP connection within ``timeout`` [s]."""
    try:
        with socket.create_connection((ip, port), timeout=timeout):
            pass
    except OSError as err:
        raise ArmUnreachable(f"no xArm controller answers at {ip}:{port} within {timeout:.1f} s ({err})") from None


def _default_sdk(ip: str) -> Any:
    try:
        # the optional `real` extra, which make install leaves out: missing, it is the error below
        from xarm.wrapper import XArmAPI  # pyright: ignore[reportMissingImports]
    except ImportError:
        raise SDKMissing(
            "the xArm driver needs xarm-python-sdk: pip install 'puzzlebox[real]' (or xarm-python-sdk)"
        ) from None
    return XArmAPI(ip, is_radian=True)


def _default_camera(device: int | str) -> Any:
    import cv2

    return cv2.VideoCapture(device)


class XArmRobot:
    """A real xArm-7 cell (see the module docstring).

    Args:
        ip: the controller's address.
        cell: the cell's config (cameras and their devices, gripper range, force limit, F/T rate).
        sdk_factory: makes the SDK object from ``ip`` (default: ``XArmAPI(ip, is_radian=True)``).
        camera_factory: opens a capture from a device (default: ``cv2.VideoCapture``).
        probe: refuses an address where no controller answers (default :func:`probe_controller`).
        sleep: waits a time [s] (default ``time.sleep``); tests pass a fake.
        clock: reads the time [s] (default ``time.monotonic``): :attr:`time` and :meth:`wait` use it, so a test
            double whose ``sleep`` advances a simulation and whose ``clock`` reads its time runs on simulated time.
    """

    def __init__(
        self,
        ip: str,
        cell: CellConfig,
        *,
        sdk_factory: Callable[[str], Any] | None = None,
        camera_factory: Callable[[int | str], Any] | None = None,
        probe: Callable[[str], None] = probe_controller,
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        missing = [c for c in cell.camera_names if c not in cell.camera_devices]
        if missing:
            raise CommandRefused(f"cell config {cell.name!r} names no capture device for camera(s) {missing}")
        self.cell = cell
        self.camera_names: tuple[str, ...] = cell.camera_names
        self._sleep, self._clock = sleep, clock
        self._camera_factory = camera_factory or _default_camera
        self._captures: dict[str, Any] = {}
        self._bias = np.zeros(6)
        self._stopped: str | None = None
        self._guarded_at: float | None = None
        probe(ip)  # before the SDK: its own connection attempt retries for much longer
        self._arm = (sdk_factory or _default_sdk)(ip)
        self._t0 = self._clock()
        # ready for streaming: motors on, servo mode (set_servo_angle_j needs it), motion state
        try:
            for call, args in (("motion_enable", (True,)), ("set_mode", (1,)), ("set_state", (0,))):
                self._code(call, getattr(self._arm, call)(*args))
            self._code("set_ft_sensor_enable", self._arm.set_ft_sensor_enable(1))
        except BaseException:
            self._arm.disconnect()  # a half-set-up arm is let go, not left connected
            raise

    # -- SDK plumbing ------------------------------------------------------------------------------
    @staticmethod
    def _code(call: str, code: int) -> None:
        if code != 0:
            raise SDKCallFailed(f"xArm SDK {call} returned code {code} (UFACTORY API code documentation)")

    def _value(self, call: str, *args: Any, **kwargs: Any) -> Any:
        code, value = getattr(self._arm, call)(*args, **kwargs)
        self._code(call, code)
        return value

    # -- proprioception ----------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Time since connection on the driver's clock (the host's monotonic clock by default) [s]."""
        return self._clock() - self._t0

    def joint_positions(self) -> np.ndarray:
        """Arm joint positions [rad], joints 1..7."""
        return np.asarray(self._value("get_servo_angle", is_radian=True), dtype=float)[:7]

    def joint_velocities(self) -> np.ndarray:
        """Arm joint velocities [rad/s], joints 1..7."""
        states = self._value("get_joint_states", is_radian=True)
        return np.asarray(states[1], dtype=float)[:7]

    def joint_limits(self) -> np.ndarray:
        """``(7, 2)`` commandable range of each joint [rad] (:data:`XARM7_JOINT_LIMITS`)."""
        return XARM7_JOINT_LIMITS.copy()

    def gripper_opening(self) -> float:
        """How closed the gripper is, 0 (open) .. 1 (closed), from its position feedback."""
        return self.cell.gripper_closure(float(self._value("get_gripper_position")))

    def tcp_pose_in_base(self) -> np.ndarray:
        """4x4 TCP pose in the base frame [m], from the controller's kinematics."""
        x, y, z, roll, pitch, yaw = (float(v) for v in self._value("get_position", is_radian=True)[:6])
        T = np.eye(4)
        T[:3, :3] = rpy_matrix(roll, pitch, yaw)
        T[:3, 3] = np.array([x, y, z]) / 1000.0  # the SDK reports [mm]
        return T

    def ft_rotation_in_base(self) -> np.ndarray:
        """3x3 orientation of the F/T sensor frame in the base frame (taken as the TCP's orientation)."""
        return self.tcp_pose_in_base()[:3, :3]

    # -- the wrist F/T sensor ----------------------------------------------------------------------
    def _read_ft(self) -> np.ndarray:
        return np.asarray(self._value("get_ft_sensor_data"), dtype=float)[:6]

    def wrench(self) -> np.ndarray:
        """``[Fx, Fy, Fz, Tx, Ty, Tz]`` in the sensor frame [N, N·m], minus the last tare; stops the arm and
        raises :class:`ForceLimitExceeded` above the cell's hard stop (``CellConfig.hard_stop_force``)."""
        w = self._read_ft() - self._bias
        force = float(np.linalg.norm(w[:3]))
        if force > self.cell.hard_stop_force:
            self._stop(f"wrist force {force:.1f} N > the cell's stop_force {self.cell.hard_stop_force:.1f} N")
        return w

    def tare(self, samples: int = 10) -> None:
        """Zero the controller's F/T offset, then the mean of ``samples`` readings at the sensor's rate."""
        self._code("set_ft_sensor_zero", self._arm.set_ft_sensor_zero())
        readings = []
        for _ in range(max(1, samples)):
            readings.append(self._read_ft())
            self._sleep(1.0 / self.cell.ft_rate_hz)
        self._bias = np.mean(readings, axis=0)

    def _stop(self, why: str, error: type[ArmStopped] = ForceLimitExceeded) -> None:
        self._stopped = why
        self._arm.emergency_stop()  # set_state(4): the controller stops the motion at once
        raise error(f"{why}: the arm was stopped (emergency_stop)")

    def _check_workspace(self) -> None:
        """Stop the arm if its TCP has left the cell's workspace box."""
        p = self.tcp_pose_in_base()[:3, 3]
        low, high = np.asarray(self.cell.workspace_min), np.asarray(self.cell.workspace_max)
        outside = np.flatnonzero((p < low) | (p > high))
        if outside.size:
            axes = ", ".join(f"{'xyz'[i]}={p[i]:.3f} not in [{low[i]:.3f}, {high[i]:.3f}]" for i in outside)
            self._stop(f"TCP outside the cell's workspace ({axes} m)", WorkspaceExceeded)

    def _guard(self) -> None:
        """The safety limits: the force limit on a fresh F/T reading and the workspace on the TCP, checked at most
        once per F/T sample period (the sensor has no newer reading sooner; a control tick's commands and the wait
        after them share one check instead of costing two SDK round trips each)."""
        now = self._clock()
        if self._guarded_at is not None and now - self._guarded_at < (1.0 - 1e-6) / self.cell.ft_rate_hz:
            return
        self._guarded_at = now
        self.wrench()
        self._check_workspace()

    def _check_commandable(self) -> None:
        if self._stopped is not None:
            raise CommandRefused(f"the arm was stopped ({self._stopped}); clear it and connect again")
        self._guard()  # the force limit and the workspace hold at every command

    # -- commands ----------------------------------------------------------------------------------
    def command_joint_positions(self, q: np.ndarray) -> None:
        """Stream the 7 arm servo targets [rad] (servo mode); non-finite or out-of-range targets are refused."""
        q = np.asarray(q, dtype=float)
        if q.shape != (7,) or not np.isfinite(q).all():
            raise CommandRefused(f"need 7 finite joint targets [rad], got {q.tolist()}")
        low, high = XARM7_JOINT_LIMITS.T
        outside = np.flatnonzero((q < low) | (q > high))
        if outside.size:
            detail = ", ".join(f"joint{i + 1}={q[i]:.3f} not in [{low[i]:.3f}, {high[i]:.3f}]" for i in outside)
            raise CommandRefused(f"joint targets outside the joint ranges: {detail}")
        self._check_commandable()
        self._code("set_servo_angle_j", self._arm.set_servo_angle_j(q.tolist(), is_radian=True))

    def command_gripper(self, closure: float) -> None:
        """Gripper target, 0 (open) .. 1 (closed), mapped onto the cell's gripper range."""
        if not np.isfinite(closure) or not 0.0 <= closure <= 1.0:
            raise CommandRefused(f"gripper closure must be in [0, 1], got {closure}")
        self._check_commandable()
        pos = self.cell.gripper_command(float(closure))
        self._code("set_gripper_position", self._arm.set_gripper_position(pos, wait=False))

    def wait(self, seconds: float) -> None:
        """Let ``seconds`` pass [s], reading the wrench and the TCP at the sensor's rate (the force limit and the
        workspace hold meanwhile)."""
        period = 1.0 / self.cell.ft_rate_hz
        end = self._clock() + seconds
        while (left := end - self._clock()) > 0.0:
            self._guard()
            self._sleep(min(period, left))

    # -- cameras -----------------------------------------------------------------------------------
    def capture(self, camera: str) -> CameraImage | None:
        """An RGB frame from a named camera, or None when the camera gave none."""
        if camera not in self.camera_names:
            raise UnknownCamera(f"unknown camera {camera!r}. Available cameras: {list(self.camera_names)}")
        if camera not in self._captures:
            self._captures[camera] = self._camera_factory(self.cell.camera_devices[camera])
        ok, frame = self._captures[camera].read()
        if not ok or frame is None:
            return None
        return CameraImage(camera=camera, rgb=np.ascontiguousarray(frame[..., ::-1]), time=self.time)  # BGR -> RGB

    def close(self) -> None:
        """Release the cameras and disconnect from the controller."""
        for capture in self._captures.values():
            capture.release()
        self._captures.clear()
        self._arm.disconnect()

    def __enter__(self) -> XArmRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """``Rz(yaw) @ Ry(pitch) @ Rx(roll)``: roll, pitch, yaw about the fixed base axes x, y, z [rad]."""
    cr, sr, cp, sp, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


__all__ = ["PROBE_TIMEOUT", "XARM7_JOINT_LIMITS", "XARM_CONTROL_PORT", "XArmRobot", "probe_controller", "rpy_matrix"]
