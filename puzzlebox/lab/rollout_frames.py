"""The rollout video's frames as a fold of a trial's events (:class:`FrameMaker`): live, fed by the trial
(:class:`puzzlebox.lab.rollout_observers.RolloutVideo`), or afterwards from its state log
(:func:`puzzlebox.lab.state_log.replay_frames`), the same frames either way.

A frame is made at every grid time 0, ``period``, 2 ``period``, ... that a robot wait passed, with the state at that
wait's end (a 10 ms control tick; a look or a settle waits up to ~1 s), and one at the end of the trial. It carries
the joint positions, the caption of the action under way (with what the hand was doing), the part tried, the looks
the pipeline took since the previous frame (each drawn on the state it was taken at, on that frame only) and the
wrist force the hand sensed over the plot window.
"""

from __future__ import annotations

import collections
import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from puzzlebox.twin.rollout_video import Caption, Look, RolloutFrame


class FrameMaker:
    """Makes :class:`~puzzlebox.twin.rollout_video.RolloutFrame` s from a trial's events (module docstring)."""

    def __init__(self, parts: list[str], period: float, plot_window: float) -> None:
        self._parts, self._period, self._window = parts, period, plot_window
        self._next = 0.0
        self._caption = Caption()
        self._part = ""
        self._forces: collections.deque[tuple[float, float]] = collections.deque()
        self._looks: dict[str, Look] = {}

    def waited(self, now: float, qpos: np.ndarray, force: float | None, phase: str) -> list[RolloutFrame]:
        """Robot time reached ``now`` [s] with the model at ``qpos``; ``force``: the wrist force magnitude the hand
        sensed [N] (None before the world exists); ``phase``: what it was doing ("surveying" before). The frames
        of the grid times this wait passed."""
        if force is not None:
            self._forces.append((now, force))
            while self._forces and self._forces[0][0] < now - self._window:
                self._forces.popleft()
        frames = []
        while self._next <= now:
            frames.append(self.frame(self._next, qpos, phase))
            self._next += self._period
        return frames

    def look(self, camera: str, look: Look) -> None:
        """The pipeline looked through ``camera`` (the next frame outlines what it found)."""
        self._looks[camera] = look

    def action_begins(self, caption: Caption) -> None:
        self._caption = caption
        # the caption names the part "<spec name> (<kind>)"
        self._part = next((p for p in self._parts if caption.component.startswith(f"{p} (")), "")

    def action_ended(self, caption: Caption) -> None:
        self._caption = caption
        self._part = ""

    def frame(self, now: float, qpos: np.ndarray, phase: str) -> RolloutFrame:
        """The frame at ``now``: the model at ``qpos``, the looks since the previous frame (then forgotten)."""
        looks, self._looks = self._looks, {}  # each look on the first frame after it, and on no other
        return RolloutFrame(
            time=now, qpos=qpos.copy(), caption=replace(self._caption, phase=phase), looks=looks,
            forces=np.array(self._forces, dtype=float).reshape(-1, 2), highlight=self._part,
        )  # fmt: skip


def hand_phase(world: Any) -> str:
    """What the hand of ``world`` (a :class:`skills.robot_world.RobotWorld`, None before it exists) is doing: its
    toggler's phase, or "surveying"."""
    return "surveying" if world is None else world.toggler.phase


def sensed_force(world: Any) -> float | None:
    """The magnitude of the wrist force the hand of ``world`` sensed (filtered, in the base frame) [N]; None before
    the world exists."""
    if world is None:
        return None
    force_in_base = world.toggler.force_in_base
    return math.sqrt(force_in_base @ force_in_base)  # np.linalg.norm, bit for bit, at a third of its cost


class CapturedLooks:
    """The looks a trial's pipeline takes, each with the simulator's joint positions at its capture: fed the captures
    (:meth:`captured`) and told each look by the pipeline's detector (:meth:`look`)."""

    def __init__(self, qpos: Callable[[], np.ndarray]) -> None:
        self._qpos = qpos
        self._captured: dict[str, tuple[float, np.ndarray]] = {}
        """Camera -> time and joint positions of its latest capture."""

    def captured(self, camera: str, time: float) -> None:
        self._captured[camera] = (time, self._qpos().copy())

    def look(self, camera: str, time: float, found: list[tuple[int, np.ndarray]]) -> Look:
        """The look through ``camera`` at ``time`` that found ``found``, with the state of its capture (None: that
        capture was not seen)."""
        captured = self._captured.get(camera)
        return Look(time, found, captured[1] if captured is not None and captured[0] == time else None)


__all__ = ["CapturedLooks", "FrameMaker", "hand_phase", "sensed_force"]
