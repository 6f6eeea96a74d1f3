"""The robot interface: what a real xArm-7 driver, its wrist F/T sensor and the cell's cameras give.

It implements :class:`models.robot.Robot`, the only door the robot's pipeline (``skills``) has into the
twin: camera frames (no intrinsics, no extrinsics: those come from calibration; None for a dropped
frame), joint positions as the encoders read them, joint velocities, the gripper opening, the wrist
wrench, the TCP pose the arm's own kinematics report, and joint-position and gripper commands. It
exposes no simulator ground truth (no box joint, no latch, no component state, no true camera), so a
pipeline that works here has nothing a real cell would not give it.

It holds no state of its own: every reading and command goes to the cell's sensor models and servo interface
(the session's ``ft``, ``encoders``, ``cameras``, ``servos``, where the reality profile acts), which it is given
with the physics it reads and the session's ``advance``: the parts it reads, not the session.

Frames: the robot base frame is the world frame of the twin. Wrenches are in the F/T sensor frame
(``ft_site``), as a real sensor reports them; :meth:`RobotInterface.ft_rotation_in_base` turns them
into the base frame.
"""

from __future__ import annotations

from collections.abc import Callable

import mujoco
import numpy as np

from puzzlebox.models.robot import CameraImage
from puzzlebox.models.scene import SceneNames
from puzzlebox.twin.errors import CommandError
from puzzlebox.twin.sensors.cameras import Cameras
from puzzlebox.twin.sensors.encoders import JointEncoders
from puzzlebox.twin.sensors.force_torque import ForceTorqueSensor
from puzzlebox.twin.servos import Servos

GRIPPER_CTRL_MAX = 255.0
"""The xArm gripper's command range is 0 (open) .. 255 (closed)."""


class RobotInterface:
    """See the module docstring. Obtain it from :attr:`TwinSession.robot`, which gives it the cell's ``model``
    and ``data``, the scene's ``names``, its sensor models and servos, the arm's dof and actuator indices, and
    ``advance(seconds)``, which steps the cell."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        names: SceneNames,
        sensors: tuple[JointEncoders, ForceTorqueSensor, Cameras],
        servos: Servos,
        arm_dof: np.ndarray,
        arm_actuators: np.ndarray,
        advance: Callable[[float], None],
    ) -> None:
        self._data = data
        self._encoders, self._ft, self._cameras = sensors
        self._servos, self._arm_dof, self._advance = servos, arm_dof, advance
        m = model
        self.camera_names: tuple[str, ...] = self._cameras.names
        self._ctrl_range = m.actuator_ctrlrange[arm_actuators].copy()
        self._low, self._high = self._ctrl_range[:, 0] - 1e-9, self._ctrl_range[:, 1] + 1e-9  # what is accepted
        driver = m.joint(names.gripper_actuator.replace("fingers", "right_driver_joint"))
        self._gripper_qpos, self._gripper_range = (
            int(driver.qposadr[0]),
            (float(driver.range[0]), float(driver.range[1])),
        )

    # -- proprioception ----------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return float(self._data.time)

    def joint_positions(self) -> np.ndarray:
        """Arm joint positions as the encoders read them [rad], joints 1..7."""
        return self._encoders.positions()

    def joint_velocities(self) -> np.ndarray:
        """Arm joint velocities [rad/s], joints 1..7."""
        return self._data.qvel[self._arm_dof].copy()

    def joint_limits(self) -> np.ndarray:
        """``(7, 2)`` commandable range of each arm joint [rad]."""
        return self._ctrl_range.copy()

    def gripper_opening(self) -> float:
        """How closed the gripper is, 0 (open) .. 1 (closed), from its driver joint."""
        low, high = self._gripper_range
        closed = (float(self._data.qpos[self._gripper_qpos]) - low) / (high - low)
        return min(max(closed, 0.0), 1.0)  # (np.clip of a scalar: ~4 us, read at every control step)

    def tcp_pose_in_base(self) -> np.ndarray:
        """4x4 pose of the TCP (between the finger pads; z along the approach) in the base frame, as the
        arm's nominal kinematics compute it from the encoders [m]."""
        return self._encoders.tcp_pose()

    def ft_rotation_in_base(self) -> np.ndarray:
        """3x3 orientation of the F/T sensor frame in the base frame, as the arm's nominal kinematics
        compute it from the encoders (the same reading as :meth:`tcp_pose_in_base`)."""
        return self._encoders.ft_rotation()

    # -- the wrist F/T sensor ----------------------------------------------------------------------
    def wrench(self) -> np.ndarray:
        """``[Fx, Fy, Fz, Tx, Ty, Tz]`` in the sensor frame [N, N·m], minus the last tare.

        The load on the sensor: what the gripper exerts on the flange. At rest it is the gripper's
        weight (7.37 N, downwards in the base frame); a push ``F`` on the gripper or on what it holds
        adds ``F``. Noise, bias, drift, delay and saturation are the reality profile's.
        """
        return self._ft.read(self.time)

    def tare(self, samples: int = 10) -> None:
        """Zero the wrench on the mean of ``samples`` readings (as a real sensor's bias reset)."""
        self._ft.tare(self.time, samples)

    # -- commands ----------------------------------------------------------------------------------
    def command_joint_positions(self, q: np.ndarray) -> None:
        """Set the 7 arm servo targets [rad]; non-finite or out-of-range targets are refused. They take
        effect after the controller's latency (the reality profile's; none in ``ideal``)."""
        q = np.asarray(q, dtype=float)
        if q.shape != (7,):
            raise CommandError(f"need 7 joint targets, got shape {q.shape}")
        if not np.isfinite(q).all():
            raise CommandError(f"joint targets must be finite, got {q}")
        low, high = self._low, self._high
        if (q < low).any() or (q > high).any():
            outside = np.flatnonzero((q < low) | (q > high))
            low, high = self._ctrl_range[:, 0], self._ctrl_range[:, 1]
            detail = ", ".join(f"joint{i + 1}={q[i]:.3f} not in [{low[i]:.3f}, {high[i]:.3f}]" for i in outside)
            raise CommandError(f"joint targets outside the servo ranges: {detail}")
        self._servos.command_joints(q)

    def command_gripper(self, closure: float) -> None:
        """Gripper target, 0 (open) .. 1 (closed with full force)."""
        if not np.isfinite(closure) or not 0.0 <= closure <= 1.0:
            raise CommandError(f"gripper closure must be in [0, 1], got {closure}")
        self._servos.command_gripper(closure * GRIPPER_CTRL_MAX)

    def wait(self, seconds: float) -> None:
        """Let ``seconds`` of time pass with the current commands [s] (the robot's control period)."""
        self._advance(seconds)

    # -- cameras -----------------------------------------------------------------------------------
    def capture(self, camera: str) -> CameraImage | None:
        """A frame from a named camera (``overview`` or the wrist camera) as the camera delivers it
        (lens distortion and all), or None when the camera dropped the frame."""
        return self._cameras.capture(camera, self.time)


__all__ = ["GRIPPER_CTRL_MAX", "RobotInterface"]
