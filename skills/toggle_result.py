"""What a toggle did, as the robot sensed it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from puzzlebox.models.try_outcome import Cause, Outcome

if TYPE_CHECKING:
    from puzzlebox.skills.door_judgement import ClosingTrace, SwingTrace
    from puzzlebox.skills.judgement import PinchTrace

LATCHED: dict[Cause, str] = {
    Cause.LOCKED_NO_PROGRESS: "latched: force rose without progress",
    Cause.LOCKED_PULLED: "latched: pulled without progress",
    Cause.LOCKED_SLIPPED_OFF: "latched: held until the grasp slipped",
    Cause.LOCKED_PUSHED: "latched: pushed without progress",
    Cause.LOCKED_PAD_SLID: "latched: the pad slid along its handle",
    Cause.LOCKED_PINCH_AND_PUSH: "latched: the door stayed shut under the pinch and the push",
}
"""The reason text of each ``blocked`` cause that carries no figure."""
HELD_PART_WAY = "latched: held part-way"
"""Reason prefix of a part that a toggle carried past ``blocked_progress`` of its travel, where it stopped against
the motion (a lock's rod met its wall: ``models.lock_mechanisms``): pulled, it stalled under ``stall_force``; pushed
(a door), its face stood still while the pad slid along it."""


@dataclass
class ToggleResult:
    """What a toggle did, as the robot sensed it."""

    outcome: Outcome
    reason: str = ""
    progress: float = 0.0
    """Measured fraction of the travel the grasp point covered (towards the other state)."""
    peak_opposing_force: float = 0.0
    """Largest force opposing the motion while actuating [N]."""
    sim_time: float = 0.0
    wall_time: float = 0.0
    forces: list[float] = field(default_factory=list)
    peak_force: float = 0.0
    """Largest filtered force magnitude over the whole try [N] (what the safety limit watches)."""
    end_stop_felt: bool = False
    """A door's pinch felt the door reach its end stop (past the travel, ``end_stop_force``)."""
    closed_on_nothing: bool = False
    """The gripper closed on nothing where the handle was looked for (whatever the try did next: a door is pushed)."""
    cause: Cause | None = None
    """Why it ended ``blocked`` or ``failed``, as a type (None for ``moved``); :attr:`reason` is its text."""
    stopped_while: str = ""
    """What the primitive was doing when the force guard stopped it (``models.toggle_log.PHASES``; "" if it did
    not)."""
    pushed_on: ToggleResult | None = None
    """A door's opening push that ran short was followed by a push on under its plate, which failed or was
    blocked: that push's result (its verdict is in :attr:`reason` after this one's)."""
    held_at: float | None = None
    """Where a part read ``held part-way`` stopped, as a fraction of its travel (a door's: where its face stood
    still while the pad slid along it)."""
    not_pushed: bool = False
    """A door the pads lost stands part-way where no look sees it: it was not pushed."""
    trace: PinchTrace | SwingTrace | ClosingTrace | None = None
    """The readings the judgement read this result from, a pinch's (:func:`skills.judgement.judge_pinch`) or a
    door's opening swing's (:func:`skills.door_judgement.judge_swing`), to judge them again offline; None for a
    result no recorded judgement gave (a closing push, a top-up, an error)."""

    def seen_moved(self) -> None:
        """The world saw the part at its other state after this try failed past ``moved_fraction`` (a stop, a slip
        near the end): a plain ``moved``, its cause and reason dropped."""
        self.outcome, self.reason, self.cause = "moved", "", None
        self.stopped_while, self.pushed_on, self.not_pushed = "", None, False

    def last_stop(self) -> ToggleResult:
        """The motion the try ended with: the push on under the plate if there was one, else this one."""
        return self.pushed_on if self.pushed_on is not None else self
