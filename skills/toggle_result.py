"""What a toggle did, as the robot sensed it."""

from __future__ import annotations

from dataclasses import dataclass, field

from puzzlebox.models.try_outcome import Outcome

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
