"""The judgement of a pinch: what the readings of a try tell, as a pure function of them.

A pinch carries a grasped handle along its path and reads, every control tick, the load against the motion, the
load's magnitude, how far the fingers got and how far the gripper is closed (:class:`Reading`). From those alone,
with no simulator, robot or renderer behind it, :class:`PinchJudge` decides tick by tick whether the try goes on,
felt a lock (``blocked``: evidence for the agent), reached the part's stop, or lost the handle; and, once the motion
has run its course and settled, how it ended (:meth:`PinchJudge.verdict`). The pinch (:mod:`skills.pinch`) feeds it
as it moves and obeys it; :func:`judge_pinch` folds a recorded try through the same judge offline, so a judgement can
be tested and measured on recorded traces without simulating.
"""

from __future__ import annotations

import collections
import collections.abc
import math
from dataclasses import dataclass
from enum import StrEnum

from puzzlebox.models.try_outcome import Cause, Outcome
from puzzlebox.skills.settings import JudgementConfig


@dataclass(frozen=True)
class Reading:
    """What a pinch reads at one control tick of its actuation."""

    commanded: float
    """Where the command stands [fraction of the travel from the start]: past 1 in a door's over-travel."""
    opposing: float
    """Filtered wrist load against the motion [N] (tared, base frame, along the perceived direction of motion)."""
    magnitude: float
    """Filtered wrist load's magnitude [N]."""
    progress: float
    """Fraction of the travel the fingers covered towards the other state, from the TCP [-]."""
    closure: float
    """Gripper closure [-] (0 open, 1 closed on nothing)."""


@dataclass(frozen=True)
class PinchLimits:
    """The per-try constants of a pinch's judgement (from its plan and the sensed noise)."""

    press_limit: float
    """Load against the motion that already means held for a handle pressed or pulled along its post [N]; inf when
    the motion runs across the post."""
    window: int
    """Ticks over which a stall is measured."""
    head_start: float
    """Fraction of the travel the part stood at, towards the other state, before the try [-]."""
    slip_ticks: int
    """Closures kept for the slip test (``slip_window`` in ticks, plus one)."""
    grasp_closure: float
    """Gripper closure once the handle was grasped [-]."""


class Decision(StrEnum):
    """What the judge tells the pinch after a tick."""

    GO_ON = "go_on"
    """Nothing decisive: the next tick."""
    HELD_EARLY = "held_early"
    """Held before ``blocked_progress``: blocked (``locked_no_progress``); take the handle back to the grasp."""
    HELD_PART_WAY = "held_part_way"
    """Held past ``blocked_progress``, short of the stop: blocked (``held_part_way``); take it back along its path."""
    AT_STOP = "at_stop"
    """Held where the part stands at its stop (head start counted): stop commanding, settle and judge."""
    SLIPPED_OFF_LOCKED = "slipped_off_locked"
    """The pads slid off a handle that held: blocked (``locked_slipped_off``)."""
    SLIPPED_AT_END_STOP = "slipped_at_end_stop"
    """The pads slid off a post pressed into its end stop: moved."""
    SLIPPED = "slipped"
    """The handle slipped out of the grasp: no evidence."""


@dataclass(frozen=True)
class Judgement:
    """How a try ended, and the evidence the judge read it from."""

    outcome: Outcome
    cause: Cause | None
    """Why it was blocked or failed (None: moved)."""
    progress: float
    """Fraction of the travel covered when judged [-]."""
    peak_opposing_force: float
    """Largest load against the motion [N]."""
    end_stop_felt: bool = False
    """The part was felt in its end stop (a door's over-travel)."""
    held_at: float | None = None
    """Where a part held part-way stopped [fraction of the travel]."""


class PinchJudge:
    """The judgement of one pinch, fed tick by tick (:meth:`read`, then :meth:`settle_read`), pure in its readings."""

    def __init__(self, config: JudgementConfig, limits: PinchLimits) -> None:
        self.config, self.limits = config, limits
        self.forces: list[float] = []
        """Load against the motion at each tick [N]."""
        self.peak = -math.inf
        """The largest of :attr:`forces` [N]."""
        self.progress = 0.0
        self.progress_at_peak = 0.0
        self.in_end_stop = False
        """The part was felt in its end stop (past the travel, ``end_stop_force``)."""
        self.recent: collections.deque[float] = collections.deque(maxlen=limits.window)
        self.closures: collections.deque[float] = collections.deque(maxlen=limits.slip_ticks)
        self.closures.append(limits.grasp_closure)
        self.readings: list[Reading] = []
        """The actuation's readings so far."""
        self.settling: list[tuple[float, float]] = []
        """The settling's (progress, closure) so far."""

    def slipped(self, closure: float) -> bool:
        """Whether the handle left the grasp: the gripper closed on nothing, or closed further than it stood within
        the slip window (a held handle creeps in the pads; a lost one closes quickly)."""
        self.closures.append(closure)
        c = self.config
        return closure >= c.empty_grasp_closure or closure > min(self.closures) + c.slip_closure_rise

    def read(self, r: Reading) -> Decision:
        """One tick of the actuation."""
        c, lim = self.config, self.limits
        self.readings.append(r)
        self.forces.append(r.opposing)
        self.peak = max(self.peak, r.opposing)  # max(self.forces), kept as it grows
        self.progress = r.progress
        if r.opposing >= self.peak:
            self.progress_at_peak = r.progress
        if self.slipped(r.closure):
            if self.progress_at_peak < c.blocked_progress and self.peak >= c.push_force:
                return Decision.SLIPPED_OFF_LOCKED  # the part held while pulled until the pads slid off its handle
            return Decision.SLIPPED_AT_END_STOP if self.in_end_stop else Decision.SLIPPED
        self.in_end_stop = self.in_end_stop or (r.commanded > 1.0 and r.magnitude > c.end_stop_force)
        held = r.opposing > lim.press_limit and r.commanded <= 1.0  # a handle pressed along its post: held lightly
        pressed = r.opposing > c.blocked_force or r.magnitude > c.blocked_magnitude or held
        if pressed and r.progress < c.blocked_progress:
            return Decision.HELD_EARLY
        self.recent.append(r.progress)
        stalled = len(self.recent) == self.recent.maxlen and r.progress - self.recent[0] < c.stall_progress
        held = held or (stalled and r.opposing > c.stall_force and r.commanded <= 1.0)
        if held and r.progress + lim.head_start >= c.moved_fraction:
            return Decision.AT_STOP  # at its stop short of the perceived travel: pushed no further
        return Decision.HELD_PART_WAY if held else Decision.GO_ON

    def settle_read(self, progress: float, closure: float) -> Decision:
        """One tick of letting the part catch up with the command's end: a slip ends the settling (at the end stop,
        the part is where it was pushed) or the try (no evidence)."""
        self.progress = progress
        self.settling.append((progress, closure))
        if self.slipped(closure):
            return Decision.AT_STOP if self.in_end_stop else Decision.SLIPPED
        return Decision.GO_ON

    def trace(self, reached: float | None = None) -> PinchTrace:
        """What this judge has read, as a record (``reached``: where the settled part was judged to stand)."""
        return PinchTrace(self.limits, tuple(self.readings), tuple(self.settling), reached)

    def ended(self, decision: Decision) -> Judgement:
        """The judgement of an actuation that ``decision`` ended early (not :attr:`Decision.AT_STOP` or
        :attr:`Decision.GO_ON`, which go on to :meth:`verdict`)."""
        if decision in (Decision.GO_ON, Decision.AT_STOP):
            raise ValueError(f"{decision} does not end a try; the verdict judges it")
        peak, progress = self.peak, self.progress
        if decision is Decision.HELD_EARLY:
            return Judgement("blocked", Cause.LOCKED_NO_PROGRESS, progress, peak)
        if decision is Decision.HELD_PART_WAY:
            return Judgement("blocked", Cause.HELD_PART_WAY, progress, peak, held_at=progress)
        if decision is Decision.SLIPPED_OFF_LOCKED:
            return Judgement("blocked", Cause.LOCKED_SLIPPED_OFF, progress, peak)
        if decision is Decision.SLIPPED_AT_END_STOP:
            return Judgement("moved", None, progress, peak, end_stop_felt=True)
        return Judgement("failed", Cause.SLIPPED, progress, peak)

    def verdict(self, reached: float, latched: Cause | None = Cause.LOCKED_PULLED) -> Judgement:
        """How a motion that ran its course ended, the part ``reached`` [fraction of the travel, head start counted]:
        ``moved`` past ``moved_fraction``; ``blocked`` (cause ``latched``, when given) short of ``blocked_progress``
        after at least ``push_force`` against the motion; else ``failed``."""
        return verdict(self.config, reached, self.forces, latched, self.in_end_stop)


def verdict(
    config: JudgementConfig, reached: float, forces: collections.abc.Sequence[float], latched: Cause | None,
    end_stop_felt: bool = False,
) -> Judgement:  # fmt: skip
    """:meth:`PinchJudge.verdict` on its own: ``forces`` [N], the load against the motion at each tick."""
    peak = max(forces)
    if reached >= config.moved_fraction:
        return Judgement("moved", None, reached, peak, end_stop_felt=end_stop_felt)
    if latched is not None and reached < config.blocked_progress and peak >= config.push_force:
        return Judgement("blocked", latched, reached, peak, end_stop_felt=end_stop_felt)
    return Judgement("failed", Cause.INCOMPLETE_TRAVEL, reached, peak, end_stop_felt=end_stop_felt)


@dataclass(frozen=True)
class PinchTrace:
    """A pinch's try as recorded: enough to judge it again offline (:func:`judge_pinch`)."""

    limits: PinchLimits
    actuation: tuple[Reading, ...]
    """The readings of the actuation, one per tick, up to the one that ended it."""
    settling: tuple[tuple[float, float], ...] = ()
    """(progress, closure) at each tick of the settling, when the actuation ran its course."""
    reached: float | None = None
    """Where the part was judged to stand after settling, head start counted [-] (None: the actuation ended it)."""


def judge_pinch(trace: PinchTrace, config: JudgementConfig) -> Judgement:
    """The judgement of a recorded pinch: the readings folded through :class:`PinchJudge`, as the pinch did live."""
    judge = PinchJudge(config, trace.limits)
    for reading in trace.actuation:
        decision = judge.read(reading)
        if decision is Decision.AT_STOP:
            break
        if decision is not Decision.GO_ON:
            return judge.ended(decision)
    for progress, closure in trace.settling:
        decision = judge.settle_read(progress, closure)
        if decision is Decision.AT_STOP:
            break
        if decision is not Decision.GO_ON:
            return judge.ended(decision)
    if trace.reached is None:
        raise ValueError("the trace ends in neither a decision nor a settled position: it was cut short")
    return judge.verdict(trace.reached)


__all__ = ["Decision", "Judgement", "PinchJudge", "PinchLimits", "PinchTrace", "Reading", "judge_pinch", "verdict"]
