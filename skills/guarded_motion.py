"""Guarded motion (:class:`GuardedMotion`): the TCP follows a Cartesian path at the control tick through the IK, the
force guard (:class:`skills.force_watch.ForceWatch`) read every tick, and the compliance that lets a path or a grasp
yield to the load across it. It knows nothing of kinds or outcomes.
"""

from __future__ import annotations

import collections.abc
import math

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from puzzlebox.models.robot import Robot
from puzzlebox.skills.errors import ForceLimitExceeded, IKFailure
from puzzlebox.skills.force_watch import ForceWatch
from puzzlebox.skills.kinematics import ArmKinematics
from puzzlebox.skills.settings import PrimitiveConfig


class GuardedMotion:
    """Moves one arm under its force guard (see the module docstring)."""

    def __init__(self, robot: Robot, config: PrimitiveConfig, ik: ArmKinematics, watch: ForceWatch) -> None:
        self.robot, self.config, self.ik, self.watch = robot, config, ik, watch
        self.joint_limits = tuple(robot.joint_limits().T)
        """``(low, high)`` servo ranges [rad]: an arm's are fixed."""

    def clip(self, q: np.ndarray) -> np.ndarray:
        """``q`` within the servo ranges [rad] (``np.clip`` for finite ``q``, without its dispatch layers)."""
        low, high = self.joint_limits
        return np.minimum(np.maximum(q, low), high)

    def wait_tick(self) -> None:
        self.robot.wait(self.config.motion.tick)
        self.watch.sense()

    # -- motion ------------------------------------------------------------------------------------
    def tick(self, target: np.ndarray) -> tuple[float, float]:
        q, position_error, orientation_error = self.ik.step_towards(target, self.config.motion.ik_iterations_per_tick)
        self.robot.command_joint_positions(self.clip(q))
        self.wait_tick()
        return position_error, orientation_error

    def move_to(self, target: np.ndarray, duration: float, smooth: bool = True) -> None:
        """Move the TCP to ``target`` (4x4) along a straight line and a slerp over ``duration`` [s], with a smooth
        start and stop, or at a constant speed (``smooth=False``: no faster than the mean anywhere)."""
        self.ik.set_joints(self.robot.joint_positions())
        start = self.ik.tcp_pose()
        slerp = Slerp([0.0, 1.0], Rotation.from_matrix([start[:3, :3], target[:3, :3]]))
        ticks = max(1, round(duration / self.config.motion.tick))
        s = np.arange(1, ticks + 1) / ticks
        if smooth:
            s = s * s * (3 - 2 * s)
        rotations = slerp(s).as_matrix()  # all at once: one scipy call per tick cost ~0.2 ms
        for k in range(ticks):
            waypoint = np.eye(4)
            waypoint[:3, :3] = rotations[k]
            waypoint[:3, 3] = (1 - s[k]) * start[:3, 3] + s[k] * target[:3, 3]
            self.tick(waypoint)
        for _ in range(round(self.config.motion.settle_time / self.config.motion.tick)):
            position_error, orientation_error = self.tick(target)
            reached = np.linalg.norm(self.robot.tcp_pose_in_base()[:3, 3] - target[:3, 3]) < 0.003
            if reached and position_error < 0.002:
                return
        if position_error > 0.01:
            raise IKFailure(f"TCP target {np.round(target[:3, 3], 3).tolist()} not reached: out of reach")

    def travel_to(self, target: np.ndarray, duration: float) -> None:
        """Reach ``target`` (4x4) from afar through a waypoint ``transit_height`` above the middle of the
        workspace: from the rest posture a straight TCP line to a box near the robot passes by the base
        and folds the arm onto itself (the gripper hit links 1, 4 and 5 at ~200 N). (A joint-space move
        to an IK solution avoided that but reached postures whose forearm then met the box.)"""
        via = target.copy()
        via[:3, 3] = (*self.config.motion.transit_xy, max(target[2, 3], self.config.motion.transit_height))
        self.move_to(via, 0.5 * duration)
        self.move_to(target, duration)

    def joint_move(self, q_goal: np.ndarray, duration: float) -> None:
        """Interpolate the joints to ``q_goal`` [rad] over ``duration`` [s] (no IK: always feasible)."""
        start = self.robot.joint_positions()
        ticks = max(1, round(duration / self.config.motion.tick))
        for k in range(1, ticks + 1):
            s = k / ticks
            s = s * s * (3 - 2 * s)
            self.robot.command_joint_positions(self.clip((1 - s) * start + s * q_goal))
            self.wait_tick()

    def close_slowly(self, settle: bool = False) -> np.ndarray:
        """Ramp the gripper command from its pre-grasp closure to fully closed at ``close_speed``, then
        hold for ``close_time`` while the grip builds, the wrist yielding along the closing axis to a load there
        (``grasp_centre_force``) and, with ``settle``, once closed, across it too (``comply_deadband``). Returns how
        far it yielded [m, base frame]: where the handle was found to be beside where it was aimed."""
        c = self.config
        ramp = max(
            1, round((1.0 - c.approach.pregrasp_closure) / c.grasp.close_speed * self.watch.slowdown / c.motion.tick)
        )
        hold = self.ik.tcp_pose()
        axis = hold[:3, 1].copy()  # the fingers close along the TCP's y axis (skills.kinematics.top_down)
        shift = 0.0
        # once closed on a handle the pads push along its motion (a slide's, a wheel's, a drawer's), the hand also
        # yields across the closing axis, as a door's path does (:meth:`yield_across`): a handle gripped a few
        # millimetres from where it was aimed (an uncalibrated camera) loads the stiff arm across the fingers —
        # 15-18 N on a free wheel, 28 N as it turned about the aimed point, read as held part-way at 29 % — and
        # the hand settles on the handle before it pulls. A post that pivots between the pads (a door's, a lever's)
        # keeps the grasp it had: settled, the doors' replayed loads fitted a friction 31 % below the nominal
        # model's on ideal-world logs (tests/twin/test_system_id.py); a door's path yields as it moves
        settled = np.zeros(3)
        for k in range(1, ramp + round(c.grasp.close_time / c.motion.tick) + 1):
            if k <= ramp:
                self.robot.command_gripper(c.approach.pregrasp_closure + (1.0 - c.approach.pregrasp_closure) * k / ramp)
            elif settle:
                settled = self.yield_across(settled, axis)
            shift = self.centring(shift, axis)
            if shift == 0.0 and not settled.any():  # (the aimed pose itself, to the bit, while nothing pushes)
                self.tick(hold)
            else:
                shifted = hold.copy()
                shifted[:3, 3] += shift * axis + settled
                self.tick(shifted)
        return shift * axis + settled

    def centring(self, shift: float, axis: np.ndarray) -> float:
        """The hand's offset ``shift`` [m] along the closing ``axis`` (unit, base frame) moved along the filtered
        load on that axis above ``grasp_centre_force`` (or the noise margin), at ``comply_gain``, within
        ``grasp_centre_limit``."""
        c = self.config
        load = float(self.watch.force_in_base @ axis)
        deadband = max(c.grasp.grasp_centre_force, c.motion.comply_noise_margin * self.watch.rest_noise)
        if abs(load) <= deadband:
            return shift
        shift += c.motion.comply_gain * c.motion.tick * math.copysign(abs(load) - deadband, load)
        return max(-c.grasp.grasp_centre_limit, min(c.grasp.grasp_centre_limit, shift))

    def take_back(self, motion: collections.abc.Callable[[], None]) -> None:
        """Run ``motion``, a held handle's way back to where it was grasped, under ``back_off_force``: stopped there,
        the arm backs off along the load (:meth:`relieve`) and sets out once more; stopped again, it stays backed
        off (the try's verdict stands). The load of the hold still rises for a few ticks after it is read (the
        filter's lag): a wheel held at 35-40 N had its way back stopped on the second tick and was left at 27 % of
        its travel, where its next try began with the hand believing it closed (it met its stop at 73 % of the way
        and read held part-way)."""
        limit = self.watch.limit
        self.watch.limit = min(limit, self.config.actuation.back_off_force)
        try:
            for _ in range(2):  # (once more after backing off)
                try:
                    motion()
                    return
                except ForceLimitExceeded:
                    self.watch.guard = False
                    try:
                        self.relieve()
                    finally:
                        self.watch.guard = True
        finally:
            self.watch.limit = limit

    def yield_across(
        self, across: np.ndarray, direction: np.ndarray, held_along: np.ndarray | None = None, share: float = 1.0
    ) -> np.ndarray:
        """The path's offset ``across`` [m] moved along the filtered force's component across the direction of
        motion ``direction`` (unit, base frame), at ``comply_gain`` per newton above a deadband
        (``comply_deadband``, ``comply_noise_margin``), within ``comply_limit``: a path planned from a slightly
        wrong hinge pulls the handle across its true arc, which the part resists with no motion, and only the
        load along the motion tells a latch. ``held_along``: a unit axis along which only ``share`` of the load is
        yielded to (``Handling.axis_yield``)."""
        c = self.config
        force = self.watch.force_in_base
        load = force - float(force @ direction) * direction
        if held_along is not None:  # only in part along this (unit) axis, where the part holds the handle in the pads
            load = load - (1.0 - share) * float(load @ held_along) * held_along
        size = math.sqrt(load @ load)
        deadband = max(c.motion.comply_deadband, c.motion.comply_noise_margin * self.watch.rest_noise)
        if size <= deadband:
            return across
        across = across + (c.motion.comply_gain * c.motion.tick * (size - deadband) / size) * load
        length = math.sqrt(across @ across)
        return across if length <= c.motion.comply_limit else across * (c.motion.comply_limit / length)

    def relieve(self) -> None:
        """Move up to ``relieve_distance`` along the load, stopping once the load along that way has fallen
        below ``relieve_load``: with the fingers still closed on a handle that jammed, the whole 5 mm carried the
        arm past where the load vanished and pushed the handle the other way (70 N, then 148 N, reversed)."""
        c = self.config
        load = math.sqrt(self.watch.force_in_base @ self.watch.force_in_base)
        if load <= c.motion.relieve_load:
            return
        along = self.watch.force_in_base / load
        start = self.robot.tcp_pose_in_base()
        self.ik.set_joints(self.robot.joint_positions())
        ticks = max(1, round(c.motion.release_time / c.motion.tick))
        for k in range(1, ticks + 1):
            s = k / ticks
            target = start.copy()
            target[:3, 3] += c.motion.relieve_distance * s * s * (3 - 2 * s) * along
            self.tick(target)
            if float(self.watch.force_in_base @ along) < c.motion.relieve_load:
                return


__all__ = ["GuardedMotion"]
