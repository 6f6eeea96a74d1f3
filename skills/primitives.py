"""Manipulation primitives: toggle a component with the arm, feeling through the wrist F/T sensor
whether it was latched.

A toggle approaches the handle from above, descends, closes the gripper, drives the grasp point
along the perceived joint (arc for hinges, line for slides) towards the other state, then releases
and retreats. A door whose handle the pads could not hold is then pushed, in the same try
(:mod:`skills.door_push`; ``door_push``): a door's handle moves along its own post, so pinching it moves the
door by pad friction alone, which a weak grip does not give (harsh profile: 12 of 60 trials ended with the
handle slipping out). A pushed door opens under the inner face of a finger pad pressed on the back of its
handle, and closes under the pads' edges pressed on its plate; doors are always shut that way
(``push.close_by_push``). Beside a door that may stand open over the part (``cautious``), descents are slow
and stop at a light touch (:mod:`skills.door_clearance`); every other descent runs its last ``touch_height``
slowly under that light touch, where fingers aimed beside a handle (a wrong hand-eye calibration) land on it.

Motion is differential IK on the robot-only model at a 10 ms control tick, targets sent to the position
servos. The wrist wrench is read every tick and filtered (a running median over
``force_filter_samples`` ticks, so no single noisy sample decides anything). The sensor's noise is measured
as the arm comes to rest above each part: a noisy sensor is tared on more readings (``tare_noise``), its median
is longer (``filtered_noise``), and every motion in contact is slowed by the same ratio (:attr:`ForceWatch.slowdown`),
so that a force rising against a stop builds no more during the longer median's delay. While actuating, the
filtered force — rotated into the base frame, tared with the fingers open — is projected on the
handle's direction of motion: if the force opposing the motion exceeds ``blocked_force`` while the
measured progress is below ``blocked_progress``, the component is latched: the arm backs off to where
it started and lets go (DESIGN.md: this rule made no error in 36 randomized attempts and stopped every
latched attempt within 0.13-1.2 s; without a stop the grasp is torn off at 100-300 N). A handle pressed down
along its own post (a lever), which the pads hold by friction alone, is held once the opposing force exceeds the
lighter ``press_force``, at any progress short of ``moved_fraction``. The start of the
travel, where latches and sticky parts are met, is driven at ``breakaway_pace`` of the rest's pace, and a
door's or a wheel's path yields across itself to the load there (``comply_gain``, ``Handling.yields_across``): only
the load along the motion tells a latch, and a path planned from a slightly wrong hinge otherwise drags the handle
across its true arc (57 N on a free door at one placement, 39 N yielding). A closed grasp yields across the
fingers' closing axis too before it pulls (:meth:`GuardedMotion.close_slowly`).

Whatever the motion (approach, descent, actuation, retreat), a filtered force above ``force_limit``
stops it at once: the gripper opens and the arm withdraws, and the try ends ``failed: force limit``
— a real arm's collision detection does the same. A handle that leaves the fingers during the motion
(the gripper closes past the handle's width) ends the try ``failed`` too: a slip is not a move.

Outcomes are ``moved``, ``blocked`` or ``failed`` (with a reason); IK failures, empty grasps, slips and
the force limit are typed errors underneath and reported as ``failed``.
"""

from __future__ import annotations

import collections
import collections.abc
import time

import numpy as np

from puzzlebox.models.robot import Robot
from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.door_push import DoorPusher
from puzzlebox.skills.errors import ForceLimitExceeded, GraspFailure, IKFailure, SlipDetected
from puzzlebox.skills.force_watch import ForceWatch
from puzzlebox.skills.guarded_motion import GuardedMotion
from puzzlebox.skills.joint_model import JointModel
from puzzlebox.skills.kinematics import ArmKinematics
from puzzlebox.skills.pinch import MAX_HEAD_START, Pinch, TryArgs
from puzzlebox.skills.retreat import Retreat
from puzzlebox.skills.settings import PrimitiveConfig
from puzzlebox.skills.toggle_result import ToggleResult

STOPPED = "motion stopped"
"""End of the reason of a motion the force guard stopped: ``... while <phase>, motion stopped``."""
STOPPED_DESCENDING = f"while descending, {STOPPED}"
"""End of the reason of a try the force guard stopped on the way down onto the handle."""
PADS_LOST_HOLD = frozenset({Cause.SLIPPED, Cause.GRASP_EMPTY, Cause.LOCKED_SLIPPED_OFF})
"""Causes of a pinch that ended for want of a hold on the handle (it slipped out, the grasp closed on nothing,
or the part held until the pads slid off: a latch, or a door heavier than the grip holds). A door is then
pushed, and the push's verdict stands."""


class Toggler:
    """Runs toggle primitives on a robot interface (``twin.robot_interface.RobotInterface`` or a real one): a try's
    control (:meth:`toggle`) over its parts — the force watch, guarded motion, retreat, pinch and door pushes."""

    def __init__(
        self, robot: Robot, config: PrimitiveConfig | None = None, kinematics: ArmKinematics | None = None
    ) -> None:
        config = config or PrimitiveConfig()
        self.ik = kinematics or ArmKinematics()
        rest_posture = robot.joint_positions()  # where the robot was handed over: out of view
        self.watch = ForceWatch(robot, config)
        self.motion = GuardedMotion(robot, config, self.ik, self.watch)
        self.retreat = Retreat(self.motion, rest_posture)
        self.pinch = Pinch(self.retreat)
        self.doors = DoorPusher(self.pinch)
        self._parts = (self.watch, self.motion, self.retreat, self.pinch, self.doors)

    @property
    def robot(self) -> Robot:
        return self.motion.robot

    @robot.setter
    def robot(self, robot: Robot) -> None:
        """Another interface to the same arm (an observer wrapping it): every part reads and moves through it."""
        for part in self._parts:
            part.robot = robot

    @property
    def config(self) -> PrimitiveConfig:
        return self.motion.config

    @config.setter
    def config(self, config: PrimitiveConfig) -> None:
        for part in self._parts:
            part.config = config

    @property
    def phase(self) -> str:
        """What the arm is doing (``models.toggle_log.PHASES``)."""
        return self.watch.phase

    @property
    def force_in_base(self) -> np.ndarray:
        """The filtered wrist force after the last tick, in the base frame [N]."""
        return self.watch.force_in_base

    @property
    def rest_posture(self) -> np.ndarray:
        """The joints of the rest posture [rad] (where the robot was handed over, unless set)."""
        return self.retreat.rest_posture

    @rest_posture.setter
    def rest_posture(self, joints: np.ndarray) -> None:
        self.retreat.rest_posture = joints

    def move_to(self, target: np.ndarray, duration: float) -> None:
        """:meth:`skills.guarded_motion.GuardedMotion.move_to`."""
        self.motion.move_to(target, duration)

    def travel_to(self, target: np.ndarray, duration: float) -> None:
        """:meth:`skills.guarded_motion.GuardedMotion.travel_to`."""
        self.motion.travel_to(target, duration)

    def withdraw(self) -> None:
        """:meth:`skills.retreat.Retreat.withdraw`."""
        self.retreat.withdraw()

    def go_rest(self) -> None:
        """:meth:`skills.retreat.Retreat.go_rest`."""
        self.retreat.go_rest()

    def toggle(
        self,
        jm: JointModel,
        opening: bool = True,
        where_is: collections.abc.Callable[[], float | None] | None = None,
        door_at: float | None = None,
        push: bool = False,
        raised: bool = False,
        cautious: bool = False,
        lean: np.ndarray | None = None,
        careful: bool = False,
        stands_at: float | None = None,
    ) -> ToggleResult:
        """Try to move the component of joint model ``jm`` to its other state (see the module docstring).
        ``where_is`` looks at the part and tells the fraction of its travel at which it stands now (0 closed,
        1 open; None if not seen): a door the pinch could not hold is pushed from there. ``door_at``: where a
        door was just seen to stand; one part-way (past ``blocked_progress`` of the motion) is pushed from
        there at once, as its handle is not where a pinch would descend. ``push``: push a door without
        pinching it first (from ``door_at``, else from its start). ``raised``: a door stands raised where no
        look sees it (above ~50 deg its handle hides its marker): pushed on up under its plate. ``cautious``: a
        door may stand open over the part (:mod:`skills.door_clearance`): every descent of the try is made at
        ``cautious_descend_time`` and stopped at ``cautious_contact_force``. ``lean``: a horizontal vector (base
        frame) in whose direction a pinch's gripper leans by ``lean_angle`` times its length (at most 1) about its
        closing axis, away from what may stand over the part (:func:`skills.door_clearance.lean_away`); it
        descends and lifts along its tilted axis. ``careful``: every motion in contact at ``careful_pace`` (a part
        tried as a kind it was not told). ``stands_at``: where a part that does not swing up was just seen to stand
        (fraction of its travel, 0 closed, 1 open; :attr:`head_start`)."""
        wall = time.perf_counter()
        ahead = None if stands_at is None or jm.handling.swings_up else (stands_at if opening else 1.0 - stands_at)
        head_start = 0.0 if ahead is None else min(max(ahead, 0.0), MAX_HEAD_START)
        args = TryArgs(cautious=cautious, careful=careful, head_start=head_start, lean=lean)
        start_time = self.robot.time
        self.watch.reset()
        c = self.config
        pushable = jm.handling.swings_up and c.door_push
        covered = None if door_at is None else (door_at if opening else 1.0 - door_at)
        if pushable and opening and raised:
            result = self._attempt(lambda: self.doors.top_up(jm, args))
        elif pushable and (
            push or (not opening and c.push.close_by_push) or (covered or 0.0) >= c.judgement.blocked_progress
        ):
            result = self._push_on(jm, opening, 0.0 if covered is None else covered, args, where_is)
        else:
            result = self._attempt(lambda: self.pinch.run(jm, 1.0 if opening else -1.0, args))
            empty = result.cause is Cause.GRASP_EMPTY
            if pushable and opening and result.outcome == "moved" and not result.end_stop_felt and c.push.top_up:
                self._attempt(lambda: self.doors.top_up(jm, args))  # best effort: the pinch's verdict stands
            if pushable and result.cause in PADS_LOST_HOLD:
                # the pads could not hold the handle: push the door instead, in the same try, from where it stands
                covered = self._push_start(result, opening, where_is)
                if covered is not None:
                    result = self._push_on(jm, opening, covered, args, where_is)
                elif result.progress < c.judgement.moved_fraction:  # (past it, the world looks whether it moved)
                    result.reason += "; the door stands part-way where it cannot be seen: not pushed"
                    result.not_pushed = True
            result.closed_on_nothing = empty
        result.peak_force = self.watch.peak_force  # over the whole try, withdrawal included
        result.sim_time = self.robot.time - start_time
        result.wall_time = time.perf_counter() - wall
        return result

    def _push_on(
        self,
        jm: JointModel,
        opening: bool,
        covered: float,
        args: TryArgs,
        where_is: collections.abc.Callable[[], float | None] | None = None,
    ) -> ToggleResult:
        """:meth:`_push`, and an opening push that lost the handle's face short of the travel (``IncompleteTravel``:
        under the harsh profile's perception error the pad drifted off a post at 62 deg) followed by a top-up
        under the plate (:meth:`DoorPusher.top_up`) if ``where_is`` does not see the door (above ~50 deg
        its handle hides its marker), whose verdict then stands (the world checks a ``moved`` against the
        marker). A door seen lower is left to a retry's push from where it stands: under a plate that low
        the top-up's pads pass over it and read "moved"."""
        result = self._push(jm, opening, covered, args)
        if opening and self.config.push.top_up and result.cause is Cause.INCOMPLETE_TRAVEL:
            if where_is is not None and where_is() is not None:
                return result
            topped = self._attempt(lambda: self.doors.top_up(jm, args))
            if topped.outcome == "moved":
                return topped
            result.reason += f"; pushed on under its plate: {topped.reason}"
            result.pushed_on = topped
        return result

    def _push(self, jm: JointModel, opening: bool, covered: float, args: TryArgs) -> ToggleResult:
        """Push door ``jm`` open or shut from where it stands, ``covered`` (fraction of this motion's travel),
        beginning ``push.start_margin`` behind it: a door let go part-way falls back ~1 deg while the arm
        comes round, and behind the handle the pad only sits higher on the post (~1.7 mm per deg)."""
        c = self.config
        start = min(max(covered - c.push.plan.start_margin, 0.0), c.judgement.moved_fraction)
        push = self.doors.push_open if opening else self.doors.push_closed
        return self._attempt(lambda: push(jm, start, args))

    def _push_start(
        self, pinch: ToggleResult, opening: bool, where_is: collections.abc.Callable[[], float | None] | None
    ) -> float | None:
        """Fraction of the motion's travel a door has covered after a pinch lost its hold, as seen by
        ``where_is``: the pinch's own progress is the fingers', and a handle sliding in weak pads lags them (a
        door at 43 deg after fingers at 68 deg), so a push placed from it met the raised post at 60-100 N, or
        swung through the air; a grasp that closed on nothing may be a door left part-way by an earlier try.
        Not seen: a pinch short of ``blocked_progress`` left the door near its start (0); a closing push
        descends onto the plate from above and meets it on the way down (0); an opening push of a door opened
        part-way (above ~50 deg its handle hides its marker from above) has nowhere safe to start (None)."""
        seen = where_is() if where_is is not None else None
        if seen is not None:
            return seen if opening else 1.0 - seen
        if pinch.progress < self.config.judgement.blocked_progress or not opening:
            return 0.0
        return None

    def _attempt(self, motion: collections.abc.Callable[[], ToggleResult]) -> ToggleResult:
        """Run one toggle motion; a typed failure ends it ``failed`` with its reason, the arm withdrawn."""
        self.pinch.progress = 0.0
        try:
            return motion()
        except (IKFailure, GraspFailure, SlipDetected, ForceLimitExceeded) as err:
            result = ToggleResult(
                "failed", reason=f"{type(err).__name__}: {err}", progress=self.pinch.progress, cause=err.cause,
                stopped_while=err.phase if isinstance(err, ForceLimitExceeded) else "",
                trace=self.pinch.judge.trace() if isinstance(err, SlipDetected) and self.pinch.judge else None,
            )  # fmt: skip
            self.retreat.withdraw()
            return result


__all__ = ["PADS_LOST_HOLD", "STOPPED_DESCENDING", "PrimitiveConfig", "ToggleResult", "Toggler"]
