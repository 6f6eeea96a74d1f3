"""Discrete component states read from joint positions, with hysteresis.

A component is in state 1 once its joint has travelled past ``open_fraction`` of its travel and back
in state 0 once below ``close_fraction``; in between it keeps its last state, so a part wobbling at
a threshold never flickers between states (and never flickers its latches).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HysteresisConfig:
    """Where the state of a component flips, as fractions of its travel."""

    open_fraction: float = 0.75
    """Fraction of the travel past which a component counts as open (state 1)."""
    close_fraction: float = 0.25
    """Fraction of the travel below which a component counts as closed again (state 0)."""

    def __post_init__(self) -> None:
        if not 0.0 < self.close_fraction < self.open_fraction < 1.0:
            raise ValueError("need 0 < close_fraction < open_fraction < 1")


class ComponentStates:
    """Tracks the 0/1 states of N components from their joint positions (vectorised)."""

    def __init__(self, travel: np.ndarray, config: HysteresisConfig | None = None) -> None:
        config = config or HysteresisConfig()
        self.open_at = np.asarray(travel, dtype=float) * config.open_fraction
        self.close_at = np.asarray(travel, dtype=float) * config.close_fraction
        self.states = np.zeros(len(travel), dtype=np.int64)

    def update(self, q: np.ndarray) -> bool:
        """Update from joint positions ``q`` [rad or m]; True if any state changed."""
        flipping = np.where(self.states == 0, q >= self.open_at, q <= self.close_at)
        if not flipping.any():  # the common case, kept cheap: this runs every few physics steps
            return False
        flips = np.flatnonzero(flipping)
        self.states = self.states.copy()
        self.states[flips] ^= 1
        return True

    def reset(self, q: np.ndarray) -> None:
        """States from scratch: open past the middle of the travel, else closed."""
        self.states = (np.asarray(q) >= 0.5 * (self.open_at + self.close_at)).astype(np.int64)
