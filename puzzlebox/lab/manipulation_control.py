"""The arm as ``puzzlebox/BoxManipulation-v0`` drives it: end-effector deltas at a fixed control rate.

An action is ``[dx, dy, dz, dyaw, grip]`` in ``[-1, 1]`` (``[dx, dy, dz, grip]`` without yaw control), float32:

- ``dx, dy, dz`` move the TCP target by up to :attr:`ControlLimits.max_translation` per step along the base frame's
  axes [m]; the target stays inside the cell's workspace box (its cell config's ``workspace_min`` /
  ``workspace_max``) and within :attr:`ControlLimits.max_lead` of the TCP the arm reports, so a part or the lid
  that stops the hand does not let the target run away;
- ``dyaw`` turns the gripper about the vertical by up to :attr:`ControlLimits.max_yaw` per step [rad], within
  :attr:`ControlLimits.yaw_span` of the start; the gripper always points straight down (``skills.kinematics.top_down``);
- ``grip`` is the gripper closure asked for, ``-1`` open .. ``1`` closed, reached at most at
  :attr:`ControlLimits.gripper_speed` (pads snapped onto a post put a 60 N impact on the wrist).

Each step the target goes through one differential-IK step from the posture commanded last, on the skills'
robot-only arm model (:mod:`puzzlebox.lab.manipulation_ik`), and the joints it gives are sent to the position servos
through the twin's robot interface; the twin then runs :data:`CONTROL_PERIOD` of physics.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from gymnasium import spaces

from puzzlebox.lab.manipulation_ik import DifferentialIK
from puzzlebox.models.robot import Robot

CONTROL_HZ = 20
"""Control rate [Hz]: one action every 50 ms, 25 physics steps of 2 ms."""
CONTROL_PERIOD = 1.0 / CONTROL_HZ
"""Time between two actions [s]."""
READY_QPOS = (0.0, -0.247, 0.0, 0.909, 0.0, 1.156, 0.0)
"""Arm posture at reset [rad]: Menagerie's home, the TCP pointing straight down 0.228 m over (0.40, 0) m with
the fingers closing along the base's y axis (yaw pi), over the middle of the workspace; the IK pulls the arm's
redundancy towards it."""


@dataclass(frozen=True)
class ControlLimits:
    """Safe limits of one control step."""

    max_translation: float = 0.01
    """Largest TCP target move per step along each axis [m] (0.2 m/s at 20 Hz)."""
    max_yaw: float = 0.1
    """Largest gripper turn per step [rad] (2 rad/s)."""
    yaw_span: float = math.pi
    """How far the gripper may turn either way from its start [rad] (joint 7 turns 2 pi either way)."""
    max_lead: float = 0.03
    """Farthest the TCP target may be from the TCP the arm reports [m]: what stops the hand meets at most the
    servos' pull over this distance."""
    gripper_speed: float = 1.0
    """Fastest change of the commanded gripper closure [1/s] (the servo alone snaps shut at ~2/s)."""

    def __post_init__(self) -> None:
        for name in ("max_translation", "max_yaw", "yaw_span", "max_lead", "gripper_speed"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"ControlLimits.{name} must be finite and > 0, got {value!r}")


def action_space(control_yaw: bool) -> spaces.Box:
    """``[dx, dy, dz, dyaw, grip]`` (``[dx, dy, dz, grip]`` without ``control_yaw``) in ``[-1, 1]``."""
    return spaces.Box(-1.0, 1.0, shape=(5 if control_yaw else 4,), dtype=np.float32)


class ArmController:
    """Turns actions into joint and gripper commands (see the module docstring); one per environment. The few numbers
    of a step are Python floats, not numpy arrays: a numpy call on a 3-vector costs a hundred times its arithmetic."""

    def __init__(self, limits: ControlLimits, control_yaw: bool) -> None:
        self.limits, self.control_yaw = limits, control_yaw
        self.ik = DifferentialIK(READY_QPOS)
        self.target = [0.0, 0.0, 0.0]
        """The TCP target [m], base frame."""
        self.yaw = 0.0
        """The gripper's target yaw [rad]."""
        self.closure = 0.0
        """The commanded gripper closure, 0 (open) .. 1 (closed)."""
        self._box: list[tuple[float, float]] = []
        self._yaw_range = (0.0, 0.0)

    def reset(self, robot: Robot, workspace: tuple[Sequence[float], Sequence[float]]) -> None:
        """Start from where the arm is (the IK from its encoders, the target at its reported TCP), the gripper as
        commanded open; ``workspace`` is the box (low, high corners [m]) the target stays in."""
        self._box = [(float(low), float(high)) for low, high in zip(*workspace, strict=True)]
        T = self.ik.reset(robot.joint_positions(), robot.joint_limits())  # the IK keeps to the servos' ranges
        self.target = [min(max(float(v), low), high) for v, (low, high) in zip(T[:3, 3], self._box, strict=True)]
        self.yaw = math.atan2(T[1, 0], T[0, 0])
        self._yaw_range = (self.yaw - self.limits.yaw_span, self.yaw + self.limits.yaw_span)
        self.closure = 0.0

    def apply(self, action: Sequence[float], robot: Robot, tcp: Sequence[float]) -> None:
        """Send the commands of one action (already within ``[-1, 1]``) to ``robot``: one IK step, joints and gripper;
        ``tcp`` is the TCP position the arm reports now [m] (as last observed)."""
        c = self.limits
        moved = (t + c.max_translation * a for t, a in zip(self.target, action[:3], strict=True))
        target = [min(max(v, low), high) for v, (low, high) in zip(moved, self._box, strict=True)]
        lead = [t - p for t, p in zip(target, tcp, strict=True)]
        distance = math.sqrt(sum(v * v for v in lead))
        if distance > c.max_lead:  # back towards the hand, to max_lead from it
            keep = c.max_lead / distance
            target = [p + keep * v for p, v in zip(tcp, lead, strict=True)]
        self.target = target
        if self.control_yaw:
            self.yaw = min(max(self.yaw + c.max_yaw * action[3], self._yaw_range[0]), self._yaw_range[1])
        robot.command_joint_positions(self.ik.step(target, self.yaw))
        step = c.gripper_speed * CONTROL_PERIOD
        self.closure = min(max(0.5 * (action[-1] + 1.0), self.closure - step), self.closure + step)
        robot.command_gripper(self.closure)


__all__ = ["CONTROL_HZ", "CONTROL_PERIOD", "READY_QPOS", "ArmController", "ControlLimits", "action_space"]
