"""Symbolic observations: what the agent knows of a scene — kinds, poses and states, never names
or lock rules. Produced by the symbolic environment and (later) by the robot's perception alike."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ComponentObservation:
    """One component as seen by the agent.

    Attributes:
        kind: kind name (``door``, ``slide``, ``wheel``, ...), as perceived — possibly wrong.
        pose_in_world: the component frame in the world (robot base) frame, ``[x, y, yaw]``
            [m, m, rad] for planar domains or ``[x, y, z, roll, pitch, yaw]`` for 3-D ones.
        state: 0 (closed, initial) or 1 (open).
    """

    kind: str
    pose_in_world: np.ndarray
    state: int


@dataclass(frozen=True)
class SceneObservation:
    """All components of the scene, in an order that carries no meaning (shuffled per episode).

    Attributes:
        components: the components; the agent's action ``i`` refers to ``components[i]``.
        goal_index: index of the component that must reach ``goal_state``.
        goal_state: the state that solves the puzzle (normally 1).
    """

    components: tuple[ComponentObservation, ...]
    goal_index: int
    goal_state: int = 1

    def __len__(self) -> int:
        return len(self.components)

    @property
    def kinds(self) -> tuple[str, ...]:
        return tuple(c.kind for c in self.components)

    @property
    def states(self) -> np.ndarray:
        return np.array([c.state for c in self.components], dtype=np.int64)

    @property
    def poses(self) -> np.ndarray:
        """``(N, pose_dim)`` array of the components' poses in the world frame."""
        return np.stack([c.pose_in_world for c in self.components])

    @property
    def solved(self) -> bool:
        return self.components[self.goal_index].state == self.goal_state
