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
from typing import Literal

Outcome = Literal["moved", "blocked", "failed"]
OUTCOMES: tuple[str, ...] = ("moved", "blocked", "failed")


@dataclass(frozen=True)
class TryResult:
    """The outcome of one try, with a reason for ``blocked`` and ``failed``.

    Attributes:
        outcome: ``moved``, ``blocked`` or ``failed``.
        reason: why (empty for a plain ``moved``), e.g. ``"GraspFailure: the gripper closed on nothing"``.
        give_up: the world will not manage to try this component again (a component it can never
            grasp): an agent should not choose it again, and a trial may end there with this reason.
    """

    outcome: Outcome
    reason: str = ""
    give_up: bool = False

    def __post_init__(self) -> None:
        if self.outcome not in OUTCOMES:
            raise ValueError(f"outcome must be one of {list(OUTCOMES)}, got {self.outcome!r}")

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


__all__ = ["OUTCOMES", "Outcome", "TryResult"]
