"""The robot interface: what a real xArm-7 driver, its wrist F/T sensor and the cell's cameras give.

Skills talk to the twin only through this class: camera images with intrinsics and calibrated
extrinsics, arm joint positions and velocities, the gripper opening, the wrist wrench, the TCP and
sensor poses the arm's own kinematics report, and joint-position and gripper commands. It exposes no
simulator ground truth (no box joint, no latch, no component state), so a pipeline that works here
has nothing a real cell would not give it.

Frames: the robot base frame is the world frame of the twin. Wrenches are in the F/T sensor frame
(``ft_site``), as a real sensor reports them; :meth:`RobotInterface.ft_rotation_in_base` turns them
into the base frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from twin.errors import CommandError
from twin.rendering import RenderConfig, Renderer

if TYPE_CHECKING:
    from twin.session import TwinSession

GRIPPER_CTRL_MAX = 255.0
"""The xArm gripper's command range is 0 (open) .. 255 (closed)."""


@dataclass(frozen=True)
class CameraImage:
    """One camera frame with everything needed to turn pixels into base-frame geometry.

    Attributes:
        camera: camera name.
        rgb: ``(H, W, 3)`` uint8 image.
        K: 3x3 pinhole intrinsics [px] (OpenCV convention).
        T_base_camera: 4x4 pose of the OpenCV camera frame (x right, y down, z forward) in the base frame.
        time: simulated time of capture [s].
    """

    camera: str
    rgb: np.ndarray
    K: np.ndarray
    T_base_camera: np.ndarray
    time: float


class RobotInterface:
    """See the module docstring. Obtain it from :attr:`TwinSession.robot`."""

    def __init__(self, session: TwinSession, render: RenderConfig | None = None) -> None:
        self._session = session
        self._render_config = render or RenderConfig()
        self._renderer: Renderer | None = None
        names = session.scene.names
        m = session.model
        self.camera_names = (names.overview_camera, names.wrist_camera)
        self._tcp = m.site(names.tcp_site).id
        self._ft = m.site(names.ft_site).id
        self._force = m.sensor(names.wrist_force).adr[0]
        self._torque = m.sensor(names.wrist_torque).adr[0]
        self._ctrl_range = m.actuator_ctrlrange[session.arm_actuators].copy()
        driver = m.joint(names.gripper_actuator.replace("fingers", "right_driver_joint"))
        self._gripper_qpos, self._gripper_range = driver.qposadr[0], driver.range.copy()

    # -- proprioception ----------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return self._session.time

    def joint_positions(self) -> np.ndarray:
        """Arm joint positions [rad], joints 1..7."""
        return self._session.data.qpos[self._session.arm_qpos].copy()

    def joint_velocities(self) -> np.ndarray:
        """Arm joint velocities [rad/s], joints 1..7."""
        return self._session.data.qvel[self._session.arm_dof].copy()

    def joint_limits(self) -> np.ndarray:
        """``(7, 2)`` commandable range of each arm joint [rad]."""
        return self._ctrl_range.copy()

    def gripper_opening(self) -> float:
        """How closed the gripper is, 0 (open) .. 1 (closed), from its driver joint."""
        low, high = self._gripper_range
        return float(np.clip((self._session.data.qpos[self._gripper_qpos] - low) / (high - low), 0.0, 1.0))

    def tcp_pose_in_base(self) -> np.ndarray:
        """4x4 pose of the TCP (between the finger pads; z along the approach) in the base frame."""
        return self._pose(self._session.data.site_xpos[self._tcp], self._session.data.site_xmat[self._tcp])

    def ft_rotation_in_base(self) -> np.ndarray:
        """3x3 orientation of the F/T sensor frame in the base frame."""
        return self._session.data.site_xmat[self._ft].reshape(3, 3).copy()

    @staticmethod
    def _pose(pos: np.ndarray, xmat: np.ndarray) -> np.ndarray:
        T = np.eye(4)
        T[:3, :3] = xmat.reshape(3, 3)
        T[:3, 3] = pos
        return T

    # -- the wrist F/T sensor ----------------------------------------------------------------------
    def wrench(self) -> np.ndarray:
        """``[Fx, Fy, Fz, Tx, Ty, Tz]`` in the sensor frame [N, N·m], minus the tare, with sensor noise.

        The load on the sensor: what the gripper exerts on the flange. At rest it is the gripper's
        weight (7.37 N, downwards in the base frame); a push ``F`` on the gripper or on what it holds
        adds ``F``. (MuJoCo's force sensor reports the opposite, the arm's support of the gripper.)
        """
        s = self._session
        raw = -np.concatenate(
            [s.data.sensordata[self._force : self._force + 3], s.data.sensordata[self._torque : self._torque + 3]]
        )
        noise = np.concatenate(
            [
                s.rng.normal(0.0, s.config.force_noise_std, 3),
                s.rng.normal(0.0, s.config.torque_noise_std, 3),
            ]
        )
        return raw + noise - s.wrench_offset

    def tare(self, samples: int = 10) -> None:
        """Zero the wrench on the mean of ``samples`` readings (as a real sensor's bias reset)."""
        s = self._session
        s.wrench_offset = np.zeros(6)
        s.wrench_offset = np.mean([self.wrench() for _ in range(samples)], axis=0)

    # -- commands ----------------------------------------------------------------------------------
    def command_joint_positions(self, q: np.ndarray) -> None:
        """Set the 7 arm servo targets [rad]; non-finite or out-of-range targets are refused."""
        q = np.asarray(q, dtype=float)
        if q.shape != (7,):
            raise CommandError(f"need 7 joint targets, got shape {q.shape}")
        if not np.all(np.isfinite(q)):
            raise CommandError(f"joint targets must be finite, got {q}")
        low, high = self._ctrl_range[:, 0], self._ctrl_range[:, 1]
        outside = np.flatnonzero((q < low - 1e-9) | (q > high + 1e-9))
        if outside.size:
            detail = ", ".join(f"joint{i + 1}={q[i]:.3f} not in [{low[i]:.3f}, {high[i]:.3f}]" for i in outside)
            raise CommandError(f"joint targets outside the servo ranges: {detail}")
        self._session.data.ctrl[self._session.arm_actuators] = q

    def command_gripper(self, closure: float) -> None:
        """Gripper target, 0 (open) .. 1 (closed with full force)."""
        if not np.isfinite(closure) or not 0.0 <= closure <= 1.0:
            raise CommandError(f"gripper closure must be in [0, 1], got {closure}")
        self._session.data.ctrl[self._session.gripper_actuator] = closure * GRIPPER_CTRL_MAX

    def wait(self, seconds: float) -> None:
        """Let ``seconds`` of time pass with the current commands [s] (the robot's control period)."""
        self._session.advance(seconds)

    # -- cameras -----------------------------------------------------------------------------------
    def capture(self, camera: str) -> CameraImage:
        """A frame from a named camera (``overview`` or the wrist camera) with its calibration."""
        if self._renderer is None:
            self._renderer = Renderer(self._session.model, self._render_config)
        data = self._session.data
        return CameraImage(
            camera=camera,
            rgb=self._renderer.render(data, camera),
            K=self._renderer.camera_intrinsics(camera),
            T_base_camera=self._renderer.camera_pose_in_world(data, camera),
            time=self.time,
        )

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


__all__ = ["GRIPPER_CTRL_MAX", "CameraImage", "RobotInterface"]
