"""The wrist's force readings as the hand uses them (:class:`ForceWatch`): every tick's wrench rotated into the base
frame and filtered by a running median, the safety limit that stops any motion, and the noise measured at rest with
the tare and filter lengths it calls for.

The filter's length and the guard's threshold carry over from one try to the next (a try that fails before its own
descent still filters with the last descent's length): they belong to the sensor, not to a try.
"""

from __future__ import annotations

import collections
import collections.abc
import math

import numpy as np

from puzzlebox.models.robot import Robot
from puzzlebox.skills.errors import ForceLimitExceeded
from puzzlebox.skills.settings import TARE_SAMPLES, PrimitiveConfig

_MEDIAN_SPREAD = math.sqrt(math.pi / 2)
"""Spread of the median of n samples of a Gaussian, times sqrt(n), over the samples' spread (large n)."""


def median_rows(rows: collections.abc.Sequence[np.ndarray]) -> np.ndarray:
    """``np.median(rows, axis=0)``, bit for bit, at a fifth of its cost on a few short rows (it runs every tick)."""
    ordered = np.sort(np.array(rows), axis=0)
    mid = len(ordered) // 2
    return ordered[mid] if len(ordered) % 2 else (ordered[mid - 1] + ordered[mid]) / 2


class ForceWatch:
    """The filtered wrist force and the force guard of one arm (see the module docstring)."""

    def __init__(self, robot: Robot, config: PrimitiveConfig) -> None:
        self.robot = robot
        self.config = config
        self.window: collections.deque[np.ndarray] = collections.deque(maxlen=config.sensing.force_filter_samples)
        """The running median's window of raw forces in the base frame [N] (its length set at each descent)."""
        self.raw: collections.deque[np.ndarray] = collections.deque(maxlen=config.sensing.noise_samples)
        """The last raw wrist forces in the base frame [N]: how noisy the sensor is (:attr:`rest_noise`)."""
        self.force_in_base = np.zeros(3)
        """The filtered wrist force after the last tick, in the base frame [N]."""
        self.phase = "moving"
        """What the arm is doing (``models.toggle_log.PHASES``: named by a force stop)."""
        self.rest_noise = 0.0
        """F/T force noise measured as the arm came to rest above the part of the toggle in progress [N]."""
        self.peak_force = 0.0
        """Largest filtered force magnitude since the last :meth:`reset` [N]."""
        self.guard = True
        """Stop motions at :attr:`limit` (off only while withdrawing from a stop)."""
        self.limit = config.sensing.force_limit
        """The force guard's threshold now [N]: ``force_limit``, or ``cautious_contact_force`` in a cautious descent."""
        self.slowdown = 1.0
        """How much slower than configured the motions in contact run [-]: the running median's length over
        ``force_filter_samples`` (1 below 7.2 N of F/T noise), over ``careful_pace`` in a careful toggle (set at
        each descent)."""

    # -- force -------------------------------------------------------------------------------------
    def reset(self) -> None:
        """Forget the force history (after a tare: older samples have another zero)."""
        self.window.clear()
        self.peak_force = 0.0

    def sense(self) -> None:
        """Read the wrench into the filter window (a running median, :attr:`force_in_base`) and enforce
        the safety limit."""
        raw = self.robot.ft_rotation_in_base() @ self.robot.wrench()[:3]
        self.window.append(raw)
        self.raw.append(raw)
        self.force_in_base = median_rows(self.window)
        magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
        self.peak_force = max(self.peak_force, magnitude)
        if self.guard and magnitude > self.limit:
            raise ForceLimitExceeded(magnitude, self.limit, self.phase)

    def noise(self) -> float:
        """The F/T force noise now: the rms over the axes of the raw force's spread over the last
        ``noise_samples`` ticks [N] (0 before there are 10)."""
        if len(self.raw) < 10:
            return 0.0
        return float(np.sqrt(np.mean(np.var(np.array(self.raw), axis=0))))

    def filter_samples(self, noise: float) -> int:
        """Ticks in the running median of the wrench for an F/T force noise ``noise`` [N, rms per axis]:
        ``force_filter_samples``, or as many as keep the median's noise under ``filtered_noise``."""
        c = self.config
        needed = math.ceil((_MEDIAN_SPREAD * noise / c.sensing.filtered_noise) ** 2)
        return max(c.sensing.force_filter_samples, min(needed, c.sensing.force_filter_max_samples))

    def filtered_noise_now(self) -> float:
        """The noise of the filtered force in the toggle in progress [N per axis]: the F/T force noise measured
        above the part through the running median of its length."""
        return _MEDIAN_SPREAD * self.rest_noise / math.sqrt(self.window.maxlen or 1)

    def tare_samples(self, noise: float) -> int:
        """Readings a tare averages for an F/T force noise ``noise`` [N, rms per axis]: ten, or as many as keep
        the tare's error under ``tare_noise``."""
        c = self.config
        return max(TARE_SAMPLES, min(math.ceil((noise / c.sensing.tare_noise) ** 2), c.sensing.tare_max_samples))


__all__ = ["ForceWatch", "median_rows"]
