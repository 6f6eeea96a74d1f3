"""The wrist force/torque sensor as a real one reads: noise, bias, drift, sampling, delay, quantisation
and saturation on top of the load MuJoCo's sensors give (:class:`~twin.reality.ForceTorqueReality`).

The load is what the gripper exerts on the flange (MuJoCo's force/torque sensors report the opposite,
the arm's support of the gripper). A reading is ``clip(load(t - delay) + bias + drift·t + noise)``,
quantised, minus the last tare. Each reading draws fresh noise, as from a sensor sampling far faster
than it reports; the load itself is sampled at ``rate_hz`` and held.
"""

from __future__ import annotations

import collections
import math
from typing import Any

import mujoco
import numpy as np

from puzzlebox.twin.reality import ForceTorqueReality
from puzzlebox.twin.sensors.random_vectors import random_vector


class ForceTorqueSensor:
    """One wrist F/T sensor of a session (see the module docstring)."""

    def __init__(
        self, data: mujoco.MjData, force_adr: int, torque_adr: int, config: ForceTorqueReality, timestep: float
    ) -> None:
        self._data = data
        self._force = slice(force_adr, force_adr + 3)
        self._torque = slice(torque_adr, torque_adr + 3)
        self.config = config
        self.sample_steps = max(1, round(1.0 / (config.rate_hz * timestep))) if config.rate_hz > 0 else 0
        """Physics steps between two samples of the load (0: the load is read continuously)."""
        self._history_length = math.ceil(config.delay * config.rate_hz) + 3
        noise = np.array([config.force_noise] * 3 + [config.torque_noise] * 3)
        self._noise = noise if noise.any() else None
        limits = np.full(6, np.inf)
        if config.force_range is not None:
            limits[:3] = config.force_range
        if config.torque_range is not None:
            limits[3:] = config.torque_range
        self._limits = limits if np.isfinite(limits).any() else None
        self._low = None if self._limits is None else -self._limits
        resolution = np.array([config.force_resolution] * 3 + [config.torque_resolution] * 3)
        self._resolution = resolution if resolution.any() else None
        self._quantised = resolution > 0
        self._step = np.where(self._quantised, resolution, 1.0)  # quantisation step (1: an unquantised axis)

    def reset(self, rng: np.random.Generator) -> None:
        """A new trial: bias and drift direction drawn from ``rng``, no tare, the load sampled now."""
        c = self.config
        self._rng = rng
        self.bias = np.concatenate([random_vector(rng, c.force_bias), random_vector(rng, c.torque_bias)])
        """Offset present at reset [N, N·m] (evaluation only)."""
        self.drift_rate = np.concatenate(
            [random_vector(rng, c.force_drift / 60.0), random_vector(rng, c.torque_drift / 60.0)]
        )
        """Zero drift [N/s, N·m/s] (evaluation only)."""
        self._offset = np.zeros(6)
        self._history: collections.deque[tuple[float, np.ndarray]] = collections.deque(maxlen=self._history_length)
        if self.sample_steps:
            self.sample()

    def load(self) -> np.ndarray:
        """The true load now ``[F, T]`` in the sensor frame [N, N·m]: ground truth, not for skills."""
        d = self._data.sensordata
        return -np.concatenate([d[self._force], d[self._torque]])

    def load_force(self) -> np.ndarray:
        """``load()[:3]``, the true force [N], without assembling the torque: ground truth, not for skills."""
        return -self._data.sensordata[self._force]

    def sample(self) -> None:
        """Record a sample of the load at the current time (the session calls it every :attr:`sample_steps`)."""
        self._history.append((float(self._data.time), self.load()))

    def _delayed_load(self, time: float) -> np.ndarray:
        if not self.sample_steps:
            return self.load()
        newest_allowed = time - self.config.delay + 1e-9
        for sample_time, load in reversed(self._history):
            if sample_time <= newest_allowed:
                return load
        return self._history[0][1]  # just after reset: nothing that old yet

    def _reading(self, time: float) -> np.ndarray:
        value = self._delayed_load(time) + self.bias + self.drift_rate * time
        if self._noise is not None:
            value = value + self._rng.normal(0.0, self._noise)
        # the sensor's raw range, before any tare (np.clip of a finite value); _low is None with _limits
        if self._limits is not None and self._low is not None:
            value = np.minimum(np.maximum(value, self._low), self._limits)
        if self._resolution is not None:
            value = np.where(self._quantised, np.round(value / self._step) * self._step, value)
        return value

    def read(self, time: float) -> np.ndarray:
        """``[Fx, Fy, Fz, Tx, Ty, Tz]`` in the sensor frame [N, N·m], minus the last tare."""
        return self._reading(time) - self._offset

    def tare(self, time: float, samples: int = 10) -> None:
        """Zero on the mean of ``samples`` readings (the sensor's bias reset)."""
        if samples < 1:
            raise ValueError(f"tare needs at least one sample, got {samples}")
        self._offset = np.mean([self._reading(time) for _ in range(samples)], axis=0)

    def get_state(self) -> dict[str, Any]:
        return {
            "rng": self._rng.bit_generator.state,
            "offset": self._offset.copy(),
            "history": [(t, w.copy()) for t, w in self._history],
            "bias": self.bias.copy(),
            "drift_rate": self.drift_rate.copy(),
        }

    def set_state(self, state: dict[str, Any]) -> None:
        self._rng.bit_generator.state = state["rng"]
        self._offset = state["offset"].copy()
        self._history = collections.deque(((t, w.copy()) for t, w in state["history"]), maxlen=self._history_length)
        self.bias = state["bias"].copy()
        self.drift_rate = state["drift_rate"].copy()
