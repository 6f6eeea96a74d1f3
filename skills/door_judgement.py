"""The judgement of a door's pushes: what their readings tell, as pure folds of them (the pinch's is in
:mod:`skills.judgement`).

- the opening *swing* (:class:`SwingJudge`): a pad pressed on the back face of the handle, swung along the door's arc;
  per tick it reads the pad's progress, the angle of the face it presses on, the load on that face, the load against
  the motion and the load's magnitude (:class:`SwingReading`). Held part-way (the face stopped turning with the pad
  past ``blocked_progress``), the pad sliding along a face that does not turn (latched; jammed if the door stood
  part-way open), or pushed in vain: blocked; else, once the swing ran its course, where the face last turned with
  the pad tells how far the door went;
- the *closing* push (:class:`ClosingJudge`): the pads' edges on the plate, followed down its arc; the plate met on
  the lid ends it, a plate that does not give short of ``blocked_progress`` after the pads first pressed on it is a
  latch.

Each judge is fed tick by tick by :class:`skills.door_push.DoorPusher`, which obeys it; :func:`judge_swing` and
:func:`judge_closing` fold a recorded push through the same judge offline.
"""

from __future__ import annotations

import collections
import math
from dataclasses import dataclass

from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.judgement import Judgement, verdict
from puzzlebox.skills.settings import DoorPushJudgement, JudgementConfig


@dataclass(frozen=True)
class SwingReading:
    """What an opening swing reads at one control tick."""

    progress: float
    """The pad's turn about the hinge since the start, the climb up the face taken out [fraction of the travel]."""
    face: float
    """The angle of the face the pad rests on, from the contact's geometry [fraction of the travel]."""
    normal: float
    """Filtered wrist load pressing the pad on the face [N]."""
    opposing: float
    """Filtered wrist load against the motion [N]."""
    magnitude: float
    """Filtered wrist load's magnitude [N]."""


@dataclass(frozen=True)
class SwingLimits:
    """The per-push constants of a swing's judgement."""

    start: float
    """Where the door stood when the push began [fraction of the travel]."""
    contact: float
    """Load on the face that means pressed on it [N] (``contact_force``, or the noise's margin)."""
    held_turn: float
    """``held_turn`` as a fraction of the travel."""
    slide_turn: float
    """``slide_turn`` as a fraction of the travel."""
    window: int
    """Ticks over which a stall is measured."""


class SwingJudge:
    """The judgement of one opening swing, fed tick by tick (:meth:`read`), pure in its readings."""

    def __init__(self, judgement: JudgementConfig, push: DoorPushJudgement, limits: SwingLimits) -> None:
        self.judgement, self.push, self.limits = judgement, push, limits
        self.forces: list[float] = []
        """Load against the motion at each tick [N]."""
        self.peak = -math.inf
        """The largest of :attr:`forces` [N]."""
        self.readings: list[SwingReading] = []
        self.pressed_at: tuple[float, float] | None = None
        """(progress, face) when the pad first pressed on the face."""
        self.last_pressed = (limits.start, 0.0)
        """(progress, face) when the pad last pressed on the face."""
        self.track: collections.deque[tuple[float, float]] = collections.deque()
        """(progress, face) pressed, tick after tick (cleared when the pad lifts off the face)."""

    def read(self, r: SwingReading) -> Judgement | None:
        """One tick of the swing: blocked (the pad is then backed off the face), or None: go on."""
        c, lim = self.judgement, self.limits
        self.readings.append(r)
        self.forces.append(r.opposing)
        self.peak = max(self.peak, r.opposing)  # max(self.forces), kept as it grows
        if r.normal > lim.contact:
            self.last_pressed = (r.progress, r.face)
            if self.pressed_at is None:
                self.pressed_at = (r.progress, r.face)
            self.track.append((r.progress, r.face))
        else:
            self.track.clear()  # (the turn over which the pad slid is measured pressed all the while)
        pressed_at, peak = self.pressed_at, self.peak
        if self.track and pressed_at is not None and self.held_part_way(pressed_at[1], r.normal):
            # where it stands: the face's turn since the pad first pressed on it, from where the door stood then
            # (the face's own reading carries the perception's offset: 1 mm of it is ~3 deg)
            held_at = lim.start + r.face - pressed_at[1]
            return Judgement("blocked", Cause.HELD_PART_WAY, r.progress, peak, held_at=held_at)
        slid = pressed_at is not None and r.progress - pressed_at[0] >= lim.slide_turn
        if slid and pressed_at is not None and r.face - pressed_at[1] < 0.5 * (r.progress - pressed_at[0]):
            if lim.start >= c.blocked_progress:  # a door held part-way open is stuck, not latched: no evidence
                return Judgement("failed", Cause.JAMMED, r.progress, peak, held_at=lim.start)
            return Judgement("blocked", Cause.LOCKED_PAD_SLID, r.progress, peak)
        pressed_hard = r.normal > self.push.blocked_force or r.magnitude > c.blocked_magnitude
        if pressed_hard and r.progress < c.blocked_progress:
            return Judgement("blocked", Cause.LOCKED_PUSHED, r.progress, peak)
        jammed = r.normal > self.push.jam_force or pressed_hard
        if jammed and lim.start >= c.blocked_progress and r.progress - lim.start < c.blocked_progress:
            # a door that stood part-way and will not go on: stuck, or its lock's rod at its wall. Judged only where
            # it stood (as the slide test judges it) the push went on, and without a calibration file it pressed a
            # door held at 27 % with 48-55 N until the pad slipped off (24 of 251 recorded swings, 40-60 N)
            return Judgement("failed", Cause.JAMMED, r.progress, peak, held_at=lim.start)
        return None

    def held_part_way(self, first_face: float, normal: float) -> bool:
        """Whether the door stopped part-way against the push (a lock's rod at its wall), the pad pressed on its face
        over :attr:`track` (ticks older than ``held_turn`` of the pad's travel are dropped): after the face had turned
        with the pad past ``blocked_progress`` of the travel since it first pressed (at ``first_face``), short of
        ``moved_fraction``, either the pad slid along the face over ``held_turn`` while the face turned less than half
        as much, or the face stood still (``stall_progress`` over the stall window) with ``normal`` [N] on it above
        ``stall_force`` (the pad, held back by its lead, turns slowly along a face that does not give: a door held at
        27 % was pressed with 51 N before it had slid 3 deg). A face that never turned is a latch or a jam, judged by
        the slide test since the first press."""
        c, track, turn = self.judgement, self.track, self.limits.held_turn
        progress, face = track[-1]
        while len(track) > 1 and track[1][0] <= progress - turn:
            track.popleft()
        begun, face_then = track[0]
        if face_then - first_face < c.blocked_progress or face >= c.moved_fraction:
            return False  # (further, the door is in its end stop: open)
        if progress - begun >= turn and face - face_then < 0.5 * (progress - begun):
            return True
        window = self.limits.window
        return normal > c.stall_force and len(track) >= window and abs(face - track[-window][1]) < c.stall_progress

    def verdict(self, progress: float) -> Judgement:
        """The verdict of a swing that ran its course to ``progress``: where the pad last pressed on the face tells
        how far the door went."""
        c, start = self.judgement, self.limits.start
        last_progress, last_face = self.last_pressed
        if last_progress < c.moved_fraction:
            # the pad lost the face before the door was open: it went over the post (a latched door, inside the
            # slide test's 7 deg: it read "moved" with the door shut) or the door is elsewhere. How far the door
            # went is how far its face turned while pressed.
            pressed_at = self.pressed_at
            at = start + (max(last_face - pressed_at[1], 0.0) if pressed_at is not None else 0.0)
            return verdict(c, at, self.forces, Cause.LOCKED_PUSHED if start < c.blocked_progress else None)
        return verdict(c, progress, self.forces, None)  # a latch was decided on the way: short of it, no evidence

    def trace(self, progress: float | None = None) -> SwingTrace:
        """What this judge has read (``progress``: where the swing ended after running its course)."""
        return SwingTrace(self.limits, tuple(self.readings), progress)


@dataclass(frozen=True)
class SwingTrace:
    """An opening swing as recorded: enough to judge it again offline (:func:`judge_swing`)."""

    limits: SwingLimits
    readings: tuple[SwingReading, ...]
    ended_at: float | None = None
    """Where the pad ended after the swing ran its course [fraction of the travel] (None: a reading ended it)."""


def judge_swing(trace: SwingTrace, judgement: JudgementConfig, push: DoorPushJudgement) -> Judgement:
    """The judgement of a recorded swing: its readings folded through :class:`SwingJudge`, as the pusher did live."""
    judge = SwingJudge(judgement, push, trace.limits)
    for reading in trace.readings:
        ended = judge.read(reading)
        if ended is not None:
            return ended
    if trace.ended_at is None:
        raise ValueError("the trace ends in neither a judgement nor the swing's end: it was cut short")
    return judge.verdict(trace.ended_at)


@dataclass(frozen=True)
class ClosingReading:
    """What a closing push reads at one control tick."""

    progress: float
    """The pads' progress down the plate's arc from the start [fraction of the closing travel]."""
    opposing: float
    """Filtered wrist load against the closing motion [N]."""
    magnitude: float
    """Filtered wrist load's magnitude [N]."""


@dataclass(frozen=True)
class ClosingLimits:
    """The per-push constants of a closing push's judgement."""

    start: float
    """Where the closing began [fraction of the closing travel]."""
    contact: float
    """Load that means the pads pressed on the plate [N]."""


class ClosingJudge:
    """The judgement of one closing push, fed tick by tick (:meth:`read`), pure in its readings."""

    def __init__(self, judgement: JudgementConfig, push: DoorPushJudgement, limits: ClosingLimits) -> None:
        self.judgement, self.push, self.limits = judgement, push, limits
        self.forces: list[float] = []
        self.readings: list[ClosingReading] = []
        self.pressed_from: float | None = None
        """The progress at which the pads first pressed on the plate."""

    def read(self, r: ClosingReading) -> Judgement | bool:
        """One tick: blocked (a plate that does not give), True (the plate is on the lid: stop and judge), or False."""
        c = self.judgement
        self.readings.append(r)
        self.forces.append(r.opposing)
        if self.pressed_from is None and r.opposing > self.limits.contact:
            self.pressed_from = r.progress
        if r.progress >= c.moved_fraction and r.magnitude > self.push.end_force:
            return True
        pushed = r.progress - (
            self.limits.start if self.pressed_from is None else max(self.pressed_from, self.limits.start)
        )
        # (a door that fell shut ahead of the pads is first pressed on the lid: closed, not latched)
        short = r.progress < c.moved_fraction and pushed < c.blocked_progress
        if short and (r.opposing > c.blocked_force or r.magnitude > c.blocked_magnitude):
            return Judgement("blocked", Cause.LOCKED_PUSHED, r.progress, max(self.forces))
        return False

    def verdict(self, progress: float) -> Judgement:
        """How a closing push that ended at ``progress`` went."""
        return verdict(self.judgement, progress, self.forces, Cause.LOCKED_PUSHED)

    def trace(self) -> ClosingTrace:
        """What this judge has read."""
        return ClosingTrace(self.limits, tuple(self.readings))


@dataclass(frozen=True)
class ClosingTrace:
    """A closing push as recorded: enough to judge it again offline (:func:`judge_closing`)."""

    limits: ClosingLimits
    readings: tuple[ClosingReading, ...]


def judge_closing(trace: ClosingTrace, judgement: JudgementConfig, push: DoorPushJudgement) -> Judgement:
    """The judgement of a recorded closing push: its readings folded through :class:`ClosingJudge` (a push that ran
    its course is judged where its last reading stood)."""
    judge = ClosingJudge(judgement, push, trace.limits)
    for reading in trace.readings:
        ended = judge.read(reading)
        if isinstance(ended, Judgement):
            return ended
        if ended:
            break
    return judge.verdict(trace.readings[-1].progress if trace.readings else 0.0)


__all__ = [
    "ClosingJudge", "ClosingLimits", "ClosingReading", "ClosingTrace", "SwingJudge", "SwingLimits", "SwingReading",
    "SwingTrace", "judge_closing", "judge_swing",
]  # fmt: skip
