"""The pinch (:class:`Pinch`): approach a handle from above, descend onto it under the force guard, close the
gripper, drive the grasp point along the perceived joint (arc for hinges, line for slides) towards the other state
while reading the load against the motion, then let go and retreat. Its verdict: ``moved`` past ``moved_fraction``
of the travel, ``blocked`` (a lock felt: the force rose without progress, the part stalled part-way, or held until
the pads slid off), else ``failed``.
"""

from __future__ import annotations

import collections
import collections.abc
import functools
import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial.transform import Rotation

from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.door_judgement import ClosingTrace, SwingTrace
from puzzlebox.skills.errors import GraspFailure, SlipDetected
from puzzlebox.skills.joint_model import JointModel
from puzzlebox.skills.judgement import Decision, Judgement, PinchJudge, PinchLimits, PinchTrace, Reading, verdict
from puzzlebox.skills.kinematics import top_down
from puzzlebox.skills.pacing import Pacing
from puzzlebox.skills.retreat import Retreat, out_to_radius
from puzzlebox.skills.toggle_result import HELD_PART_WAY, LATCHED, ToggleResult

MAX_HEAD_START = 0.5
"""Largest :attr:`Pinch.head_start` believed [-]: a part seen further along is not where its state says."""
INCOMPLETE_TRAVEL = "IncompleteTravel"
"""Reason prefix of a motion that ran its course short of ``moved_fraction`` (no latch read)."""


@dataclass(frozen=True)
class TryArgs:
    """How one toggle is made, as the pinch and the pushes read it (a value passed along, never left on a part)."""

    cautious: bool = False
    """Descend slowly, stopped at a light touch: a door may stand open over the part (``toggle(cautious=True)``)."""
    careful: bool = False
    """Move in contact at ``careful_pace``: a part tried as a kind it was not told (``toggle(careful=True)``)."""
    head_start: float = 0.0
    """Fraction of the travel towards the other state the part stood at when the toggle began
    (``toggle(stands_at=...)``), counted into the progress that tells it reached its stop: the fingers' progress
    counts from the perceived closed (or open) pose, and the handle of a lever left part-way is that much ahead
    of them (a lever rests up to ~20 % pressed once lifted, a try taken back leaves it at 30-45 %). Its stop
    was met with the fingers at 57-73 % and read ``held part-way``; taken back, the lever was tried again and
    again until the grasp closed on nothing."""
    lean: np.ndarray | None = None
    """Horizontal vector (base frame) along which the gripper leans over the part, by ``lean_angle`` times its
    length (``toggle(lean=...)``), or None: upright."""


@dataclass(frozen=True)
class PinchPath:
    """The plan of a pinch's actuation (:meth:`Pinch.plan`)."""

    lead: float
    """How far the command may run ahead of the measured progress [fraction of the travel]."""
    end: float
    """Where the command ends [fraction of the travel]: past 1 for a door's over-travel."""
    pacing: Pacing
    """Where the command is at each tick: a slow start, then a ramp up."""
    last_tick: int
    """Ticks of the command (the over-travel at half pace)."""
    held_along: np.ndarray | None
    """Axis along which the path yields to only part of the load (``Handling.axis_yield``), or None."""
    returning: float
    """Share of the path's offset kept per tick past the travel [-]."""
    window: int
    """Ticks over which a stall is measured."""
    press_limit: float
    """Load against the motion that already means held for a handle pressed or pulled along its post [N]."""


class Pinch:
    """Pinches a handle and carries it along its path (see the module docstring)."""

    def __init__(self, retreat: Retreat) -> None:
        self.retreat, self.motion, self.watch = retreat, retreat.motion, retreat.watch
        self.robot, self.config, self.ik = retreat.robot, retreat.config, retreat.ik
        c = self.config
        self.progress = 0.0
        """Measured progress of the current toggle's actuation so far (kept when a stop ends it)."""
        self.slip_ticks = max(2, round(c.judgement.slip_window / c.motion.tick) + 1)
        """Gripper closures the slip test compares (``slip_window`` in ticks, plus one)."""
        self.grasp_closure = 0.0
        """Gripper closure once the current toggle's handle was grasped [-]."""
        self.judge: PinchJudge | None = None
        """The judgement of the current (or last) toggle's actuation (:mod:`skills.judgement`)."""

    # -- the toggle --------------------------------------------------------------------------------
    def grasp_yaw(self, jm: JointModel) -> float:
        """Yaw of the gripper (the kind's ``Handling.grasp``). Slides and wheels: the fingers close along
        the handle's (horizontal) direction of motion, so the pads push it. Doors: along the hinge axis, so the
        handle pivots between the pads like a pin as the door swings and the gripper need not tilt 85 degrees
        (tilting with it folded the arm onto itself)."""
        direction = jm.axis if jm.handling.grasp == "along_axis" else jm.motion_direction(0.0)
        return float(np.arctan2(direction[1], direction[0]) + np.pi / 2)

    def descend_to(self, target: np.ndarray, args: TryArgs) -> None:
        """Open to the pre-grasp closure, travel above ``target`` (4x4; :meth:`approach`), tare the F/T there and
        descend onto it."""
        c = self.config
        # the lift off this part goes back the same way: a pinch's lean, not a push's upright pads after it
        self.retreat.lean_drift = target[:3, 2] / target[2, 2]
        self.retreat.lean_drift[2] = 0.0
        self.robot.command_gripper(c.approach.pregrasp_closure)
        self.watch.phase = "approaching"
        height = self.approach(target)
        self.watch.rest_noise = self.watch.noise()  # coming to rest above the part
        self.robot.tare(
            self.watch.tare_samples(self.watch.rest_noise)
        )  # fingers open, arm still: the gripper's load alone
        # older samples were taken with another zero; the window is as long as this noise needs
        samples = self.watch.filter_samples(self.watch.rest_noise)
        self.watch.window = collections.deque(maxlen=samples)
        self.watch.slowdown = (
            samples / c.sensing.force_filter_samples / (c.actuation.careful_pace if args.careful else 1.0)
        )
        self.watch.phase = "descending"
        if args.cautious:  # the whole way slowly, under the light touch
            slow = c.approach.cautious_descend_time * height / c.approach.approach_height
        else:
            # quickly down to where the fingers could first meet a handle they were aimed beside, then slowly, so
            # that one met (a wrong perception or calibration) stops the arm at a light touch: the try fails, not
            # the part
            near = target.copy()
            near[:3, 3] -= c.approach.touch_height * target[:3, 2]
            self.motion.move_to(
                near,
                c.approach.descend_time
                * (height - c.approach.touch_height)
                / c.approach.approach_height
                * self.watch.slowdown,
            )
            slow = c.approach.touch_height / c.approach.touch_speed
        self.watch.limit = max(
            c.approach.cautious_contact_force, c.approach.cautious_noise_margin * self.watch.rest_noise
        )
        try:
            self.motion.move_to(target, slow * self.watch.slowdown, smooth=False)
        finally:
            self.watch.limit = c.sensing.force_limit

    def approach(self, target: np.ndarray) -> float:
        """Travel to above ``target`` (4x4) along its approach axis (up, when upright) and return how high above it
        [m]: ``approach_height``, or, where that point stands within ``base_radius`` of the vertical axis of the
        arm's base, ``base_rise``, reached at that height from ``base_radius`` out and moving in horizontally (the
        way :meth:`out_from_base` leaves): the arm reaches there folded over its own shoulder, and every route to 8
        cm above a drawer's handle 0.176 m from the axis put the gripper's knuckle on link 2 (101-137 N, 17 mm deep in
        the robot model); arriving 3.5 cm above it from outside kept 3-6 mm of clearance, more on the way down."""
        c = self.config
        above = target.copy()
        above[:3, 3] -= c.approach.approach_height * target[:3, 2]
        radius = math.hypot(above[0, 3], above[1, 3])
        if not 1e-6 <= radius < c.approach.base_radius:
            self.motion.travel_to(above, c.approach.approach_time)
            return c.approach.approach_height
        height = max(c.approach.base_rise, c.approach.touch_height)
        above[:3, 3] = target[:3, 3] - height * target[:3, 2]
        out = above.copy()
        out_to_radius(out, c.approach.base_radius)
        self.motion.travel_to(out, c.approach.approach_time)
        self.motion.move_to(above, c.retreat.retreat_time)
        return height

    def run(self, jm: JointModel, sign: float, args: TryArgs) -> ToggleResult:
        c = self.config
        begin = 0.0 if sign > 0 else 1.0
        grasp_yaw = self.grasp_yaw(jm)
        at_grasp = self.leaning(top_down(jm.grasp_point_at(begin), grasp_yaw), args.lean)
        self.descend_to(at_grasp, args)
        self.watch.phase = "grasping"
        found = self.motion.close_slowly(settle=jm.handling.grasp == "across_motion")
        if found.any():  # the handle stands that far beside where it was aimed: the path starts from it
            jm = replace(jm, origin=jm.origin + found, grasp_point=jm.grasp_point + found)
            at_grasp = at_grasp.copy()
            at_grasp[:3, 3] += found
        grasp_closure = self.grasp_closure = self.robot.gripper_opening()
        if grasp_closure >= c.judgement.empty_grasp_closure:
            raise GraspFailure(f"the gripper closed on nothing at {np.round(at_grasp[:3, 3], 3).tolist()}")

        self.watch.phase = "actuating"
        result = self.actuate(jm, sign, begin, at_grasp, args)
        self.watch.phase = "retreating"
        self.retreat.let_go_and_retreat()
        self.watch.phase = "moving"
        return result

    def plan(self, jm: JointModel, sign: float, begin: float, at_grasp: np.ndarray, args: TryArgs) -> PinchPath:
        """The actuation's plan for the part of joint model ``jm`` grasped at ``at_grasp`` (4x4), moving from
        ``begin`` (0 closed, 1 open) in direction ``sign``: pure, no sensor read."""
        c = self.config
        along_post = float(sign * jm.motion_direction(begin) @ at_grasp[:3, 2])  # cosine to the approach axis
        pressed = along_post > math.cos(c.actuation.press_angle)
        # pulled up along its post (``press_force``), but not from a head start of MAX_HEAD_START: a part seen that far
        # along is not where its state says, and may be lifted into its stop
        pulled = (
            along_post < -math.cos(c.actuation.press_angle)
            and not jm.handling.swings_up
            and args.head_start < MAX_HEAD_START
        )
        slowdown = self.watch.slowdown
        if pressed:  # at press_pace at the most (a careful toggle may already go slower)
            slowdown *= max(1.0, (c.actuation.careful_pace if args.careful else 1.0) / c.actuation.press_pace)
        ticks = round(c.actuation.actuate_time * slowdown / c.motion.tick)
        path_length = (
            jm.travel
            if jm.joint == "slide"
            else jm.travel
            * float(
                np.linalg.norm((jm.grasp_point - jm.origin) - np.dot(jm.grasp_point - jm.origin, jm.axis) * jm.axis)
            )
        )
        lead = c.actuation.lead / path_length  # as a fraction of the travel
        end = 1.0 + (c.actuation.door_overtravel if jm.handling.swings_up and sign > 0 else 0.0)
        pace = end / ticks  # travel per tick up to the travel's end
        pacing = Pacing(
            pace, pace * c.actuation.breakaway_pace, c.actuation.breakaway_fraction
        )  # slow start, then a ramp up
        press_limit = (
            max(c.judgement.press_force, c.judgement.press_noise_margin * self.watch.filtered_noise_now())
            if pressed or pulled
            else math.inf
        )
        return PinchPath(
            lead=lead,
            end=end,
            pacing=pacing,
            last_tick=pacing.ticks_to(1.0 + 2 * (end - 1.0)),
            held_along=None if jm.handling.axis_yield == 1.0 else jm.axis,  # (a load along it: yielded to in part)
            returning=1.0 - c.motion.tick / c.motion.comply_return_time,  # the offset kept per tick past the travel
            window=max(2, round(c.judgement.stall_window * slowdown / c.motion.tick)),
            press_limit=press_limit,
        )

    def actuate(self, jm: JointModel, sign: float, begin: float, at_grasp: np.ndarray, args: TryArgs) -> ToggleResult:
        """Carry the grasped handle along its path (:meth:`plan`), reading the load against the motion every tick:
        held (a lock) ends it ``blocked`` and takes the handle back; run to its end, :meth:`settle` judges it."""
        c = self.config
        path = self.plan(jm, sign, begin, at_grasp, args)
        limits = PinchLimits(path.press_limit, path.window, args.head_start, self.slip_ticks, self.grasp_closure)
        judge = self.judge = PinchJudge(c.judgement, limits)
        progress = 0.0
        lead, end, pacing = path.lead, path.end, path.pacing
        across = np.zeros(3)  # the path's offset across itself, yielding to the load there [m, base frame]
        yields = jm.handling.yields_across
        held_along, axis_yield, returning = path.held_along, jm.handling.axis_yield, path.returning
        self.ik.set_joints(self.robot.joint_positions())
        for k in range(1, path.last_tick + 1):
            paced = pacing.at(k)
            paced = paced if paced <= 1.0 else 1.0 + 0.5 * (paced - 1.0)  # past the travel at half pace
            s = min(end, paced, max(progress, 0.0) + lead)
            fraction = begin + sign * s
            target = self.pose_along(jm, fraction, at_grasp, begin)
            target[:3, 3] += across
            self.motion.tick(target)
            direction = sign * jm.motion_direction(fraction)
            opposing = float(-np.dot(self.watch.force_in_base, direction))
            if yields:  # once the end stop is felt, back to the planned arc: its load tells the door is open
                if s <= 1.0 or (c.actuation.overtravel_comply and not judge.in_end_stop):
                    across = self.motion.yield_across(across, direction, held_along, axis_yield)
                else:
                    across = across * returning
            progress = self.progress = self.progress_of(jm, sign, begin)
            magnitude = math.sqrt(self.watch.force_in_base @ self.watch.force_in_base)  # np.linalg.norm, bit for bit
            decision = judge.read(Reading(s, opposing, magnitude, progress, self.robot.gripper_opening()))
            if decision is Decision.GO_ON:
                if s > 1.0 and magnitude > c.actuation.overtravel_force:  # past the travel and pushing hard: stop
                    end = max(1.0, min(progress, s))
                continue
            if decision is Decision.AT_STOP:
                end = max(progress, 0.0)  # at its stop short of the perceived travel: pushed no further
                break
            if decision is Decision.HELD_EARLY:  # back to where the handle was grasped
                self.motion.take_back(functools.partial(self.motion.move_to, at_grasp, 0.5))
            elif decision is Decision.HELD_PART_WAY:
                self.motion.take_back(functools.partial(self.return_along, jm, sign, begin, progress, at_grasp, across))
            return self.result_of(judge.ended(decision), judge.forces, judge.trace())
        return self.settle(jm, sign, begin, at_grasp, end, lead, across, args)

    def settle(
        self,
        jm: JointModel,
        sign: float,
        begin: float,
        at_grasp: np.ndarray,
        end: float,
        lead: float,
        across: np.ndarray,
        args: TryArgs,
    ) -> ToggleResult:
        """Let the part catch up with the actuation's ``end`` target (fraction of the travel) and judge where it got:
        ``moved``, ``blocked`` (pulled without progress: taken back to ``at_grasp``) or ``failed``."""
        c = self.config
        judge = self.judge
        assert judge is not None  # (set by actuate)
        for _ in range(round(2 * c.motion.settle_time / c.motion.tick)):  # let the part catch up with the end target
            progress = self.progress = self.progress_of(jm, sign, begin)
            target = self.pose_along(jm, begin + sign * min(end, max(progress, 0.0) + lead), at_grasp, begin)
            target[:3, 3] += across
            self.motion.tick(target)
            decision = judge.settle_read(progress, self.robot.gripper_opening())
            if decision is Decision.AT_STOP:
                break
            if decision is not Decision.GO_ON:
                return self.result_of(judge.ended(decision), judge.forces, judge.trace())
        reached = self.progress_of(jm, sign, begin) + args.head_start
        judgement = judge.verdict(reached, Cause.LOCKED_PULLED)
        if judgement.outcome == "blocked":
            self.motion.take_back(functools.partial(self.motion.move_to, at_grasp, 0.5))
        return self.result_of(judgement, judge.forces, judge.trace(reached))

    def return_along(
        self, jm: JointModel, sign: float, begin: float, covered: float, at_grasp: np.ndarray, across: np.ndarray
    ) -> None:
        """Take a handle held part-way, ``covered`` of the travel from ``begin``, back along its path to where it
        was grasped (``at_grasp``; ``across``: the path's offset, let go on the way) over ``release_time`` per 10 %
        of the travel: a straight line cuts a hinge's arc."""
        c = self.config
        ticks = max(1, round(c.motion.release_time * max(covered, 0.0) / 0.1 / c.motion.tick))
        for k in range(1, ticks + 1):
            left = 1.0 - k / ticks
            target = self.pose_along(jm, begin + sign * covered * left, at_grasp, begin)
            target[:3, 3] += across * left
            self.motion.tick(target)

    def verdict(self, progress: float, forces: list[float], latched: Cause | None = None) -> ToggleResult:
        """How a motion that ran its course ended (:func:`skills.judgement.verdict`): ``moved`` past
        ``moved_fraction`` of the travel; ``blocked`` (cause ``latched``, when given) short of ``blocked_progress``
        after at least ``push_force`` against the motion (``forces`` [N], one per tick); else ``failed``."""
        return self.result_of(verdict(self.config.judgement, progress, forces, latched), forces)

    @staticmethod
    def result_of(
        judgement: Judgement, forces: list[float], trace: PinchTrace | SwingTrace | ClosingTrace | None = None
    ) -> ToggleResult:
        """The toggle's result of a judgement, its reason rendered from its cause; a slip raises
        :class:`SlipDetected` (no evidence: the toggle's retries decide what follows)."""
        cause, progress = judgement.cause, judgement.progress
        if cause is Cause.SLIPPED:  # (the readings stay with the pinch's judge: Toggler keeps them with the failure)
            raise SlipDetected(f"the handle slipped out of the grasp after {progress:.0%} of the travel")
        if cause is None:
            reason = ""
        elif cause is Cause.HELD_PART_WAY:
            reason = f"{HELD_PART_WAY} ({judgement.held_at:.0%} of the travel)"
        elif cause is Cause.JAMMED:
            reason = f"Jammed: the door held at {judgement.held_at:.0%} of its travel"
        elif cause is Cause.INCOMPLETE_TRAVEL:
            reason = f"{INCOMPLETE_TRAVEL}: only {progress:.0%} of the travel covered"
        else:
            reason = LATCHED[cause]
        return ToggleResult(
            judgement.outcome, reason, progress, judgement.peak_opposing_force, forces=forces, cause=cause,
            end_stop_felt=judgement.end_stop_felt, trace=trace,
            held_at=judgement.held_at if cause is Cause.HELD_PART_WAY else None,
        )  # fmt: skip

    def leaning(self, upright: np.ndarray, lean: np.ndarray | None) -> np.ndarray:
        """``upright`` (a top-down TCP pose, 4x4) turned by ``lean_angle`` about its closing axis (y) so that the
        gripper's upper part leans along ``lean``'s component across that axis; unchanged without a lean,
        or when the lean lies along the closing axis (turning the pads off the handle's faces would not do)."""
        if lean is None or self.config.approach.lean_angle == 0.0:
            return upright
        strength = float(np.linalg.norm(lean))
        closing = upright[:3, 1]
        across = lean - float(lean @ closing) * closing
        across[2] = 0.0
        size = float(np.linalg.norm(across))
        if size < 0.5 * strength:
            return upright
        across /= size
        angle = self.config.approach.lean_angle * min(strength, 1.0)
        axis = np.cross((0.0, 0.0, 1.0), across)  # turning +z towards ``across``
        leaning = upright.copy()
        leaning[:3, :3] = Rotation.from_rotvec(axis * angle).as_matrix() @ upright[:3, :3]
        return leaning

    def pose_along(self, jm: JointModel, fraction: float, at_grasp: np.ndarray, begin: float) -> np.ndarray:
        T = at_grasp.copy()
        T[:3, 3] = jm.grasp_point_at(fraction)
        if jm.joint == "hinge" and abs(jm.axis[2]) > 0.9:  # wheels: the gripper turns with the knob
            turn = Rotation.from_rotvec(jm.axis * (fraction - begin) * jm.travel).as_matrix()
            T[:3, :3] = turn @ at_grasp[:3, :3]
        return T

    def progress_of(self, jm: JointModel, sign: float, begin: float) -> float:
        """Measured fraction of the travel covered towards the other state, from the TCP position."""
        return sign * jm.fraction_between(jm.grasp_point_at(begin), self.robot.tcp_pose_in_base()[:3, 3])


__all__ = ["INCOMPLETE_TRAVEL", "MAX_HEAD_START", "Pinch", "TryArgs"]
