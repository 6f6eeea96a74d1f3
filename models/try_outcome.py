"""What a try of a component gives back through the ``World`` protocol.

Three outcomes, because a real robot has three (DESIGN.md, "The seams"):

- ``moved``: the component reached its other state;
- ``blocked``: the robot held the handle, pulled and felt it held (evidence of a lock);
- ``failed``: the robot could not make a proper try (the grasp closed on nothing, IK failed, the
  marker was lost, a force limit stopped the motion): **no evidence** about locks, so the agent's
  belief must not change.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Literal

Outcome = Literal["moved", "blocked", "failed"]
OUTCOMES: tuple[str, ...] = ("moved", "blocked", "failed")


class Cause(StrEnum):
    """Why a try ended ``blocked`` or ``failed`` (a plain ``moved`` has none), as a type: the code decides on it,
    the human text (:attr:`TryResult.reason`) is only shown. The value is what a record stores."""

    # blocked: the robot held the part, pushed or pulled, and felt it held (evidence of a lock)
    LOCKED_NO_PROGRESS = "locked_no_progress"
    """The force against the motion rose before the part covered ``blocked_progress`` of its travel."""
    LOCKED_PULLED = "locked_pulled"
    """A pull ran its course and the part stayed short of ``blocked_progress`` after ``push_force``."""
    LOCKED_SLIPPED_OFF = "locked_slipped_off"
    """The part held while pulled until the pads slid off its handle."""
    HELD_PART_WAY = "held_part_way"
    """The part stopped against the motion past ``blocked_progress`` (a lock's rod met its wall)."""
    LOCKED_PUSHED = "locked_pushed"
    """A door pushed did not move."""
    LOCKED_PAD_SLID = "locked_pad_slid"
    """A door's face stood still while the pushing pad slid along it."""
    LOCKED_PINCH_AND_PUSH = "locked_pinch_and_push"
    """A door stayed shut under the pinch and then under the push."""
    # failed: no proper try, no evidence about locks
    GRASP_EMPTY = "grasp_empty"
    """The gripper closed on nothing."""
    SLIPPED = "slipped"
    """The handle slipped out of the grasp during the motion."""
    UNREACHABLE = "unreachable"
    """The inverse kinematics could not reach a target."""
    FORCE_LIMIT = "force_limit"
    """The wrist force passed the safety limit: the motion was stopped."""
    INCOMPLETE_TRAVEL = "incomplete_travel"
    """A motion ran its course short of ``moved_fraction`` with no latch read."""
    JAMMED = "jammed"
    """A door held part-way open is stuck, not latched."""
    MARKER_LOST = "marker_lost"
    """After the try the part's marker was not seen."""
    NOT_BACK_CLOSED = "not_back_closed"
    """The handle moved but the part is not back at its closed pose."""
    MARKER_STILL = "marker_still"
    """The handle moved but the part's marker did not."""
    DOOR_STAYED_SHUT = "door_stayed_shut"
    """The fingers went the whole way and the door stayed shut."""
    STANDS_PART_WAY = "stands_part_way"
    """After the try the part stands between its states."""

    @classmethod
    def from_legacy(cls, reason: str) -> Cause | None:
        """The cause of a try recorded before causes were stored, from its reason text; None for a text no
        version of the hand wrote. The one place a reason string is read: loading an old record."""
        for head, cause in _LEGACY:
            if reason.startswith(head):
                return cause
        return None

    @property
    def prefix(self) -> str:
        """The head of the reason text (what reports group failures by): an error's class name or ``latched``."""
        return _PREFIXES.get(self, "latched")

    def fits(self, outcome: str) -> bool:
        """Whether a try of ``outcome`` can have this cause: a lock's causes a ``blocked`` try, the others a
        ``failed`` one; a ``moved`` try has none."""
        return outcome != "moved" and (outcome == "blocked") == (self.family == "locked")

    @property
    def family(self) -> str:
        """The coarse class: ``locked``, ``grasp empty``, ``slipped``, ``unreachable``, ``force limit``,
        ``stopped part-way`` or ``marker lost``."""
        return _FAMILIES[self]


_PREFIXES = {
    Cause.GRASP_EMPTY: "GraspFailure",
    Cause.SLIPPED: "SlipDetected",
    Cause.UNREACHABLE: "IKFailure",
    Cause.FORCE_LIMIT: "ForceLimitExceeded",
    Cause.INCOMPLETE_TRAVEL: "IncompleteTravel",
    Cause.JAMMED: "Jammed",
    Cause.MARKER_LOST: "SlipDetected",
    Cause.NOT_BACK_CLOSED: "SlipDetected",
    Cause.MARKER_STILL: "SlipDetected",
    Cause.DOOR_STAYED_SHUT: "SlipDetected",
    Cause.STANDS_PART_WAY: "SlipDetected",
}
_LEGACY: tuple[tuple[str, Cause], ...] = (
    ("ForceLimitExceeded", Cause.FORCE_LIMIT),
    ("IKFailure", Cause.UNREACHABLE),
    ("GraspFailure", Cause.GRASP_EMPTY),
    ("SlipDetected: the handle slipped", Cause.SLIPPED),
    ("SlipDetected: the part was not seen", Cause.MARKER_LOST),
    ("SlipDetected: the handle moved but the part is not back", Cause.NOT_BACK_CLOSED),
    ("SlipDetected: the handle moved but the marker did not", Cause.MARKER_STILL),
    ("SlipDetected: the door stayed shut", Cause.DOOR_STAYED_SHUT),
    ("SlipDetected: the part stands at", Cause.STANDS_PART_WAY),
    ("IncompleteTravel", Cause.INCOMPLETE_TRAVEL),
    ("Jammed", Cause.JAMMED),
    ("latched: held part-way", Cause.HELD_PART_WAY),
    ("latched: force rose without progress", Cause.LOCKED_NO_PROGRESS),
    ("latched: pulled without progress", Cause.LOCKED_PULLED),
    ("latched: held until the grasp slipped", Cause.LOCKED_SLIPPED_OFF),
    ("latched: pushed without progress", Cause.LOCKED_PUSHED),
    ("latched: the pad slid along its handle", Cause.LOCKED_PAD_SLID),
    ("latched: the door stayed shut under the pinch and the push", Cause.LOCKED_PINCH_AND_PUSH),
)
"""Heads of the reason texts each cause was written as (checked in order)."""
_FAMILIES = {
    **{c: "locked" for c in Cause if c.name.startswith("LOCKED_")},
    Cause.HELD_PART_WAY: "locked",
    Cause.GRASP_EMPTY: "grasp empty",
    Cause.SLIPPED: "slipped",
    Cause.NOT_BACK_CLOSED: "slipped",
    Cause.MARKER_STILL: "slipped",
    Cause.DOOR_STAYED_SHUT: "slipped",
    Cause.UNREACHABLE: "unreachable",
    Cause.FORCE_LIMIT: "force limit",
    Cause.INCOMPLETE_TRAVEL: "stopped part-way",
    Cause.STANDS_PART_WAY: "stopped part-way",
    Cause.JAMMED: "stopped part-way",
    Cause.MARKER_LOST: "marker lost",
}


@dataclass(frozen=True)
class TryResult:
    """The outcome of one try, with a reason for ``blocked`` and ``failed``.

    Attributes:
        outcome: ``moved``, ``blocked`` or ``failed``.
        reason: why (empty for a plain ``moved``), e.g. ``"GraspFailure: the gripper closed on nothing"``.
        give_up: the world will not manage to try this component again (a component it can never
            grasp): an agent should not choose it again, and a trial may end there with this reason.
        cause: why, as a type (None for ``moved`` and for worlds that do not say: the symbolic ones).
    """

    outcome: Outcome
    reason: str = ""
    give_up: bool = False
    cause: Cause | None = None

    def __post_init__(self) -> None:
        if self.outcome not in OUTCOMES:
            raise ValueError(f"outcome must be one of {list(OUTCOMES)}, got {self.outcome!r}")
        if self.cause is not None and not self.cause.fits(self.outcome):
            raise ValueError(f"a {self.outcome!r} try cannot be caused by {self.cause.value!r}")

    @property
    def moved(self) -> bool:
        return self.outcome == "moved"

    @property
    def informative(self) -> bool:
        """True for ``moved`` and ``blocked``: outcomes that say something about locks."""
        return self.outcome != "failed"

    @classmethod
    def from_moved(cls, moved: bool) -> TryResult:
        """``moved`` or ``blocked`` (the symbolic environment's two outcomes)."""
        return cls("moved") if moved else cls("blocked")


class ReadsItsResult:
    """A record of one try that holds the world's :class:`TryResult` as it was returned (``result``) and reads its
    outcome through it, copying none of its fields (the run's ``learning.ActionRecord``, the world's
    ``skills.robot_world.ActionLog``)."""

    result: TryResult

    @property
    def moved(self) -> bool:
        return self.result.moved

    @property
    def outcome(self) -> Outcome:
        """``moved``, ``blocked`` or ``failed``."""
        return self.result.outcome

    @property
    def reason(self) -> str:
        return self.result.reason

    @property
    def cause(self) -> Cause | None:
        """Why it was ``blocked`` or ``failed``, as a type (None for ``moved`` and for worlds that do not say)."""
        return self.result.cause


__all__ = ["OUTCOMES", "Cause", "Outcome", "ReadsItsResult", "TryResult"]
