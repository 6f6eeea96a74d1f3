"""The world a trial's agent acts on, telling the trial's observers which action is under way and how it ended."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

from puzzlebox.lab.observers import TrialObserver
from puzzlebox.models import SceneObservation, TryResult
from puzzlebox.skills.robot_world import RobotWorld
from puzzlebox.twin.rollout_video import Caption

__all__ = ["NarratedWorld"]


class NarratedWorld:
    """A :class:`~puzzlebox.models.world.World` over ``world``: before each try, ``action_begins(caption)`` to
    every observer (the component, and the agent's last decision's ``w`` and ``Q`` values from ``decisions``);
    after it, ``action_ended(caption)`` with the outcome as sensed and, in evaluation, the truth."""

    def __init__(
        self, world: RobotWorld, observers: Sequence[TrialObserver], decisions: Callable[[], Sequence[Any]]
    ) -> None:
        self._world, self._observers, self._decisions = world, tuple(observers), decisions
        self._last = Caption()

    def observe(self) -> SceneObservation:
        return self._world.observe()

    def ground_truth_name(self, index: int) -> str:
        return self._world.ground_truth_name(index)

    def try_toggle(self, index: int) -> TryResult:
        world = self._world
        marker = world.markers[index]
        name = (world.names or {}).get(marker, f"marker {marker}")
        decisions = self._decisions()
        decision = decisions[-1] if decisions else None
        caption = Caption(
            previous=self._last.ending(),
            action=len(world.log) + 1,
            component=f"{name} ({world.marker_map[marker]})",
            weight_info=None if decision is None else float(decision.weight_info),
            q_info=None if decision is None else float(decision.q_info[index]),
            q_exploit=None if decision is None else float(decision.q_exploit[index]),
        )
        for observer in self._observers:
            observer.action_begins(caption)
        result = world.try_toggle(index)
        truth = world.log[-1].true_moved if world.log else None
        self._last = replace(
            caption, sensed=result.outcome, truth="" if truth is None else ("moved" if truth else "did not move")
        )
        for observer in self._observers:
            observer.action_ended(self._last)
        return result
