"""Record every toggle a world makes as robot data (:class:`models.toggle_log.ToggleLog`): the data a system
identification of the box fits the twin to.

:class:`ToggleRecorder` stands between the robot and the pipeline (it satisfies :class:`models.robot.Robot`,
passing every call through) and follows a :class:`~skills.robot_world.RobotWorld`'s toggle primitive from the
outside (:meth:`ToggleRecorder.attach` wraps the world's ``toggler.toggle`` on the instance). While a toggle runs,
every wrench the primitive reads (once per 10 ms control tick) is logged with what the robot reports at that
instant — joint positions, gripper closure, TCP pose, the F/T sensor's orientation (which turns the wrench into
the base frame) — the last joint and gripper commands sent, and the primitive's phase. It reads nothing the
pipeline could not (no simulator state) and draws no extra sensor reading: the wrench logged is the one the
primitive got, and a reading of the joints at an instant already read is the same reading (a real driver
reports one state per cycle), so a recorded trial senses and does exactly what an unrecorded one does.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from puzzlebox.models.robot import Robot
from puzzlebox.models.toggle_log import PHASES, ToggleLog
from puzzlebox.skills.joint_model import JointModel
from puzzlebox.skills.perception import upright_pose
from puzzlebox.skills.toggle_result import ToggleResult


class _Ticks:
    """The per-tick rows of the toggle in progress."""

    def __init__(self) -> None:
        self.time: list[float] = []
        self.joints: list[np.ndarray] = []
        self.closure: list[float] = []
        self.tcp: list[np.ndarray] = []
        self.force: list[np.ndarray] = []
        self.torque: list[np.ndarray] = []
        self.joint_command: list[np.ndarray] = []
        self.gripper_command: list[float] = []
        self.phase: list[int] = []


class ToggleRecorder:
    """See the module docstring. ``robot`` is the robot the pipeline would use (a :class:`models.robot.Robot`);
    ``context`` is copied into every toggle's log (e.g. the box's name and the trial's seed)."""

    def __init__(self, robot: Robot, context: dict[str, Any] | None = None) -> None:
        self._robot = robot
        self.context = dict(context or {})
        self.toggles: list[ToggleLog] = []
        """Every finished toggle, in order."""
        self._ticks: _Ticks | None = None
        self._phase = lambda: "moving"
        self._joint_command = np.full(7, np.nan)
        self._gripper_command = float("nan")

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)

    def command_joint_positions(self, q: np.ndarray) -> None:
        self._robot.command_joint_positions(q)
        self._joint_command = np.array(q, dtype=float)  # after the robot took it: a refused command is not sent

    def command_gripper(self, closure: float) -> None:
        self._robot.command_gripper(closure)
        self._gripper_command = float(closure)

    def wrench(self) -> np.ndarray:
        w = self._robot.wrench()
        ticks = self._ticks
        if ticks is not None:
            r = self._robot
            R = r.ft_rotation_in_base()
            ticks.time.append(r.time)
            ticks.joints.append(r.joint_positions())
            ticks.closure.append(r.gripper_opening())
            ticks.tcp.append(r.tcp_pose_in_base())
            ticks.force.append(R @ w[:3])
            ticks.torque.append(R @ w[3:])
            ticks.joint_command.append(self._joint_command)
            ticks.gripper_command.append(self._gripper_command)
            phase = self._phase()
            ticks.phase.append(PHASES.index(phase) if phase in PHASES else 0)
        return w

    def attach(self, world: Any) -> None:
        """Follow ``world``'s toggles (a :class:`~skills.robot_world.RobotWorld` built on this recorder): its
        toggler's ``toggle`` is wrapped on the instance, the primitive itself untouched."""
        toggler = world.toggler
        if toggler.robot is not self:
            raise ValueError("the world's robot is not this recorder: build the world on it")
        self._phase = lambda: toggler.phase
        original = toggler.toggle

        @functools.wraps(original)
        def toggle(jm: JointModel, opening: bool = True, *args: Any, **kwargs: Any) -> ToggleResult:
            self._ticks = _Ticks()
            try:
                result = original(jm, opening, *args, **kwargs)
            finally:
                ticks, self._ticks = self._ticks, None
            self.toggles.append(self._log(world, jm, opening, result, ticks))
            return result

        toggler.toggle = toggle

    def _log(self, world: Any, jm: JointModel, opening: bool, result: ToggleResult, ticks: _Ticks) -> ToggleLog:
        marker = next((m for m, model in world.joint_models.items() if model is jm), -1)
        names = getattr(world, "names", None) or {}
        pose = upright_pose(world.closed_poses[marker], world.lid_height) if marker in world.closed_poses else np.eye(4)
        n = len(ticks.time)
        return ToggleLog(
            component=names.get(marker, f"marker-{marker}"), marker=int(marker), kind=jm.kind, joint=jm.joint,
            axis=np.array(jm.axis, dtype=float), origin=np.array(jm.origin, dtype=float),
            grasp_point=np.array(jm.grasp_point, dtype=float), pose=np.array(pose, dtype=float),
            travel=float(jm.travel), opening=bool(opening),
            outcome=result.outcome, reason=result.reason, progress=float(result.progress),
            time=np.array(ticks.time, dtype=float), joints=np.array(ticks.joints, dtype=float).reshape(n, 7),
            closure=np.array(ticks.closure, dtype=float), tcp=np.array(ticks.tcp, dtype=float).reshape(n, 4, 4),
            force=np.array(ticks.force, dtype=float).reshape(n, 3),
            torque=np.array(ticks.torque, dtype=float).reshape(n, 3),
            joint_command=np.array(ticks.joint_command, dtype=float).reshape(n, 7),
            gripper_command=np.array(ticks.gripper_command, dtype=float),
            phase=np.array(ticks.phase, dtype=np.int64), context={**self.context, "action": len(world.log) + 1},
        )  # fmt: skip


__all__ = ["ToggleRecorder"]
