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
is longer (``filtered_noise``), and every motion in contact is slowed by the same ratio (:attr:`Toggler.slowdown`),
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
fingers' closing axis too before it pulls (:meth:`Toggler._close_slowly`).

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
import functools
import math
import time
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from puzzlebox.models.robot import Robot
from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.door_push import DoorPushing
from puzzlebox.skills.errors import ForceLimitExceeded, GraspFailure, IKFailure, SlipDetected
from puzzlebox.skills.joint_model import JointModel
from puzzlebox.skills.kinematics import ArmKinematics, top_down
from puzzlebox.skills.pacing import Pacing
from puzzlebox.skills.settings import TARE_SAMPLES, PrimitiveConfig
from puzzlebox.skills.toggle_result import HELD_PART_WAY, LATCHED, ToggleResult

SLIPPED_OFF = LATCHED[Cause.LOCKED_SLIPPED_OFF]
MAX_HEAD_START = 0.5
"""Largest :attr:`Toggler.head_start` believed [-]: a part seen further along is not where its state says."""
INCOMPLETE_TRAVEL = "IncompleteTravel"
"""Reason prefix of a motion that ran its course short of ``moved_fraction`` (no latch read)."""
STOPPED = "motion stopped"
"""End of the reason of a motion the force guard stopped: ``... while <phase>, motion stopped``."""
STOPPED_DESCENDING = f"while descending, {STOPPED}"
"""End of the reason of a try the force guard stopped on the way down onto the handle."""
PADS_LOST_HOLD = frozenset({Cause.SLIPPED, Cause.GRASP_EMPTY, Cause.LOCKED_SLIPPED_OFF})
"""Causes of a pinch that ended for want of a hold on the handle (it slipped out, the grasp closed on nothing,
or the part held until the pads slid off: a latch, or a door heavier than the grip holds). A door is then
pushed, and the push's verdict stands."""


_MEDIAN_SPREAD = math.sqrt(math.pi / 2)
"""Spread of the median of n samples of a Gaussian, times sqrt(n), over the samples' spread (large n)."""


def _out_to_radius(pose: np.ndarray, radius: float) -> None:
    """Move ``pose`` (4x4, base frame; in place) out horizontally from the base's vertical axis to ``radius`` [m] if
    it stands closer (and not on the axis itself)."""
    now = math.hypot(pose[0, 3], pose[1, 3])
    if 1e-6 <= now < radius:
        pose[:2, 3] *= radius / now


def _median_rows(rows: collections.abc.Sequence[np.ndarray]) -> np.ndarray:
    """``np.median(rows, axis=0)``, bit for bit, at a fifth of its cost on a few short rows (it runs every tick)."""
    ordered = np.sort(np.array(rows), axis=0)
    mid = len(ordered) // 2
    return ordered[mid] if len(ordered) % 2 else (ordered[mid - 1] + ordered[mid]) / 2


class Toggler(DoorPushing):
    """Runs toggle primitives on a robot interface (``twin.robot_interface.RobotInterface`` or a real one)."""

    config: PrimitiveConfig

    def __init__(
        self, robot: Robot, config: PrimitiveConfig | None = None, kinematics: ArmKinematics | None = None
    ) -> None:
        self.robot = robot
        self.config = config or PrimitiveConfig()
        self.ik = kinematics or ArmKinematics()
        self.rest_posture = robot.joint_positions()  # where the robot was handed over: out of view
        self._joint_limits = tuple(robot.joint_limits().T)  # (low, high) [rad]: an arm's servo ranges are fixed
        self._force_window: collections.deque[np.ndarray] = collections.deque(
            maxlen=self.config.sensing.force_filter_samples
        )
        self._raw_forces: collections.deque[np.ndarray] = collections.deque(maxlen=self.config.sensing.noise_samples)
        """The last raw wrist forces in the base frame [N]: how noisy the sensor is (:attr:`rest_noise`)."""
        self.force_in_base = np.zeros(3)
        """The filtered wrist force after the last tick, in the base frame [N]."""
        self.phase = "moving"
        """What the arm is doing (for the reasons of failed tries)."""
        self.rest_noise = 0.0
        """F/T force noise measured as the arm came to rest above the part of the toggle in progress [N]."""
        self.progress = 0.0
        """Measured progress of the current toggle's actuation so far (kept when a stop ends it)."""
        c = self.config
        self._closures: collections.deque[float] = collections.deque(
            maxlen=max(2, round(c.judgement.slip_window / c.motion.tick) + 1)
        )
        """Gripper closures over the last ``slip_window`` of the toggle in progress (the slip test)."""
        self.peak_force = 0.0
        """Largest filtered force magnitude since the last :meth:`reset_force_watch` [N]."""
        self.guard = True
        """Stop motions at ``force_limit`` (off only while withdrawing from a stop)."""
        self.limit = self.config.sensing.force_limit
        """The force guard's threshold now [N]: ``force_limit``, or ``cautious_contact_force`` in a cautious descent."""
        self.cautious = False
        """Whether the toggle in progress descends cautiously (``toggle(cautious=True)``)."""
        self.careful = False
        """Whether the toggle in progress moves in contact at ``careful_pace`` (``toggle(careful=True)``)."""
        self.slowdown = 1.0
        """How much slower than configured the motions in contact of the toggle in progress run [-]: the
        running median's length over ``force_filter_samples`` (1 below 7.2 N of F/T noise)."""
        self.head_start = 0.0
        """Fraction of the travel towards the other state a part stood at when the toggle in progress began
        (``toggle(stands_at=...)``), counted into the progress that tells it reached its stop: the fingers' progress
        counts from the perceived closed (or open) pose, and the handle of a lever left part-way is that much ahead
        of them (a lever rests up to ~20 % pressed once lifted, a try taken back leaves it at 30-45 %). Its stop
        was met with the fingers at 57-73 % and read ``held part-way``; taken back, the lever was tried again and
        again until the grasp closed on nothing."""
        self.lean: np.ndarray | None = None
        """Horizontal vector (base frame) along which the gripper leans over the part of the toggle in progress,
        by ``lean_angle`` times its length (``toggle(lean=...)``), or None: upright."""
        self._lean_drift = np.zeros(3)
        """Horizontal motion of the TCP per metre it rises along the approach axis of its last descent [m/m]
        (zero upright; set by :meth:`_descend_to`)."""

    # -- force -------------------------------------------------------------------------------------
    def reset_force_watch(self) -> None:
        """Forget the force history (after a tare: older samples have another zero)."""
        self._force_window.clear()
        self.peak_force = 0.0

    def _sense(self) -> None:
        """Read the wrench into the filter window (a running median, :attr:`force_in_base`) and enforce
        the safety limit."""
        raw = self.robot.ft_rotation_in_base() @ self.robot.wrench()[:3]
        self._force_window.append(raw)
        self._raw_forces.append(raw)
        self.force_in_base = _median_rows(self._force_window)
        magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
        self.peak_force = max(self.peak_force, magnitude)
        if self.guard and magnitude > self.limit:
            raise ForceLimitExceeded(magnitude, self.limit, self.phase)

    def force_noise(self) -> float:
        """The F/T force noise now: the rms over the axes of the raw force's spread over the last
        ``noise_samples`` ticks [N] (0 before there are 10)."""
        if len(self._raw_forces) < 10:
            return 0.0
        return float(np.sqrt(np.mean(np.var(np.array(self._raw_forces), axis=0))))

    def filter_samples(self, noise: float) -> int:
        """Ticks in the running median of the wrench for an F/T force noise ``noise`` [N, rms per axis]:
        ``force_filter_samples``, or as many as keep the median's noise under ``filtered_noise``."""
        c = self.config
        needed = math.ceil((_MEDIAN_SPREAD * noise / c.sensing.filtered_noise) ** 2)
        return max(c.sensing.force_filter_samples, min(needed, c.sensing.force_filter_max_samples))

    def filtered_noise_now(self) -> float:
        """The noise of the filtered force in the toggle in progress [N per axis]: the F/T force noise measured
        above the part through the running median of its length."""
        return _MEDIAN_SPREAD * self.rest_noise / math.sqrt(self._force_window.maxlen or 1)

    def tare_samples(self, noise: float) -> int:
        """Readings a tare averages for an F/T force noise ``noise`` [N, rms per axis]: ten, or as many as keep
        the tare's error under ``tare_noise``."""
        c = self.config
        return max(TARE_SAMPLES, min(math.ceil((noise / c.sensing.tare_noise) ** 2), c.sensing.tare_max_samples))

    def _clip(self, q: np.ndarray) -> np.ndarray:
        """``q`` within the servo ranges [rad] (``np.clip`` for finite ``q``, without its dispatch layers)."""
        low, high = self._joint_limits
        return np.minimum(np.maximum(q, low), high)

    def _wait_tick(self) -> None:
        self.robot.wait(self.config.motion.tick)
        self._sense()

    # -- motion ------------------------------------------------------------------------------------
    def _tick(self, target: np.ndarray) -> tuple[float, float]:
        q, position_error, orientation_error = self.ik.step_towards(target, self.config.motion.ik_iterations_per_tick)
        self.robot.command_joint_positions(self._clip(q))
        self._wait_tick()
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
            self._tick(waypoint)
        for _ in range(round(self.config.motion.settle_time / self.config.motion.tick)):
            position_error, orientation_error = self._tick(target)
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

    def _joint_move(self, q_goal: np.ndarray, duration: float) -> None:
        """Interpolate the joints to ``q_goal`` [rad] over ``duration`` [s] (no IK: always feasible)."""
        start = self.robot.joint_positions()
        ticks = max(1, round(duration / self.config.motion.tick))
        for k in range(1, ticks + 1):
            s = k / ticks
            s = s * s * (3 - 2 * s)
            self.robot.command_joint_positions(self._clip((1 - s) * start + s * q_goal))
            self._wait_tick()

    def _gripper(self, closure: float, duration: float) -> None:
        self.robot.command_gripper(closure)
        ticks = round(duration / self.config.motion.tick)
        for _ in range(ticks):
            self._tick(self.ik.tcp_pose())

    def _close_slowly(self, settle: bool = False) -> np.ndarray:
        """Ramp the gripper command from its pre-grasp closure to fully closed at ``close_speed``, then
        hold for ``close_time`` while the grip builds, the wrist yielding along the closing axis to a load there
        (``grasp_centre_force``) and, with ``settle``, once closed, across it too (``comply_deadband``). Returns how
        far it yielded [m, base frame]: where the handle was found to be beside where it was aimed."""
        c = self.config
        ramp = max(1, round((1.0 - c.approach.pregrasp_closure) / c.grasp.close_speed * self.slowdown / c.motion.tick))
        hold = self.ik.tcp_pose()
        axis = hold[:3, 1].copy()  # the fingers close along the TCP's y axis (skills.kinematics.top_down)
        shift = 0.0
        # once closed on a handle the pads push along its motion (a slide's, a wheel's, a drawer's), the hand also
        # yields across the closing axis, as a door's path does (:meth:`_yield_across`): a handle gripped a few
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
                settled = self._yield_across(settled, axis)
            shift = self._centring(shift, axis)
            if shift == 0.0 and not settled.any():  # (the aimed pose itself, to the bit, while nothing pushes)
                self._tick(hold)
            else:
                shifted = hold.copy()
                shifted[:3, 3] += shift * axis + settled
                self._tick(shifted)
        return shift * axis + settled

    def _centring(self, shift: float, axis: np.ndarray) -> float:
        """The hand's offset ``shift`` [m] along the closing ``axis`` (unit, base frame) moved along the filtered
        load on that axis above ``grasp_centre_force`` (or the noise margin), at ``comply_gain``, within
        ``grasp_centre_limit``."""
        c = self.config
        load = float(self.force_in_base @ axis)
        deadband = max(c.grasp.grasp_centre_force, c.motion.comply_noise_margin * self.rest_noise)
        if abs(load) <= deadband:
            return shift
        shift += c.motion.comply_gain * c.motion.tick * math.copysign(abs(load) - deadband, load)
        return max(-c.grasp.grasp_centre_limit, min(c.grasp.grasp_centre_limit, shift))

    # -- the toggle --------------------------------------------------------------------------------
    def grasp_yaw(self, jm: JointModel) -> float:
        """Yaw of the gripper (the kind's ``Handling.grasp``). Slides and wheels: the fingers close along
        the handle's (horizontal) direction of motion, so the pads push it. Doors: along the hinge axis, so the
        handle pivots between the pads like a pin as the door swings and the gripper need not tilt 85 degrees
        (tilting with it folded the arm onto itself)."""
        direction = jm.axis if jm.handling.grasp == "along_axis" else jm.motion_direction(0.0)
        return float(np.arctan2(direction[1], direction[0]) + np.pi / 2)

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
        self.cautious = cautious
        self.careful = careful
        ahead = None if stands_at is None or jm.handling.swings_up else (stands_at if opening else 1.0 - stands_at)
        self.head_start = 0.0 if ahead is None else min(max(ahead, 0.0), MAX_HEAD_START)
        self.lean = lean
        start_time = self.robot.time
        self.reset_force_watch()
        c = self.config
        pushable = jm.handling.swings_up and c.door_push
        covered = None if door_at is None else (door_at if opening else 1.0 - door_at)
        if pushable and opening and raised:
            result = self._attempt(lambda: self._top_up_door(jm))
        elif pushable and (
            push or (not opening and c.push.close_by_push) or (covered or 0.0) >= c.judgement.blocked_progress
        ):
            result = self._push_on(jm, opening, 0.0 if covered is None else covered, where_is)
        else:
            result = self._attempt(lambda: self._toggle(jm, 1.0 if opening else -1.0))
            empty = result.cause is Cause.GRASP_EMPTY
            if pushable and opening and result.outcome == "moved" and not result.end_stop_felt and c.push.top_up:
                self._attempt(lambda: self._top_up_door(jm))  # best effort: the pinch's verdict stands
            if pushable and result.cause in PADS_LOST_HOLD:
                # the pads could not hold the handle: push the door instead, in the same try, from where it stands
                covered = self._push_start(result, opening, where_is)
                if covered is not None:
                    result = self._push_on(jm, opening, covered, where_is)
                elif result.progress < c.judgement.moved_fraction:  # (past it, the world looks whether it moved)
                    result.reason += "; the door stands part-way where it cannot be seen: not pushed"
                    result.not_pushed = True
            result.closed_on_nothing = empty
        result.peak_force = self.peak_force  # over the whole try, withdrawal included
        result.sim_time = self.robot.time - start_time
        result.wall_time = time.perf_counter() - wall
        return result

    def _push_on(
        self,
        jm: JointModel,
        opening: bool,
        covered: float,
        where_is: collections.abc.Callable[[], float | None] | None = None,
    ) -> ToggleResult:
        """:meth:`_push`, and an opening push that lost the handle's face short of the travel (``IncompleteTravel``:
        under the harsh profile's perception error the pad drifted off a post at 62 deg) followed by a top-up
        under the plate (:meth:`DoorPushing._top_up_door`) if ``where_is`` does not see the door (above ~50 deg
        its handle hides its marker), whose verdict then stands (the world checks a ``moved`` against the
        marker). A door seen lower is left to a retry's push from where it stands: under a plate that low
        the top-up's pads pass over it and read "moved"."""
        result = self._push(jm, opening, covered)
        if opening and self.config.push.top_up and result.cause is Cause.INCOMPLETE_TRAVEL:
            if where_is is not None and where_is() is not None:
                return result
            topped = self._attempt(lambda: self._top_up_door(jm))
            if topped.outcome == "moved":
                return topped
            result.reason += f"; pushed on under its plate: {topped.reason}"
            result.pushed_on = topped
        return result

    def _push(self, jm: JointModel, opening: bool, covered: float) -> ToggleResult:
        """Push door ``jm`` open or shut from where it stands, ``covered`` (fraction of this motion's travel),
        beginning ``push.start_margin`` behind it: a door let go part-way falls back ~1 deg while the arm
        comes round, and behind the handle the pad only sits higher on the post (~1.7 mm per deg)."""
        c = self.config
        start = min(max(covered - c.push.plan.start_margin, 0.0), c.judgement.moved_fraction)
        push = self._push_door_open if opening else self._push_door_closed
        return self._attempt(lambda: push(jm, start))

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
        self.progress = 0.0
        try:
            return motion()
        except (IKFailure, GraspFailure, SlipDetected, ForceLimitExceeded) as err:
            result = ToggleResult(
                "failed", reason=f"{type(err).__name__}: {err}", progress=self.progress, cause=err.cause,
                stopped_while=err.phase if isinstance(err, ForceLimitExceeded) else "",
            )  # fmt: skip
            self.withdraw()
            return result

    def _descend_to(self, target: np.ndarray) -> None:
        """Open to the pre-grasp closure, travel above ``target`` (4x4; :meth:`_approach`), tare the F/T there and
        descend onto it."""
        c = self.config
        # the lift off this part goes back the same way: a pinch's lean, not a push's upright pads after it
        self._lean_drift = target[:3, 2] / target[2, 2]
        self._lean_drift[2] = 0.0
        self.robot.command_gripper(c.approach.pregrasp_closure)
        self.phase = "approaching"
        height = self._approach(target)
        self.rest_noise = self.force_noise()  # coming to rest above the part
        self.robot.tare(self.tare_samples(self.rest_noise))  # fingers open, arm still: the gripper's load alone
        # older samples were taken with another zero; the window is as long as this noise needs
        samples = self.filter_samples(self.rest_noise)
        self._force_window = collections.deque(maxlen=samples)
        self.slowdown = samples / c.sensing.force_filter_samples / (c.actuation.careful_pace if self.careful else 1.0)
        self.phase = "descending"
        if self.cautious:  # the whole way slowly, under the light touch
            slow = c.approach.cautious_descend_time * height / c.approach.approach_height
        else:
            # quickly down to where the fingers could first meet a handle they were aimed beside, then slowly, so
            # that one met (a wrong perception or calibration) stops the arm at a light touch: the try fails, not
            # the part
            near = target.copy()
            near[:3, 3] -= c.approach.touch_height * target[:3, 2]
            self.move_to(
                near,
                c.approach.descend_time
                * (height - c.approach.touch_height)
                / c.approach.approach_height
                * self.slowdown,
            )
            slow = c.approach.touch_height / c.approach.touch_speed
        self.limit = max(c.approach.cautious_contact_force, c.approach.cautious_noise_margin * self.rest_noise)
        try:
            self.move_to(target, slow * self.slowdown, smooth=False)
        finally:
            self.limit = c.sensing.force_limit

    def _approach(self, target: np.ndarray) -> float:
        """Travel to above ``target`` (4x4) along its approach axis (up, when upright) and return how high above it
        [m]: ``approach_height``, or, where that point stands within ``base_radius`` of the vertical axis of the
        arm's base, ``base_rise``, reached at that height from ``base_radius`` out and moving in horizontally (the
        way :meth:`_out_from_base` leaves): the arm reaches there folded over its own shoulder, and every route to 8
        cm above a drawer's handle 0.176 m from the axis put the gripper's knuckle on link 2 (101-137 N, 17 mm deep in
        the robot model); arriving 3.5 cm above it from outside kept 3-6 mm of clearance, more on the way down."""
        c = self.config
        above = target.copy()
        above[:3, 3] -= c.approach.approach_height * target[:3, 2]
        radius = math.hypot(above[0, 3], above[1, 3])
        if not 1e-6 <= radius < c.approach.base_radius:
            self.travel_to(above, c.approach.approach_time)
            return c.approach.approach_height
        height = max(c.approach.base_rise, c.approach.touch_height)
        above[:3, 3] = target[:3, 3] - height * target[:3, 2]
        out = above.copy()
        _out_to_radius(out, c.approach.base_radius)
        self.travel_to(out, c.approach.approach_time)
        self.move_to(above, c.retreat.retreat_time)
        return height

    def _toggle(self, jm: JointModel, sign: float) -> ToggleResult:
        c = self.config
        begin = 0.0 if sign > 0 else 1.0
        grasp_yaw = self.grasp_yaw(jm)
        at_grasp = self._leaning(top_down(jm.grasp_point_at(begin), grasp_yaw))
        self._descend_to(at_grasp)
        self.phase = "grasping"
        found = self._close_slowly(settle=jm.handling.grasp == "across_motion")
        if found.any():  # the handle stands that far beside where it was aimed: the path starts from it
            jm = replace(jm, origin=jm.origin + found, grasp_point=jm.grasp_point + found)
            at_grasp = at_grasp.copy()
            at_grasp[:3, 3] += found
        grasp_closure = self.robot.gripper_opening()
        self._closures.clear()
        self._closures.append(grasp_closure)
        if grasp_closure >= c.judgement.empty_grasp_closure:
            raise GraspFailure(f"the gripper closed on nothing at {np.round(at_grasp[:3, 3], 3).tolist()}")

        self.phase = "actuating"
        result = self._actuate(jm, sign, begin, at_grasp)
        self.phase = "retreating"
        self._let_go_and_retreat()
        self.phase = "moving"
        return result

    def _actuate(self, jm: JointModel, sign: float, begin: float, at_grasp: np.ndarray) -> ToggleResult:
        c = self.config
        along_post = float(sign * jm.motion_direction(begin) @ at_grasp[:3, 2])  # cosine to the approach axis
        pressed = along_post > math.cos(c.actuation.press_angle)
        # pulled up along its post (``press_force``), but not from a head start of MAX_HEAD_START: a part seen that far
        # along is not where its state says, and may be lifted into its stop
        pulled = (
            along_post < -math.cos(c.actuation.press_angle)
            and not jm.handling.swings_up
            and self.head_start < MAX_HEAD_START
        )
        slowdown = self.slowdown
        if pressed:  # at press_pace at the most (a careful toggle may already go slower)
            slowdown *= max(1.0, (c.actuation.careful_pace if self.careful else 1.0) / c.actuation.press_pace)
        ticks = round(c.actuation.actuate_time * slowdown / c.motion.tick)
        forces: list[float] = []
        progress = 0.0
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
        last_tick = pacing.ticks_to(1.0 + 2 * (end - 1.0))
        progress_at_peak = 0.0
        in_end_stop = False  # felt the door reach its end stop: open, whatever the pads do next
        across = np.zeros(3)  # the path's offset across itself, yielding to the load there [m, base frame]
        yields = jm.handling.yields_across
        held_along = None if jm.handling.axis_yield == 1.0 else jm.axis  # (a load along it: yielded to in part)
        axis_yield = jm.handling.axis_yield
        returning = 1.0 - c.motion.tick / c.motion.comply_return_time  # the offset kept per tick past the travel
        window = max(2, round(c.judgement.stall_window * slowdown / c.motion.tick))
        press_limit = (
            max(c.judgement.press_force, c.judgement.press_noise_margin * self.filtered_noise_now())
            if pressed or pulled
            else math.inf
        )
        recent: collections.deque[float] = collections.deque(maxlen=window)  # progress over the last stall_window
        self.ik.set_joints(self.robot.joint_positions())
        for k in range(1, last_tick + 1):
            paced = pacing.at(k)
            paced = paced if paced <= 1.0 else 1.0 + 0.5 * (paced - 1.0)  # past the travel at half pace
            s = min(end, paced, max(progress, 0.0) + lead)
            fraction = begin + sign * s
            target = self._pose_along(jm, fraction, at_grasp, begin)
            target[:3, 3] += across
            self._tick(target)
            direction = sign * jm.motion_direction(fraction)
            opposing = float(-np.dot(self.force_in_base, direction))
            if yields:  # once the end stop is felt, back to the planned arc: its load tells the door is open
                if s <= 1.0 or (c.actuation.overtravel_comply and not in_end_stop):
                    across = self._yield_across(across, direction, held_along, axis_yield)
                else:
                    across = across * returning
            forces.append(opposing)
            progress = self.progress = self._progress(jm, sign, begin)
            if opposing >= max(forces):
                progress_at_peak = progress
            try:
                self._check_grip(progress)
            except SlipDetected:
                if progress_at_peak < c.judgement.blocked_progress and max(forces) >= c.judgement.push_force:
                    # the part held while pulled until the pads slid off its handle: a latch, not a slip
                    return ToggleResult("blocked", SLIPPED_OFF, progress, max(forces),
                                        forces=forces, cause=Cause.LOCKED_SLIPPED_OFF)  # fmt: skip
                if in_end_stop:  # the pads slid off a post pressed into its end stop: the door is open
                    return ToggleResult("moved", "", progress, max(forces), forces=forces, end_stop_felt=True)
                raise
            magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
            in_end_stop = in_end_stop or (s > 1.0 and magnitude > c.judgement.end_stop_force)
            if s > 1.0 and magnitude > c.actuation.overtravel_force:  # past the travel and pushing hard: stop here
                end = max(1.0, min(progress, s))
            held = opposing > press_limit and s <= 1.0  # a handle pressed along its post: held at a light force
            if (
                opposing > c.judgement.blocked_force or magnitude > c.judgement.blocked_magnitude or held
            ) and progress < c.judgement.blocked_progress:
                self._take_back(functools.partial(self.move_to, at_grasp, 0.5))  # back to where the handle was grasped
                return ToggleResult(
                    "blocked", LATCHED[Cause.LOCKED_NO_PROGRESS], progress, max(forces), forces=forces,
                    cause=Cause.LOCKED_NO_PROGRESS,
                )  # fmt: skip
            recent.append(progress)
            stalled = len(recent) == recent.maxlen and progress - recent[0] < c.judgement.stall_progress
            held = held or (stalled and opposing > c.judgement.stall_force and s <= 1.0)
            if held and progress + self.head_start >= c.judgement.moved_fraction:
                end = max(progress, 0.0)  # at its stop short of the perceived travel: pushed no further
                break
            if held:  # (progress >= blocked_progress: tested above)
                self._take_back(functools.partial(self._return_along, jm, sign, begin, progress, at_grasp, across))
                return ToggleResult(
                    "blocked", f"{HELD_PART_WAY} ({progress:.0%} of the travel)", progress, max(forces), forces=forces,
                    cause=Cause.HELD_PART_WAY, held_at=progress,
                )  # fmt: skip
        for _ in range(round(2 * c.motion.settle_time / c.motion.tick)):  # let the part catch up with the end target
            progress = self.progress = self._progress(jm, sign, begin)
            target = self._pose_along(jm, begin + sign * min(end, max(progress, 0.0) + lead), at_grasp, begin)
            target[:3, 3] += across
            self._tick(target)
            try:
                self._check_grip(progress)
            except SlipDetected:
                if not in_end_stop:
                    raise
                break
        reached = self._progress(jm, sign, begin) + self.head_start
        result = self._verdict(reached, forces, Cause.LOCKED_PULLED)
        result.end_stop_felt = in_end_stop
        if result.outcome == "blocked":
            self._take_back(functools.partial(self.move_to, at_grasp, 0.5))
        return result

    def _take_back(self, motion: collections.abc.Callable[[], None]) -> None:
        """Run ``motion``, a held handle's way back to where it was grasped, under ``back_off_force``: stopped there,
        the arm backs off along the load (:meth:`_relieve`) and sets out once more; stopped again, it stays backed
        off (the try's verdict stands). The load of the hold still rises for a few ticks after it is read (the
        filter's lag): a wheel held at 35-40 N had its way back stopped on the second tick and was left at 27 % of
        its travel, where its next try began with the hand believing it closed (it met its stop at 73 % of the way
        and read held part-way)."""
        limit = self.limit
        self.limit = min(limit, self.config.actuation.back_off_force)
        try:
            for _ in range(2):  # (once more after backing off)
                try:
                    motion()
                    return
                except ForceLimitExceeded:
                    self.guard = False
                    try:
                        self._relieve()
                    finally:
                        self.guard = True
        finally:
            self.limit = limit

    def _return_along(
        self, jm: JointModel, sign: float, begin: float, covered: float, at_grasp: np.ndarray, across: np.ndarray
    ) -> None:
        """Take a handle held part-way, ``covered`` of the travel from ``begin``, back along its path to where it
        was grasped (``at_grasp``; ``across``: the path's offset, let go on the way) over ``release_time`` per 10 %
        of the travel: a straight line cuts a hinge's arc."""
        c = self.config
        ticks = max(1, round(c.motion.release_time * max(covered, 0.0) / 0.1 / c.motion.tick))
        for k in range(1, ticks + 1):
            left = 1.0 - k / ticks
            target = self._pose_along(jm, begin + sign * covered * left, at_grasp, begin)
            target[:3, 3] += across * left
            self._tick(target)

    def _yield_across(
        self, across: np.ndarray, direction: np.ndarray, held_along: np.ndarray | None = None, share: float = 1.0
    ) -> np.ndarray:
        """The path's offset ``across`` [m] moved along the filtered force's component across the direction of
        motion ``direction`` (unit, base frame), at ``comply_gain`` per newton above a deadband
        (``comply_deadband``, ``comply_noise_margin``), within ``comply_limit``: a path planned from a slightly
        wrong hinge pulls the handle across its true arc, which the part resists with no motion, and only the
        load along the motion tells a latch. ``held_along``: a unit axis along which only ``share`` of the load is
        yielded to (``Handling.axis_yield``)."""
        c = self.config
        force = self.force_in_base
        load = force - float(force @ direction) * direction
        if held_along is not None:  # only in part along this (unit) axis, where the part holds the handle in the pads
            load = load - (1.0 - share) * float(load @ held_along) * held_along
        size = math.sqrt(load @ load)
        deadband = max(c.motion.comply_deadband, c.motion.comply_noise_margin * self.rest_noise)
        if size <= deadband:
            return across
        across = across + (c.motion.comply_gain * c.motion.tick * (size - deadband) / size) * load
        length = math.sqrt(across @ across)
        return across if length <= c.motion.comply_limit else across * (c.motion.comply_limit / length)

    def _verdict(self, progress: float, forces: list[float], latched: Cause | None = None) -> ToggleResult:
        """How a motion that ran its course ended: ``moved`` past ``moved_fraction`` of the travel; ``blocked``
        (cause ``latched``, when given) short of ``blocked_progress`` after at least ``push_force`` against
        the motion (``forces`` [N], one per tick); else ``failed``."""
        c = self.config
        peak = max(forces)
        if progress >= c.judgement.moved_fraction:
            return ToggleResult("moved", "", progress, peak, forces=forces)
        if latched is not None and progress < c.judgement.blocked_progress and peak >= c.judgement.push_force:
            return ToggleResult("blocked", LATCHED[latched], progress, peak, forces=forces, cause=latched)
        return ToggleResult(
            "failed", f"{INCOMPLETE_TRAVEL}: only {progress:.0%} of the travel covered", progress, peak, forces=forces,
            cause=Cause.INCOMPLETE_TRAVEL,
        )  # fmt: skip

    def _check_grip(self, progress: float) -> None:
        closure = self.robot.gripper_opening()
        self._closures.append(closure)
        if (
            closure >= self.config.judgement.empty_grasp_closure
            or closure > min(self._closures) + self.config.judgement.slip_closure_rise
        ):
            raise SlipDetected(f"the handle slipped out of the grasp after {progress:.0%} of the travel")

    def _leaning(self, upright: np.ndarray) -> np.ndarray:
        """``upright`` (a top-down TCP pose, 4x4) turned by ``lean_angle`` about its closing axis (y) so that the
        gripper's upper part leans along :attr:`lean`'s component across that axis; unchanged without a lean,
        or when the lean lies along the closing axis (turning the pads off the handle's faces would not do)."""
        if self.lean is None or self.config.approach.lean_angle == 0.0:
            return upright
        strength = float(np.linalg.norm(self.lean))
        closing = upright[:3, 1]
        across = self.lean - float(self.lean @ closing) * closing
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

    def _pose_along(self, jm: JointModel, fraction: float, at_grasp: np.ndarray, begin: float) -> np.ndarray:
        T = at_grasp.copy()
        T[:3, 3] = jm.grasp_point_at(fraction)
        if jm.joint == "hinge" and abs(jm.axis[2]) > 0.9:  # wheels: the gripper turns with the knob
            turn = Rotation.from_rotvec(jm.axis * (fraction - begin) * jm.travel).as_matrix()
            T[:3, :3] = turn @ at_grasp[:3, :3]
        return T

    def _progress(self, jm: JointModel, sign: float, begin: float) -> float:
        """Measured fraction of the travel covered towards the other state, from the TCP position."""
        return sign * jm.fraction_between(jm.grasp_point_at(begin), self.robot.tcp_pose_in_base()[:3, 3])

    def withdraw(self) -> None:
        """After a stop: back off along the load, open the gripper, move up and go to rest with the force
        guard off (the load that tripped it is what the withdrawal relieves). Backing off first matters for
        a pad pressed on a part: held where it stopped while the gripper opens, a stuck door kept 170 N on
        the wrist for half a second."""
        self.guard = False
        try:
            self._relieve()
        finally:
            self.guard = True
        self._let_go_and_retreat(guarded=False)

    def _relieve(self) -> None:
        """Move up to ``relieve_distance`` along the load, stopping once the load along that way has fallen
        below ``relieve_load``: with the fingers still closed on a handle that jammed, the whole 5 mm carried the
        arm past where the load vanished and pushed the handle the other way (70 N, then 148 N, reversed)."""
        c = self.config
        load = math.sqrt(self.force_in_base @ self.force_in_base)
        if load <= c.motion.relieve_load:
            return
        along = self.force_in_base / load
        start = self.robot.tcp_pose_in_base()
        self.ik.set_joints(self.robot.joint_positions())
        ticks = max(1, round(c.motion.release_time / c.motion.tick))
        for k in range(1, ticks + 1):
            s = k / ticks
            target = start.copy()
            target[:3, 3] += c.motion.relieve_distance * s * s * (3 - 2 * s) * along
            self._tick(target)
            if float(self.force_in_base @ along) < c.motion.relieve_load:
                return

    def _let_go_and_retreat(self, guarded: bool = True) -> None:
        """Open, move up and go to rest; a force stop on the way withdraws unguarded."""
        try:
            self.guard = guarded
            self._retreat_moves()
        except ForceLimitExceeded:
            self.guard = False
            self._retreat_moves()
        finally:
            self.guard = True

    def _retreat_moves(self) -> None:
        """Open gently to the pre-grasp closure (wide enough to let the 12 mm post go; fully open, the ~8 cm
        fingers caught neighbouring parts on the way up), lift, and go to rest."""
        c = self.config
        self._open_gently(c.approach.pregrasp_closure)
        try:
            self.ik.set_joints(self.robot.joint_positions())
            self._lift_clear(c.approach.approach_height)
        except IKFailure:
            pass  # already as high as the arm goes
        self._interpolate_to_rest()

    def _lift_clear(self, height: float) -> None:
        """Lift the open gripper by ``height`` [m], stopping at a light touch (``lift_contact_force``); on one,
        back off, step ``lift_sidestep`` along the pads (the TCP's x: parallel to the handle between them, which
        the step then never pushes), first to the side the load pushed towards, then to the other, and lift
        again. Withdrawing (guard off), or when neither side clears, the lift runs under the full guard. Near the
        base's axis it first moves out from it (:meth:`_out_from_base`)."""
        c = self.config
        bottom = self.robot.tcp_pose_in_base()[2, 3]
        top = bottom + height
        if self.guard:
            limit = self.limit
            self.limit = max(c.retreat.lift_contact_force, c.retreat.lift_noise_margin * self.filtered_noise_now())
            origin, away = None, np.zeros(3)
            try:
                for side in (0.0, 1.0, -1.0):
                    try:
                        if side:
                            assert origin is not None  # the first try (side 0) ended in a touch
                            self._step_along_pads(origin, side * away)
                        up = self.robot.tcp_pose_in_base()
                        self._rise(up, min(up[2, 3] + c.retreat.lift_slow_height, top))
                        self.move_to(up, c.retreat.lift_slow_time)
                        self._out_from_base(up, bottom, top)
                        self._rise(up, top)
                        self.move_to(up, c.retreat.retreat_time)
                        return
                    except ForceLimitExceeded:
                        if origin is None:  # which way the first touch pushed, before backing off from it
                            away = self.force_in_base.copy()
                        self.guard = False
                        try:
                            self._relieve()
                        finally:
                            self.guard = True
                        if origin is None:
                            origin = self.robot.tcp_pose_in_base()[:3, 3].copy()
            finally:
                self.limit = limit
        up = self.robot.tcp_pose_in_base()
        self._out_from_base(up, bottom, top)
        self._rise(up, top)
        self.move_to(up, c.retreat.retreat_time)

    def _out_from_base(self, pose: np.ndarray, bottom: float, top: float) -> None:
        """If ``pose`` (4x4, the lift's target so far; moved in place) stands within ``base_radius`` of the vertical
        axis of the arm's base, rise to ``base_rise`` above ``bottom`` (where the lift began; at most ``top``) [m]
        and move out horizontally to ``base_radius``: the arm reached there folded over its own shoulder."""
        c = self.config
        radius = math.hypot(pose[0, 3], pose[1, 3])
        if radius >= c.approach.base_radius or radius < 1e-6:
            return
        if pose[2, 3] < min(bottom + c.approach.base_rise, top):
            self._rise(pose, min(bottom + c.approach.base_rise, top))
            self.move_to(pose, c.retreat.lift_slow_time)
        _out_to_radius(pose, c.approach.base_radius)
        self.move_to(pose, c.retreat.retreat_time)

    def _open_gently(self, closure: float) -> None:
        """Ramp the gripper's command open to ``closure`` at ``gentle_release_speed`` (slowed with the motions in
        contact); a filtered force that rises past the lift's light touch (``lift_contact_force``, or
        ``lift_noise_margin`` times the filtered noise) above its value at the start holds the command, and the arm
        backs off along the load before they open on (three times; at a fourth touch the fingers stay where they
        are): a finger opening under the plate of a door standing open over the part presses into it with the
        gripper's whole force."""
        c = self.config
        touch = max(c.retreat.lift_contact_force, c.retreat.lift_noise_margin * self.filtered_noise_now())
        touch += math.sqrt(self.force_in_base @ self.force_in_base)  # the handle's load, gone once let go
        step = c.retreat.gentle_release_speed * c.motion.tick / self.slowdown
        command = self.robot.gripper_opening()
        touches = 0
        while command > closure:
            command = max(closure, command - step)
            self.robot.command_gripper(command)
            self._tick(self.ik.tcp_pose())
            if math.sqrt(self.force_in_base @ self.force_in_base) > touch:
                if touches == 3:  # let go as far as there is room: the lift steps aside from what stops it
                    self.robot.command_gripper(self.robot.gripper_opening())
                    return
                touches += 1
                # the command held, no harder: the finger opens on as the arm backs off, until the load is gone
                guard, self.guard = self.guard, False
                try:
                    self._relieve()
                finally:
                    self.guard = guard

    def _rise(self, pose: np.ndarray, height: float) -> None:
        """Raise ``pose`` (4x4, in place) to ``height`` [m] along the approach axis of a leaning gripper (straight
        up when upright): back the way it came down, its upper part clear of what it leans away from."""
        if self._lean_drift.any():
            pose[:3, 3] += (height - pose[2, 3]) * self._lean_drift
        pose[2, 3] = height

    def _step_along_pads(self, origin: np.ndarray, away: np.ndarray) -> None:
        """Move the TCP to ``lift_sidestep`` from ``origin`` (base frame [m]) along its x axis, on the side of
        ``away`` (a load's direction: it points from what was met), at its present height."""
        pose = self.robot.tcp_pose_in_base()
        along = pose[:3, 0].copy()
        along[2] = 0.0
        along /= np.linalg.norm(along)
        target = pose.copy()
        target[:3, 3] = origin + math.copysign(self.config.retreat.lift_sidestep, float(away @ along)) * along
        target[2, 3] = pose[2, 3]
        self.move_to(target, self.config.retreat.retreat_time)

    def go_rest(self) -> None:
        """Back to the rest posture by joint interpolation (no IK: always feasible); a force stop on the
        way withdraws upwards first."""
        try:
            self._interpolate_to_rest()
        except ForceLimitExceeded:
            self.withdraw()

    def _interpolate_to_rest(self) -> None:
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
                self.move_to(via, c.retreat.lift_time)
            via[:3, 3] = (*c.motion.transit_xy, max(via[2, 3], c.motion.transit_height))
            self.move_to(via, c.retreat.lift_time)
        except IKFailure:
            pass  # as far as the arm goes: interpolate from here
        self._joint_move(np.asarray(self.rest_posture), c.retreat.rest_time)
        self.robot.wait(c.motion.settle_time)
