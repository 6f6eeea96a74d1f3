"""Trying a part as kinds it was not told (:class:`OtherKinds`): a part told one kind that the hand cannot move as it
(held again, or failed so often the world would give it up) is tried, carefully, as the other registered kinds whose
handle height fits its marker, most plausible first; one that moves it is kept, one whose grasp held where the told
kind's closed on nothing is used from then on (the rule in :mod:`skills.robot_world`'s docstring).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from puzzlebox.models import TryResult
from puzzlebox.models.disassembly_kinds import family_kind_names
from puzzlebox.models.kinds import get_kind, registered_kinds
from puzzlebox.skills.door_clearance import near_open_door
from puzzlebox.skills.joint_model import JointModel
from puzzlebox.skills.toggle_result import ToggleResult


class OtherKinds:
    """The other kinds of one world's parts (see the module docstring)."""

    def __init__(self, world: Any) -> None:
        self.world = world
        """The :class:`skills.robot_world.RobotWorld` whose parts these are (its kinds, joint models, looks and
        toggler: not imported here, as it imports this module)."""

    def due(self, marker: int, outcome: TryResult, failures: int) -> bool:
        """Whether ``marker``'s part, just tried as the kind in use with ``outcome`` after ``failures`` failed
        attempts, is now tried as other kinds (the rule in :mod:`skills.robot_world`'s docstring)."""
        w = self.world
        c = w.config
        if not c.other_kinds or marker in w.moved_as or w.other_kind_rounds.get(marker, 0) >= c.other_kind_rounds:
            return False
        if outcome.outcome == "failed":
            return failures > c.max_retries  # the world would give it up
        return outcome.outcome == "blocked" and marker in w.blocked_as  # blocked again

    def ranked(self, marker: int, held: bool) -> list[str]:
        """The kinds other than the one in use that ``marker``'s part may be, most plausible first: registered
        kinds whose ``lift`` fits the marker's perceived height above the lid and whose handle is not where a grasp
        on it closed on nothing; those of the family of the kinds the world was told first (the paper's, when all
        are), then (``held``: the grasp held the handle) those whose handle stands where the kind in use has it,
        then in registration order."""
        w = self.world
        c = w.config
        in_use = w.joint_models[marker]
        family = set(family_kind_names(tuple(w.marker_map.values())))
        empty = w.empty_handles.get(marker, [])
        ranked = []
        for order, name in enumerate(registered_kinds()):
            if name == in_use.kind or abs(w.marker_heights[marker] - get_kind(name).lift) > c.lift_tolerance:
                continue
            grasp = w._joint_model(marker, name).grasp_point
            if any(np.linalg.norm(grasp - e) < c.same_handle for e in empty):
                continue
            elsewhere = bool(np.linalg.norm(grasp - in_use.grasp_point) >= c.same_handle)
            ranked.append((name not in family, held and elsewhere, order, name))
        return [name for *_, name in sorted(ranked)]

    def try_them(
        self, marker: int, opening: bool, first: TryResult, empty: bool
    ) -> tuple[TryResult, ToggleResult | None, tuple[str, ...]]:
        """Try ``marker``'s part as up to ``other_kinds`` other kinds (:meth:`ranked`), one careful attempt
        each, after ``first``, its outcome as the kind in use (``empty``: a grasp of it closed on nothing). Gives the
        try's outcome, the last toggle's result with the effort of them all (None if no other kind fits) and the
        kinds tried. A kind that moves the part is kept (:attr:`RobotWorld.found_kinds`); one whose grasp held where
        the kind in use closed on nothing, or that carried the part past ``blocked_progress``, is used from then on
        (the first that carried it, else the first that held)."""
        w = self.world
        c = w.config
        in_use = w.joint_models[marker]
        if empty:
            w.empty_handles.setdefault(marker, []).append(in_use.grasp_point)
        candidates = self.ranked(marker, held=first.outcome == "blocked")[: c.other_kinds]
        if not candidates:
            return first, None, ()
        w.other_kind_rounds[marker] = w.other_kind_rounds.get(marker, 0) + 1
        total: ToggleResult | None = None
        blocked = [first] if first.outcome == "blocked" else []
        adopt: JointModel | None = None
        adopt_carried = False
        tried: list[str] = []
        # the part itself, as the door in use, may stand open over the other kinds' grasp points
        own_door = w._lowest_open(marker, 0 if opening else 1) if in_use.handling.swings_up else None
        for kind in candidates:
            tried.append(kind)
            w.joint_models[marker] = jm = w._joint_model(marker, kind)
            w.kinds[marker] = kind
            grasp = jm.grasp_point_at(0.0 if opening else 1.0)
            cautious = c.other_kinds_cautious and (
                bool(w._doors_overhanging(marker, opening))
                or (own_door is not None and near_open_door(in_use, own_door, grasp, c.door_clearance))
            )
            result = w.toggler.toggle(
                jm, opening, where_is=lambda: w._fraction_open(marker), careful=True, cautious=cautious
            )
            if result.outcome == "failed" and result.progress >= w.toggler.config.judgement.moved_fraction:
                if w._overview_verdict(marker, opening, unseen_moved=not jm.handling.swings_up).moved:
                    result.seen_moved()
            outcome = w._sensed_outcome(result, marker, opening)
            if total is not None:
                result.peak_force = max(result.peak_force, total.peak_force)
                result.sim_time, result.wall_time = result.sim_time + total.sim_time, result.wall_time + total.wall_time
            total = result
            if outcome.moved:  # (try_toggle keeps it in found_kinds)
                w.blocked_as.discard(marker)
                return TryResult("moved", f"moved as a {kind}, not a {in_use.kind}"), total, tuple(tried)
            carried = result.progress >= w.toggler.config.judgement.blocked_progress
            if result.closed_on_nothing:
                w.empty_handles.setdefault(marker, []).append(jm.grasp_point)
            elif (adopt is None or (not adopt_carried and carried)) and (
                (outcome.outcome == "blocked" and empty) or (jm.handling.swings_up and carried)
            ):
                # its handle is there (held, or carried part of the way): this kind from now on; one that carried
                # the handle part of the way before it was held outranks one held at once (a wheel told a slide,
                # pushed without progress as a door, then held part-way as a wheel: a wheel)
                adopt, adopt_carried = jm, carried
            if outcome.outcome == "blocked":
                blocked.append(outcome)
        w.joint_models[marker] = adopt or in_use
        w.kinds[marker] = (adopt or in_use).kind
        if adopt is not None:
            w.blocked_as.discard(marker)
            if adopt.handling.swings_up and opening:
                w.unsettled.add(marker)  # the next try of it looks first
        if blocked:
            held = ", ".join(tried)
            also = TryResult("blocked", f"{blocked[0].reason} (also tried as {held})", cause=blocked[0].cause)
            return also, total, tuple(tried)
        return first, total, tuple(tried)


__all__ = ["OtherKinds"]
