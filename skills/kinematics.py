"""Differential inverse kinematics of the xArm-7 with mink, on a robot-only model.

The IK model is the robot alone (``models.xarm7``), as a real controller's URDF is: IK never sees,
let alone moves, the box. Tasks: a FrameTask on the TCP site, a PostureTask (cost 1e-2) that keeps
the redundant arm near a comfortable posture, joint limits; solved with daqp (DESIGN.md: 0.1-0.3 ms
per iteration, ~6-13 iterations to 1 mm); each iteration's QP is built and solved by
:class:`skills.ik_qp.VelocityQP`, mink's ``solve_ik`` for this one problem at a fraction of its cost. mink
neither flags an unreachable target (it stalls) nor rejects a NaN target (it returns NaN velocities), so both
are checked here and become :class:`~skills.errors.IKFailure` — no NaN ever reaches a joint command.
"""

from __future__ import annotations

import copy
import functools
import math
from dataclasses import dataclass

import mink
import mujoco
import numpy as np
from dm_control import mjcf

from puzzlebox.models.xarm7 import ARM_JOINTS, build_xarm7
from puzzlebox.skills.errors import IKFailure
from puzzlebox.skills.ik_qp import VelocityQP

TCP_SITE = "gripper/tcp"


@dataclass(frozen=True)
class IKConfig:
    """Solver settings."""

    dt: float = 0.01
    """Integration step of one IK iteration [s] (one control tick)."""
    position_cost: float = 1.0
    orientation_cost: float = 0.5
    posture_cost: float = 1e-3
    """Pull towards a relaxed posture: 1e-2 left a 2 mm steady-state error here; much weaker lets the
    redundant arm drift into folded postures over successive motions."""
    damping: float = 1e-3
    """Levenberg-Marquardt damping of the QP, for smooth motion near singularities."""
    position_tolerance: float = 0.001
    """Converged when the TCP is this close to the target [m]..."""
    orientation_tolerance: float = 0.01
    """... and this close in orientation [rad]."""
    max_iterations: int = 300
    """Iterations allowed to converge before the target is declared unreachable."""
    settled_position: float = 5e-5
    """:meth:`ArmKinematics.step_towards` runs no further iteration once the TCP is this close to its target
    [m]... (a control tick's target moves ~1 mm: one iteration leaves 0.015 mm in the median, 0.06 mm at the
    90th percentile, and a second one left 0.013 mm, the posture task's pull — twice the IK for nothing)"""
    settled_orientation: float = 5e-4
    """... and this close in orientation [rad] (one iteration: 7e-5 rad at the 90th percentile)."""


@functools.cache
def _robot_model() -> mujoco.MjModel:
    """The robot-only IK model, built once per process (it never changes). Callers get copies: nothing one
    kinematics does to its model reaches another.

    Without geoms or meshes: IK needs the kinematic tree alone, every xArm body states its inertia, and
    compiling the meshes was 0.15-0.3 s of the model's 0.2-0.4 s (site poses and Jacobians are bit for bit
    those of the model with them)."""
    root = mjcf.RootElement(model="ik")
    root.attach(build_xarm7())
    for element in (*root.find_all("geom"), *root.find_all("mesh")):
        element.remove()
    return mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())


class ArmKinematics:
    """IK for the arm joints (the gripper's joints are not moved)."""

    def __init__(self, config: IKConfig | None = None) -> None:
        self.config = config or IKConfig()
        self.model = copy.deepcopy(_robot_model())
        self.arm_qpos = np.array([self.model.joint(f"xarm7/{j}").qposadr[0] for j in ARM_JOINTS])
        self.configuration = mink.Configuration(self.model)
        self.tcp = mink.FrameTask(
            f"xarm7/{TCP_SITE}", "site", position_cost=self.config.position_cost,
            orientation_cost=self.config.orientation_cost, lm_damping=1.0,
        )  # fmt: skip
        self.posture = mink.PostureTask(self.model, cost=self.config.posture_cost)
        rest = self.model.qpos0.copy()
        rest[self.arm_qpos] = (0.0, -0.247, 0.0, 0.909, 0.0, 1.156, 0.0)  # Menagerie home: a relaxed posture
        self.posture.set_target(rest)
        self.limits = [mink.ConfigurationLimit(self.model)]
        self._qp = VelocityQP(self.configuration, self.tcp, self.posture, self.limits[0], self.config.damping)

    def set_joints(self, q_arm: np.ndarray) -> None:
        q = self.configuration.q.copy()
        q[self.arm_qpos] = q_arm
        self.configuration.update(q)

    @property
    def joints(self) -> np.ndarray:
        return self.configuration.data.qpos[self.arm_qpos]  # fancy indexing: a copy

    def tcp_pose(self) -> np.ndarray:
        """4x4 TCP pose in the base frame for the current IK joints."""
        return self.configuration.get_transform_frame_to_world(f"xarm7/{TCP_SITE}", "site").as_matrix()

    def step_towards(self, T_base_tcp: np.ndarray, iterations: int = 1) -> tuple[np.ndarray, float, float]:
        """Run up to ``iterations`` IK iterations towards a target, none once the TCP is within
        ``settled_position`` and ``settled_orientation`` of it (a target held still, as while the gripper
        closes, costs no IK); returns the arm joints and the position [m] and orientation [rad] errors left."""
        if not np.isfinite(T_base_tcp).all():
            raise IKFailure(f"IK target is not finite: {T_base_tcp}")
        self.tcp.set_target(se3(T_base_tcp))
        c = self.config
        position_error, orientation_error = self._errors()
        for _ in range(iterations):
            if position_error < c.settled_position and orientation_error < c.settled_orientation:
                break
            velocity = self._qp.velocity(c.dt)
            if not np.isfinite(velocity).all():
                raise IKFailure("IK returned non-finite joint velocities")
            self._integrate(velocity, c.dt)
            position_error, orientation_error = self._errors()
        return self.joints, position_error, orientation_error

    def _integrate(self, velocity: np.ndarray, dt: float) -> None:
        """``configuration.integrate_inplace`` without its equality-constraint pass (no task here uses one):
        the joints moved, their frames and Jacobian terms updated."""
        m, d = self.model, self.configuration.data
        mujoco.mj_integratePos(m, d.qpos, velocity, dt)
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)

    def _errors(self) -> tuple[float, float]:
        """Position [m] and orientation [rad] error of the TCP from the target."""
        error = self.tcp.compute_error(self.configuration)
        position, orientation = error[:3], error[3:]
        return math.sqrt(position @ position), math.sqrt(orientation @ orientation)  # np.linalg.norm, bit for bit

    def solve(self, T_base_tcp: np.ndarray, q_seed: np.ndarray | None = None) -> np.ndarray:
        """Arm joints that put the TCP at ``T_base_tcp``; :class:`IKFailure` if it stays out of reach."""
        if q_seed is not None:
            self.set_joints(q_seed)
        position_error = orientation_error = np.inf
        for _ in range(self.config.max_iterations):
            q, position_error, orientation_error = self.step_towards(T_base_tcp)
            if (
                position_error < self.config.position_tolerance
                and orientation_error < self.config.orientation_tolerance
            ):
                return q
        raise IKFailure(
            f"IK stalled {position_error * 1000:.1f} mm / {np.degrees(orientation_error):.1f} deg from the target "
            f"at {np.round(T_base_tcp[:3, 3], 3).tolist()} after {self.config.max_iterations} iterations: out of reach"
        )


def se3(T: np.ndarray) -> mink.SE3:
    """``mink.SE3.from_matrix(T)`` (the same quaternion, from ``mju_mat2Quat``) without its Python layers."""
    wxyz_xyz = np.empty(7)
    mujoco.mju_mat2Quat(wxyz_xyz[:4], np.ascontiguousarray(T[:3, :3], dtype=np.float64).ravel())
    wxyz_xyz[4:] = T[:3, 3]
    return mink.SE3(wxyz_xyz=wxyz_xyz)


def top_down(position: np.ndarray, yaw: float) -> np.ndarray:
    """TCP pose at ``position`` [m] pointing straight down (approach axis -z), fingers closing along the
    horizontal direction ``yaw`` + 90 deg (the gripper's y axis) [rad]."""
    c, s = np.cos(yaw), np.sin(yaw)
    R = np.array([[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]])  # x = (c, s, 0), z = down, y = z cross x
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = position
    return T


__all__ = ["ArmKinematics", "IKConfig", "se3", "top_down"]
