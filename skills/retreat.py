"""The retreat (:class:`Retreat`): after a try, or a stop, let go of the handle gently, lift clear of the part and
what stands over it, and go back to the rest posture (out of the overview camera's view), by guarded motions.
"""

from __future__ import annotations

import math

import numpy as np

from puzzlebox.skills.errors import ForceLimitExceeded, IKFailure
from puzzlebox.skills.guarded_motion import GuardedMotion


def out_to_radius(pose: np.ndarray, radius: float) -> None:
    """Move ``pose`` (4x4, base frame; in place) out horizontally from the base's vertical axis to ``radius`` [m] if
    it stands closer (and not on the axis itself)."""
    now = math.hypot(pose[0, 3], pose[1, 3])
    if 1e-6 <= now < radius:
        pose[:2, 3] *= radius / now


class Retreat:
    """Lets go and leaves (see the module docstring)."""

    def __init__(self, motion: GuardedMotion, rest_posture: np.ndarray) -> None:
        self.motion, self.watch = motion, motion.watch
        self.robot, self.config, self.ik = motion.robot, motion.config, motion.ik
        self.rest_posture = rest_posture
        """The joints of the rest posture [rad]: where the robot was handed over (out of view)."""
        self.lean_drift = np.zeros(3)
        """Horizontal motion of the TCP per metre it rises along the approach axis of its last descent [m/m]
        (zero upright; set by :meth:`skills.pinch.Pinch.descend_to`)."""

    def withdraw(self) -> None:
        """After a stop: back off along the load, open the gripper, move up and go to rest with the force
        guard off (the load that tripped it is what the withdrawal relieves). Backing off first matters for
        a pad pressed on a part: held where it stopped while the gripper opens, a stuck door kept 170 N on
        the wrist for half a second."""
        self.watch.guard = False
        try:
            self.motion.relieve()
        finally:
            self.watch.guard = True
        self.let_go_and_retreat(guarded=False)

    def let_go_and_retreat(self, guarded: bool = True) -> None:
        """Open, move up and go to rest; a force stop on the way withdraws unguarded."""
        try:
            self.watch.guard = guarded
            self.retreat_moves()
        except ForceLimitExceeded:
            self.watch.guard = False
            self.retreat_moves()
        finally:
            self.watch.guard = True

    def retreat_moves(self) -> None:
        """Open gently to the pre-grasp closure (wide enough to let the 12 mm post go; fully open, the ~8 cm
        fingers caught neighbouring parts on the way up), lift, and go to rest."""
        c = self.config
        self.open_gently(c.approach.pregrasp_closure)
        try:
            self.ik.set_joints(self.robot.joint_positions())
            self.lift_clear(c.approach.approach_height)
        except IKFailure:
            pass  # already as high as the arm goes
        self.interpolate_to_rest()

    def lift_clear(self, height: float) -> None:
        """Lift the open gripper by ``height`` [m], stopping at a light touch (``lift_contact_force``); on one,
        back off, step ``lift_sidestep`` along the pads (the TCP's x: parallel to the handle between them, which
        the step then never pushes), first to the side the load pushed towards, then to the other, and lift
        again. Withdrawing (guard off), or when neither side clears, the lift runs under the full guard. Near the
        base's axis it first moves out from it (:meth:`out_from_base`)."""
        c = self.config
        bottom = self.robot.tcp_pose_in_base()[2, 3]
        top = bottom + height
        if self.watch.guard:
            limit = self.watch.limit
            self.watch.limit = max(
                c.retreat.lift_contact_force, c.retreat.lift_noise_margin * self.watch.filtered_noise_now()
            )
            origin, away = None, np.zeros(3)
            try:
                for side in (0.0, 1.0, -1.0):
                    try:
                        if side:
                            assert origin is not None  # the first try (side 0) ended in a touch
                            self.step_along_pads(origin, side * away)
                        up = self.robot.tcp_pose_in_base()
                        self.rise(up, min(up[2, 3] + c.retreat.lift_slow_height, top))
                        self.motion.move_to(up, c.retreat.lift_slow_time)
                        self.out_from_base(up, bottom, top)
                        self.rise(up, top)
                        self.motion.move_to(up, c.retreat.retreat_time)
                        return
                    except ForceLimitExceeded:
                        if origin is None:  # which way the first touch pushed, before backing off from it
                            away = self.watch.force_in_base.copy()
                        self.watch.guard = False
                        try:
                            self.motion.relieve()
                        finally:
                            self.watch.guard = True
                        if origin is None:
                            origin = self.robot.tcp_pose_in_base()[:3, 3].copy()
            finally:
                self.watch.limit = limit
        up = self.robot.tcp_pose_in_base()
        self.out_from_base(up, bottom, top)
        self.rise(up, top)
        self.motion.move_to(up, c.retreat.retreat_time)

    def out_from_base(self, pose: np.ndarray, bottom: float, top: float) -> None:
        """If ``pose`` (4x4, the lift's target so far; moved in place) stands within ``base_radius`` of the vertical
        axis of the arm's base, rise to ``base_rise`` above ``bottom`` (where the lift began; at most ``top``) [m]
        and move out horizontally to ``base_radius``: the arm reached there folded over its own shoulder."""
        c = self.config
        radius = math.hypot(pose[0, 3], pose[1, 3])
        if radius >= c.approach.base_radius or radius < 1e-6:
            return
        if pose[2, 3] < min(bottom + c.approach.base_rise, top):
            self.rise(pose, min(bottom + c.approach.base_rise, top))
            self.motion.move_to(pose, c.retreat.lift_slow_time)
        out_to_radius(pose, c.approach.base_radius)
        self.motion.move_to(pose, c.retreat.retreat_time)

    def open_gently(self, closure: float) -> None:
        """Ramp the gripper's command open to ``closure`` at ``gentle_release_speed`` (slowed with the motions in
        contact); a filtered force that rises past the lift's light touch (``lift_contact_force``, or
        ``lift_noise_margin`` times the filtered noise) above its value at the start holds the command, and the arm
        backs off along the load before they open on (three times; at a fourth touch the fingers stay where they
        are): a finger opening under the plate of a door standing open over the part presses into it with the
        gripper's whole force."""
        c = self.config
        touch = max(c.retreat.lift_contact_force, c.retreat.lift_noise_margin * self.watch.filtered_noise_now())
        touch += math.sqrt(self.watch.force_in_base @ self.watch.force_in_base)  # the handle's load, gone once let go
        step = c.retreat.gentle_release_speed * c.motion.tick / self.watch.slowdown
        command = self.robot.gripper_opening()
        touches = 0
        while command > closure:
            command = max(closure, command - step)
            self.robot.command_gripper(command)
            self.motion.tick(self.ik.tcp_pose())
            if math.sqrt(self.watch.force_in_base @ self.watch.force_in_base) > touch:
                if touches == 3:  # let go as far as there is room: the lift steps aside from what stops it
                    self.robot.command_gripper(self.robot.gripper_opening())
                    return
                touches += 1
                # the command held, no harder: the finger opens on as the arm backs off, until the load is gone
                guard, self.watch.guard = self.watch.guard, False
                try:
                    self.motion.relieve()
                finally:
                    self.watch.guard = guard

    def rise(self, pose: np.ndarray, height: float) -> None:
        """Raise ``pose`` (4x4, in place) to ``height`` [m] along the approach axis of a leaning gripper (straight
        up when upright): back the way it came down, its upper part clear of what it leans away from."""
        if self.lean_drift.any():
            pose[:3, 3] += (height - pose[2, 3]) * self.lean_drift
        pose[2, 3] = height

    def step_along_pads(self, origin: np.ndarray, away: np.ndarray) -> None:
        """Move the TCP to ``lift_sidestep`` from ``origin`` (base frame [m]) along its x axis, on the side of
        ``away`` (a load's direction: it points from what was met), at its present height."""
        pose = self.robot.tcp_pose_in_base()
        along = pose[:3, 0].copy()
        along[2] = 0.0
        along /= np.linalg.norm(along)
        target = pose.copy()
        target[:3, 3] = origin + math.copysign(self.config.retreat.lift_sidestep, float(away @ along)) * along
        target[2, 3] = pose[2, 3]
        self.motion.move_to(target, self.config.retreat.retreat_time)

    def go_rest(self) -> None:
        """Back to the rest posture by joint interpolation (no IK: always feasible); a force stop on the
        way withdraws upwards first."""
        try:
            self.interpolate_to_rest()
        except ForceLimitExceeded:
            self.withdraw()

    def interpolate_to_rest(self) -> None:
        """Lift the TCP straight up to ``transit_height``, clear of the box and anything standing on it,
        move it to the transit waypoint, and only from there interpolate the joints to the rest posture
        (folded over the base, out of the overview's view): interpolated from wherever the arm was, the
        joints swept the gripper base into the arm's own link 2 (69-185 N on the wrist)."""
        c = self.config
        try:
            self.ik.set_joints(self.robot.joint_positions())
            via = self.robot.tcp_pose_in_base()
            if via[2, 3] < c.motion.transit_height - 0.01:
                via[2, 3] = c.motion.transit_height
                self.motion.move_to(via, c.retreat.lift_time)
            via[:3, 3] = (*c.motion.transit_xy, max(via[2, 3], c.motion.transit_height))
            self.motion.move_to(via, c.retreat.lift_time)
        except IKFailure:
            pass  # as far as the arm goes: interpolate from here
        self.motion.joint_move(np.asarray(self.rest_posture), c.retreat.rest_time)
        self.robot.wait(c.motion.settle_time)


__all__ = ["Retreat", "out_to_radius"]
