"""The oracle agent: knows the lock rules and plays a shortest plan — the ceiling on performance.

It is given the spec, so it knows the lock graph; it still only sees the world through observations,
so it matches observed components to spec components by kind and position (the observation order is
shuffled) and replans from the observed state after every action (so a jam costs one retry).
"""

from __future__ import annotations

import numpy as np

from puzzlebox.learning.errors import LearningError
from puzzlebox.models import LockTable, PuzzleSpec, SceneObservation, TryResult

KIND_MISMATCH_COST = 1.0
"""Matching cost of a kind mismatch [m-equivalent]: larger than any position error we expect."""


class OracleAgent:
    name = "oracle"

    def __init__(self, spec: PuzzleSpec) -> None:
        self.spec = spec
        self.table = LockTable.from_spec(spec)
        self._spec_of_obs = np.arange(len(spec.components))

    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        if len(observation) != len(self.spec.components):
            raise LearningError(
                f"oracle for {self.spec.name!r} knows {len(self.spec.components)} components, "
                f"the world shows {len(observation)}"
            )
        true_poses = self.spec.poses_in_world()
        position_size = 2 if true_poses.shape[1] == 3 else 3  # planar [x, y, yaw]; 6-DOF [x, y, z, ...]
        true_xy = true_poses[:, :position_size]
        seen_xy = observation.poses[:, :position_size]
        cost = np.linalg.norm(seen_xy[:, None, :] - true_xy[None, :, :], axis=2)
        true_kinds = np.array(self.spec.kinds)
        cost += KIND_MISMATCH_COST * (np.array(observation.kinds)[:, None] != true_kinds[None, :])
        from scipy.optimize import linear_sum_assignment  # scipy on first use (start-up time)

        rows, cols = linear_sum_assignment(cost)
        self._spec_of_obs = cols[np.argsort(rows)]

    def choose(self, observation: SceneObservation) -> int:
        state = 0
        for obs_index, s in enumerate(observation.states):
            state |= int(s) << int(self._spec_of_obs[obs_index])
        plan = self.table.shortest_solution(state)
        if not plan:  # already solved, or the observed state is a dead end: nothing useful to do
            return 0
        return int(np.flatnonzero(self._spec_of_obs == plan[0])[0])

    def record(self, index: int, result: TryResult, observation: SceneObservation) -> None:
        pass

    def end_episode(self, solved: bool) -> None:
        pass
