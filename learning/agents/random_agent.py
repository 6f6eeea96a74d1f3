"""The random agent: tries a uniformly random component each step (the floor to beat)."""

from __future__ import annotations

import numpy as np

from puzzlebox.models import SceneObservation, TryResult


class RandomAgent:
    name = "random"

    def __init__(self) -> None:
        self._rng = np.random.default_rng(0)

    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        self._rng = rng

    def choose(self, observation: SceneObservation) -> int:
        return int(self._rng.integers(len(observation)))

    def record(self, index: int, result: TryResult, observation: SceneObservation) -> None:
        pass

    def end_episode(self, solved: bool) -> None:
        pass
