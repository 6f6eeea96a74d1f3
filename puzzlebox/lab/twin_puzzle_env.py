"""``puzzlebox/TwinPuzzle-v0``: the twin at the option level, as a gymnasium environment.

The same observation and action spaces as the symbolic ``puzzlebox/Puzzle-v0``
(:class:`puzzlebox.learning.PuzzleEnv`), so a policy trained on the symbolic simulator runs unchanged here — the
paper's sim-to-real experiment in gymnasium's terms. One step is one try, made end to end by the robot's pipeline:
the survey's ArUco perception, the motion primitives, the outcome felt through the wrist F/T sensor, under any
reality profile with its calibration (:class:`~puzzlebox.lab.TrialConfig`). Observations are what the pipeline
perceived: each component's kind as told, its closed pose in the world frame ``[x, y, yaw]`` [m, m, rad] as
seen, its state as sensed; the order is shuffled per episode. ``info`` holds the try's ``outcome`` (``moved``,
``blocked`` or ``failed``), its ``reason``, ``moved``, ``give_up`` (the pipeline cannot try that part again),
``num_actions`` and the simulated time ``sim_time_s`` [s]; ``true_moved`` (the simulator's truth) only with
``ground_truth=True``, for evaluation.

Each ``reset`` opens a new twin session (a seeded cell and, under a profile that places boxes, a new placement)
and surveys the box: a few seconds of wall time. ``render()`` (``render_mode="rgb_array"``) draws the scene from
the overview camera without touching what the pipeline senses. ``close()`` releases the session and renderer.
"""

from __future__ import annotations

import contextlib
import dataclasses
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from puzzlebox.lab.errors import TrialConfigError
from puzzlebox.lab.trial_config import TrialConfig
from puzzlebox.lab.twin_trial import trial_world, twin_session
from puzzlebox.learning.errors import InvalidAction
from puzzlebox.learning.puzzle_env import pose_space
from puzzlebox.models import PuzzleSpec, SceneObservation
from puzzlebox.models.disassembly_kinds import family_kind_names
from puzzlebox.skills.robot_world import RobotWorld
from puzzlebox.twin.session import TwinSession

__all__ = ["TwinPuzzleEnv"]

RENDER_SIZE = (480, 640)
"""Height and width of ``render()``'s frames [px]."""


class TwinPuzzleEnv(gym.Env[dict[str, Any], np.int64]):
    """A puzzle box in the twin as a gymnasium environment (see the module docstring).

    Args:
        spec: the puzzle box (a disassembly scene has no twin).
        config: the trial's settings (``reality``, ``calibration``, ``locks``, ``misreport_kind``; ``sim`` must be
            ``twin``; ``seed`` is the first episode's when ``reset`` gets none); default: ``ideal``.
        max_actions: tries before an episode is truncated.
        ground_truth: add the simulator's ``true_moved`` to ``info`` (evaluation only: never for deciding).
        render_mode: None or ``"rgb_array"``.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 2}

    def __init__(
        self,
        spec: PuzzleSpec,
        config: TrialConfig | None = None,
        max_actions: int = 30,
        ground_truth: bool = False,
        render_mode: str | None = None,
    ) -> None:
        if not isinstance(spec, PuzzleSpec):
            raise TrialConfigError(f"spec must be a PuzzleSpec, got {type(spec).__name__} {spec!r:.60}")
        if config is not None and not isinstance(config, TrialConfig):
            raise TrialConfigError(f"config must be a TrialConfig or None, got {type(config).__name__}")
        if isinstance(max_actions, bool) or not isinstance(max_actions, int | np.integer):
            raise TrialConfigError(f"max_actions must be an integer, got {type(max_actions).__name__}")
        config = config or TrialConfig()
        if spec.box is None:
            raise TrialConfigError(f"spec {spec.name!r} is a disassembly scene: the twin holds puzzle boxes only")
        if config.sim != "twin":
            raise TrialConfigError(f"TwinPuzzle-v0 runs the twin: config.sim must be 'twin', got {config.sim!r}")
        if max_actions < 1:
            raise TrialConfigError(f"max_actions must be at least 1, got {max_actions}")
        if render_mode not in (None, "rgb_array"):
            raise TrialConfigError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.puzzle, self.config, self.max_actions = spec, config, max_actions
        self.ground_truth, self.render_mode = ground_truth, render_mode
        n = len(spec.components)
        self.kind_names = family_kind_names(spec.kinds)
        self.action_space = spaces.Discrete(n)
        self.observation_space = spaces.Dict(
            {
                "states": spaces.MultiBinary(n),
                "kinds": spaces.MultiDiscrete(np.full(n, len(self.kind_names))),
                "poses": pose_space((n, 3)),
                "goal": spaces.Discrete(n),
            }
        )
        self.world: RobotWorld | None = None
        """The episode's world (perception and primitives over the twin's robot)."""
        self.session: TwinSession | None = None
        """The episode's twin session (for evaluation and rendering: never for deciding)."""
        self.num_actions = 0
        self._episode = contextlib.ExitStack()
        self._episodes = 0
        self._renderer: Any = None
        self._seed = config.seed

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed)
        if seed is not None:
            self._seed = int(seed)
        elif self._episodes:  # a later episode without a seed: the next from the generator
            self._seed = int(self.np_random.integers(2**31 - 1))
        self._close_episode()
        config = dataclasses.replace(self.config, seed=self._seed)
        self.session = self._episode.enter_context(twin_session(self.puzzle, config))
        self.world = trial_world(self.session, config)
        self._episodes += 1
        self.num_actions = 0
        return self._observation(self.world.observe()), {"num_actions": 0, "sim_time_s": self.session.time}

    def step(self, action: Any) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        world, session = self.world, self.session
        if world is None or session is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        n = len(self.puzzle.components)
        if not isinstance(action, int | np.integer) or not 0 <= int(action) < n:
            raise InvalidAction(f"action must be an integer in 0..{n - 1}, got {action!r}")
        result = world.try_toggle(int(action))
        self.num_actions += 1
        scene = world.observe()
        terminated = bool(scene.solved)
        truncated = not terminated and self.num_actions >= self.max_actions
        info: dict[str, Any] = {"outcome": result.outcome, "reason": result.reason, "moved": result.moved,
                                "give_up": result.give_up, "num_actions": self.num_actions,
                                "sim_time_s": session.time}  # fmt: skip
        if self.ground_truth and world.log:
            info["true_moved"] = world.log[-1].true_moved
        return self._observation(scene), 1.0 if terminated else 0.0, terminated, truncated, info

    def render(self) -> np.ndarray | None:
        session = self.session
        if self.render_mode != "rgb_array" or session is None:
            return None
        if self._renderer is None:  # one per episode: each session compiles its own model (the box placed anew)
            import mujoco

            self._renderer = mujoco.Renderer(session.model, *RENDER_SIZE)
        self._renderer.update_scene(session.data, camera=session.scene.names.overview_camera)
        return self._renderer.render().copy()

    def close(self) -> None:
        self._close_episode()

    def _close_episode(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self.world = self.session = None
        self._episode.close()
        self._episode = contextlib.ExitStack()

    def _observation(self, scene: SceneObservation) -> dict[str, Any]:
        return {
            "states": np.array([c.state for c in scene.components], dtype=np.int8),
            "kinds": np.array([self.kind_names.index(c.kind) for c in scene.components], dtype=np.int64),
            "poses": np.array([c.pose_in_world for c in scene.components], dtype=np.float64),
            "goal": np.int64(scene.goal_index),
        }
