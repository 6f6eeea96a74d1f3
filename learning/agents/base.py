"""The agent interface: what the trial loop calls, whatever the agent and whatever the world."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from puzzlebox.models import SceneObservation, TryResult


class Agent(Protocol):
    """An agent solving one puzzle per episode through a ``World``."""

    name: str

    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        """A new puzzle (or a new attempt): ``observation`` is the scene before any action."""
        ...

    def choose(self, observation: SceneObservation) -> int:
        """Index of the component to try next."""
        ...

    def record(self, index: int, result: TryResult, observation: SceneObservation) -> None:
        """The outcome of trying ``index`` and the scene after it. A ``failed`` try (the robot could
        not make a proper try) is no evidence about locks: learners must not read it as ``blocked``."""
        ...

    def end_episode(self, solved: bool) -> None:
        """The episode is over (solved or out of actions)."""
        ...
