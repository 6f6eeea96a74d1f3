"""The ``Robot`` protocol: exactly what the robot's pipeline (``skills``) uses of an arm and its cell.

The twin's robot interface implements it; a real xArm-7 driver implements it too (DESIGN.md, "Layers").
Nothing here is simulator ground truth: images come without intrinsics or extrinsics (those are what
*calibration* produced, :mod:`models.calibration`), joint positions are what the encoders read, the TCP
pose is what the arm's own kinematics report from them, and the wrench is what the wrist sensor gives.

Frames: the robot base frame is the world frame. Wrenches are in the F/T sensor frame, as a real
sensor reports them; :meth:`Robot.ft_rotation_in_base` turns them into the base frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np


@dataclass(frozen=True)
class CameraImage:
    """One camera frame as a camera driver delivers it.

    Attributes:
        camera: camera name (a key of the cell's calibration).
        rgb: ``(H, W, 3)`` uint8 image, as the sensor gave it (lens distortion and all).
        time: robot time of capture [s].
    """

    camera: str
    rgb: np.ndarray
    time: float


@runtime_checkable
class Robot(Protocol):
    """An arm with a gripper, a wrist F/T sensor and cameras (see the module docstring)."""

    camera_names: tuple[str, ...]
    """Cameras :meth:`capture` accepts."""

    @property
    def time(self) -> float:
        """Robot time [s] (simulated time in the twin)."""
        ...

    def joint_positions(self) -> np.ndarray:
        """Arm joint positions as the encoders read them [rad], joints 1..7."""
        ...

    def joint_velocities(self) -> np.ndarray:
        """Arm joint velocities [rad/s], joints 1..7."""
        ...

    def joint_limits(self) -> np.ndarray:
        """``(7, 2)`` commandable range of each arm joint [rad]."""
        ...

    def gripper_opening(self) -> float:
        """How closed the gripper is, 0 (open) .. 1 (closed), from its position feedback."""
        ...

    def tcp_pose_in_base(self) -> np.ndarray:
        """4x4 pose of the TCP (between the finger pads, z along the approach) in the base frame, as
        the arm's kinematics report it from the encoders [m]."""
        ...

    def ft_rotation_in_base(self) -> np.ndarray:
        """3x3 orientation of the F/T sensor frame in the base frame."""
        ...

    def wrench(self) -> np.ndarray:
        """``[Fx, Fy, Fz, Tx, Ty, Tz]`` in the sensor frame [N, N·m], minus the last tare: the load the
        gripper puts on the flange."""
        ...

    def tare(self, samples: int = 10) -> None:
        """Zero the wrench on the mean of ``samples`` readings (the sensor's bias reset)."""
        ...

    def command_joint_positions(self, q: np.ndarray) -> None:
        """Set the 7 arm servo targets [rad]; non-finite or out-of-range targets are refused."""
        ...

    def command_gripper(self, closure: float) -> None:
        """Gripper target, 0 (open) .. 1 (closed with full force)."""
        ...

    def wait(self, seconds: float) -> None:
        """Let ``seconds`` of robot time pass with the current commands [s]."""
        ...

    def capture(self, camera: str) -> CameraImage | None:
        """A frame from a named camera, or None when the camera delivered no frame (a dropped frame)."""
        ...


__all__ = ["CameraImage", "Robot"]
