"""The ``World`` protocol over the symbolic environment: what the agent meets in training."""

from __future__ import annotations

from puzzlebox.learning.puzzle_env import PuzzleEnv, PuzzleEnvConfig
from puzzlebox.models import ComponentObservation, PuzzleSpec, SceneObservation, TryResult


class SymbolicWorld:
    """A puzzle spec the agent can observe and act on, one episode long.

    ``max_actions`` of the config is ignored here (the trial loop keeps its own budget): the world
    never truncates on its own.
    """

    def __init__(self, spec: PuzzleSpec, seed: int, config: PuzzleEnvConfig | None = None) -> None:
        self.env = PuzzleEnv(spec, config)
        self._obs, _ = self.env.reset(seed=seed)

    def observe(self) -> SceneObservation:
        obs = self._obs
        components = tuple(
            ComponentObservation(self.env.kind_names[int(k)], pose.copy(), int(s))
            for k, pose, s in zip(obs["kinds"], obs["poses"], obs["states"], strict=True)
        )
        return SceneObservation(components, goal_index=int(obs["goal"]), goal_state=self.env.table.goal_state)

    def try_toggle(self, index: int) -> TryResult:
        self._obs, _, _, _, info = self.env.step(index)
        return TryResult.from_moved(bool(info["moved"]))

    def ground_truth_name(self, index: int) -> str:
        """Spec name of the component at observation ``index`` — for logs and evaluation only."""
        return self.env.puzzle.components[self.env.spec_index(index)].name
