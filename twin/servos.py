"""The arm's servo interface as a real controller takes commands: after a latency, and not at all
during an occasional stall (:class:`~twin.reality.ArmReality`).

Joint commands wait in a queue keyed by the physics step at which they take effect (the latency
rounded up to whole steps: never shorter than the profile's, and 5 ms at 2 ms steps is 6 ms, where
Python's half-to-even ``round`` would make it 4 ms); the session steps up to each one and writes it to
the servos. Stalls are a Poisson process (``stall_rate``) of windows ``stall_duration`` long: a command
sent during one is held until it ends, and the backlog a stall leaves is then taken in order, one command
per controller cycle (:data:`CONTROLLER_CYCLE`): the first at the stall's end, the last (backlog - 1) cycles
later, as a controller that resumes works through the commands it received (writing them all at once would
jump the arm to the last one in one physics step and saturate the wrist servos). A command sent while a
backlog drains waits its turn behind it. Outside stalls and their backlogs a command waits its latency only.
Gripper commands take effect at once (the gripper has its own controller). With no latency and no stalls a
command is written immediately, as to an ideal servo.
"""

from __future__ import annotations

import collections
import math
from typing import Any

import mujoco
import numpy as np

from puzzlebox.twin.reality import ArmReality

CONTROLLER_CYCLE = 0.004
"""The arm controller's servo cycle [s]: it takes at most one joint command per cycle (the xArm's servo mode
runs at 250 Hz, REALITY_NOTES.md §2 "command / feedback rate", U12: xArm-Python-SDK#5)."""


def _whole_steps(seconds: float, timestep: float) -> int:
    """``seconds`` rounded up to whole physics steps; a quotient a rounding error above a whole number
    (``0.05 / 0.002``) stays that number."""
    return math.ceil(seconds / timestep - 1e-9)


class Servos:
    """Joint and gripper commands of a session (see the module docstring)."""

    def __init__(
        self, data: mujoco.MjData, arm_actuators: np.ndarray, gripper_actuator: int, config: ArmReality, timestep: float
    ) -> None:
        self._data = data
        self._arm = arm_actuators
        self._gripper = gripper_actuator
        self._dt = timestep
        self.latency_steps = _whole_steps(config.command_latency, timestep)
        self._stall_steps = _whole_steps(config.stall_duration, timestep) if config.stall_rate > 0 else 0
        self._stall_rate = config.stall_rate
        self.cycle_steps = max(1, _whole_steps(CONTROLLER_CYCLE, timestep))

    @property
    def immediate(self) -> bool:
        return self.latency_steps == 0 and self._stall_steps == 0

    def _step(self) -> int:
        return round(self._data.time / self._dt)

    def reset(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self._queue: collections.deque[tuple[int, np.ndarray]] = collections.deque()
        self._stall_start = self._next_stall(0) if self._stall_steps else None
        self._backlog_free = 0  # the first step at which a stall's backlog can take its next command

    def _next_stall(self, after: int) -> int:
        return after + max(1, math.ceil(self._rng.exponential(1.0 / self._stall_rate) / self._dt))

    def command_joints(self, q: np.ndarray) -> None:
        """Queue arm servo targets [rad] (checked by the caller)."""
        if self.immediate:
            self._data.ctrl[self._arm] = q
            return
        now = self._step()
        due = now + self.latency_steps
        held = False  # by a stall or the backlog one left: then it takes a controller cycle of its own
        if self._stall_start is not None:
            while self._stall_start + self._stall_steps <= now:  # stalls already over
                self._stall_start = self._next_stall(self._stall_start + self._stall_steps)
            if self._stall_start <= now and self._stall_start + self._stall_steps > due:
                due, held = self._stall_start + self._stall_steps, True
        if due < self._backlog_free:
            due, held = self._backlog_free, True
        if self._queue:
            due = max(due, self._queue[-1][0])  # a controller keeps the order of its commands
        if held:
            self._backlog_free = due + self.cycle_steps
        self._queue.append((due, np.array(q, dtype=float)))
        self.apply_due()

    def command_gripper(self, ctrl: float) -> None:
        """Gripper actuator target [its ctrl units], at once."""
        self._data.ctrl[self._gripper] = ctrl

    def steps_to_next(self) -> int | None:
        """Physics steps until the next queued command takes effect (None: none queued)."""
        return max(1, self._queue[0][0] - self._step()) if self._queue else None

    def apply_due(self) -> None:
        """Write every queued command whose time has come to the servos."""
        now = self._step()
        while self._queue and self._queue[0][0] <= now:
            self._data.ctrl[self._arm] = self._queue.popleft()[1]

    def get_state(self) -> dict[str, Any]:
        return {
            "rng": self._rng.bit_generator.state,
            "queue": [(due, q.copy()) for due, q in self._queue],
            "stall_start": self._stall_start,
            "backlog_free": self._backlog_free,
        }

    def set_state(self, state: dict[str, Any]) -> None:
        self._rng.bit_generator.state = state["rng"]
        self._queue = collections.deque((due, q.copy()) for due, q in state["queue"])
        self._stall_start = state["stall_start"]
        self._backlog_free = state["backlog_free"]
