"""Jams: a free component that sticks on some tries, as a real part with a burr or a warped rail does.

A *try* starts when a component that no lock rule holds leaves its rest position (by more than
:data:`START_FRACTION` of its travel). At that moment, with probability ``p`` (one draw per try), the
component jams: its latch constraint holds it where it stands, exactly as a lock would, so the robot
feels it blocked. The try ends once the gripper has touched none of the component (its handle, or its
plate that a push presses on) for ``release_after`` seconds: a jam is then released and the component's
rest position becomes wherever it now is. All draws come from one generator, in the order tries start,
so a session stays a pure function of its seed and commands.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

START_FRACTION = 0.02
"""Displacement from rest, as a fraction of the travel, that starts a try (1.7 deg of a door, 1 mm of a slide)."""


class Jams:
    """Decides, try by try, which free components jam (see the module docstring)."""

    def __init__(
        self,
        model: mujoco.MjModel,
        part_geoms: Sequence[np.ndarray | Sequence[int]],
        gripper_bodies: np.ndarray,
        travel: np.ndarray,
        probability: float,
        release_after: float,
    ) -> None:
        self._geom_component = np.full(model.ngeom, -1, dtype=np.int64)
        for c, geoms in enumerate(part_geoms):  # (keyed on the handle alone, a door pushed shut by its plate
            self._geom_component[np.asarray(geoms, dtype=np.int64)] = c  # drew a new jam every 0.5 s of the push)
        self._gripper_geom = np.isin(model.geom_bodyid, gripper_bodies)
        self._threshold = START_FRACTION * np.abs(travel)
        self.probability = probability
        self.release_after = release_after
        n = len(part_geoms)
        self.jammed = np.zeros(n, dtype=bool)
        self._in_try = np.zeros(n, dtype=bool)
        self._rest = np.zeros(n)
        self._last_contact = np.zeros(n)

    def reset(self, rng: np.random.Generator, q: np.ndarray) -> None:
        self._rng = rng
        self.jammed[:] = False
        self._in_try[:] = False
        self._rest = np.array(q, dtype=float)
        self._last_contact[:] = 0.0

    def touched(self, data: mujoco.MjData) -> np.ndarray:
        """Which components the gripper touches now."""
        touched = np.zeros(len(self.jammed), dtype=bool)
        if data.ncon:
            geoms = data.contact.geom[: data.ncon]
            for a, b in ((0, 1), (1, 0)):
                component = self._geom_component[geoms[:, a]]
                hit = (component >= 0) & self._gripper_geom[geoms[:, b]]
                touched[component[hit]] = True
        return touched

    def update(self, data: mujoco.MjData, q: np.ndarray, held: np.ndarray) -> bool:
        """Start and end tries at joint positions ``q`` given the components lock rules ``held``;
        True when :attr:`jammed` changed."""
        time = float(data.time)
        if data.ncon:
            self._last_contact[self.touched(data)] = time
        changed = False
        # this runs every control tick: the common case (no try starts, none ends) is kept to a few array ops
        moved = np.abs(q - self._rest) > self._threshold
        starting = np.flatnonzero(~self._in_try & ~held & moved) if moved.any() else ()
        for c in starting:  # in component order: a deterministic sequence of draws
            self._in_try[c] = True
            self._last_contact[c] = time
            if self._rng.random() < self.probability:
                self.jammed[c] = True
                changed = True
        if not self._in_try.any():
            return changed
        ending = np.flatnonzero(self._in_try & (time - self._last_contact >= self.release_after))
        for c in ending:
            self._in_try[c] = False
            self._rest[c] = q[c]
            if self.jammed[c]:
                self.jammed[c] = False
                changed = True
        return changed

    def get_state(self) -> dict[str, Any]:
        return {
            "rng": self._rng.bit_generator.state,
            "jammed": self.jammed.copy(),
            "in_try": self._in_try.copy(),
            "rest": self._rest.copy(),
            "last_contact": self._last_contact.copy(),
        }

    def set_state(self, state: dict[str, Any]) -> None:
        self._rng.bit_generator.state = state["rng"]
        self.jammed = state["jammed"].copy()
        self._in_try = state["in_try"].copy()
        self._rest = state["rest"].copy()
        self._last_contact = state["last_contact"].copy()
