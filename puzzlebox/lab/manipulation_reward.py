"""Rewards of ``puzzlebox/BoxManipulation-v0``.

- ``sparse``: 1 on the step the goal is reached, else 0.
- ``dense``: the sparse reward plus potential-based shaping, ``r = phi(s') - phi(s) + [goal]`` (Ng et al. 1999: the
  same optimal policies as the sparse reward, no gain in hovering short of the goal or in ending an episode
  early). The potential ``phi`` in ``[0, 1]`` follows a shortest solution from the parts' current states
  (``models.lock_table``):

      phi = (done + (reach + progress) / 2) / L0,   reach = 1 - tanh(10 d)

  with ``L0`` the length of a shortest solution from the start, ``done = max(0, L0 - L)`` the toggles made of it
  (``L`` the length from now), ``d`` the distance [m] from the TCP to the grasp point on the handle of the part
  that solution moves next (``reach``: 1 on it, 0.24 at 10 cm) and ``progress`` that part's joint travel
  towards its other state, 0 .. 1. A toggle that lengthens the solution lowers ``phi``.

The potential reads the simulator's truth (true TCP, joints and states): a reward, never an observation.
"""

from __future__ import annotations

import math

import numpy as np

from puzzlebox.models import LockTable
from puzzlebox.twin.session import TwinSession

REWARD_MODES = ("sparse", "dense")
"""The reward modes."""
REACH_SCALE = 10.0
"""Gain of the distance in ``reach = 1 - tanh(REACH_SCALE * d)`` [1/m]."""


def _bits(states: np.ndarray) -> int:
    return int(sum(int(s) << i for i, s in enumerate(states)))


class ProgressPotential:
    """``phi`` of one session (see the module docstring); shortest solutions are cached per state."""

    def __init__(self, session: TwinSession) -> None:
        self.session = session
        self.table: LockTable = session.rules
        self._solutions: dict[int, list[int]] = {}
        self._states: np.ndarray | None = None
        self._state_bits = 0
        self._start = len(self._solution(0))
        self._tcp = session.model.site(session.scene.names.tcp_site).id

    def _solution(self, bits: int) -> list[int]:
        if bits not in self._solutions:
            self._solutions[bits] = self.table.shortest_solution(bits) or []
        return self._solutions[bits]

    def _now(self) -> tuple[np.ndarray, int]:
        """The parts' states and their bitmask (recomputed only when they changed: the twin then makes a new array)."""
        states = self.session.states.states
        if states is not self._states:
            self._states, self._state_bits = states, _bits(states)
        return states, self._state_bits

    def solved(self) -> bool:
        """Whether the parts' states meet the goal."""
        return self.table.is_goal(self._now()[1])

    def __call__(self, grasp_points: np.ndarray) -> float:
        """``phi`` now, given every handle's grasp point ``(N, 3)`` [m]."""
        states, bits = self._now()
        plan = self._solution(bits)
        if not plan or not self._start:
            return 1.0
        part = plan[0]
        d = self.session.data
        offset = d.site_xpos[self._tcp] - grasp_points[part]
        reach = 1.0 - math.tanh(REACH_SCALE * math.sqrt(float(offset @ offset)))
        fraction = float(d.qpos[self.session.component_qpos[part]]) / float(self.session.travel[part])
        progress = min(max(fraction if states[part] == 0 else 1.0 - fraction, 0.0), 1.0)
        done = max(0, self._start - len(plan))
        return (done + 0.5 * (reach + progress)) / self._start


__all__ = ["REACH_SCALE", "REWARD_MODES", "ProgressPotential"]
