"""How far along its path a motion's command stands after each control tick: slowly over the start of the travel,
where a lock's pins are met, then a ramp up to the full pace.

The pace rises over :data:`RAMP_TICKS` control ticks rather than in one step, so that a lock's pin met just past
the slow span is still met slowly.
"""

from __future__ import annotations

import math

__all__ = ["RAMP_TICKS", "Pacing"]

RAMP_TICKS = 30
"""Control ticks over which the pace rises from the slow pace to the full one (0.3 s at the 10 ms tick, longer by
the toggle's slowdown with the tick count)."""


class Pacing:
    """The commanded fraction of the travel after tick ``k`` (:meth:`at`): ``slow_pace`` (travel per tick) up to
    ``slow_span``, then rising linearly to ``pace`` over ``ramp`` ticks, then ``pace``."""

    def __init__(self, pace: float, slow_pace: float, slow_span: float, ramp: int = RAMP_TICKS) -> None:
        self.pace, self.slow_pace, self.slow_span = pace, slow_pace, max(slow_span, 0.0)
        self.slow_ticks = self.slow_span / slow_pace if slow_pace > 0 else 0.0
        self.ramp = ramp if self.slow_span > 0 else 0
        self.ramp_span = self.ramp * (slow_pace + pace) / 2  # travel covered while the pace rises

    def at(self, k: float) -> float:
        """Fraction of the travel commanded after ``k`` ticks (from the start of the motion)."""
        if k <= self.slow_ticks:
            return self.slow_pace * k
        t = k - self.slow_ticks
        if t <= self.ramp:
            return self.slow_span + self.slow_pace * t + (self.pace - self.slow_pace) * t * t / (2 * self.ramp)
        return self.slow_span + self.ramp_span + self.pace * (t - self.ramp)

    def ticks_to(self, span: float) -> int:
        """Ticks until the command has covered ``span`` of the travel (at least)."""
        if span <= self.slow_span:
            return math.ceil(span / self.slow_pace - 1e-9) if self.slow_pace > 0 else 0
        if span <= self.slow_span + self.ramp_span:
            low, high = self.slow_ticks, self.slow_ticks + self.ramp
            for _ in range(60):  # the ramp's quadratic, inverted by bisection (a handful of calls a try)
                mid = (low + high) / 2
                low, high = (mid, high) if self.at(mid) < span else (low, mid)
            return math.ceil(high - 1e-9)
        return math.ceil(self.slow_ticks + self.ramp + (span - self.slow_span - self.ramp_span) / self.pace - 1e-9)
