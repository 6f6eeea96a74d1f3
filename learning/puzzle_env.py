"""The symbolic puzzle environment: a ``gymnasium.Env`` over a puzzle spec.

Action ``n`` tries to toggle the component shown at observation index ``n``; it moves iff no active
lock rule holds it (and, with faults enabled, it did not jam). Observations hold the components'
states, kinds, world-frame poses and which one is the goal — never names or lock rules — in an order
shuffled at every reset, as in the paper. The episode terminates when the goal is reached and is
truncated after ``max_actions`` actions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from puzzlebox.learning.errors import ConfigError, InvalidAction
from puzzlebox.models import LockTable, PuzzleSpec
from puzzlebox.models.disassembly_kinds import family_kind_names
from puzzlebox.models.geometry import wrap_angle


@dataclass(frozen=True)
class FaultConfig:
    """Faults injected into the symbolic world (for robustness experiments); all off by default."""

    jam_probability: float = 0.0
    """Chance that a try on an unlocked component fails to move it anyway, per try [0..1]."""
    misreported_kinds: int = 0
    """Number of components whose kind is reported as another kind, drawn at each reset."""
    position_noise_std: float = 0.0
    """Standard deviation of Gaussian noise on each observed x and y, drawn at each reset [m]."""
    yaw_noise_std: float = 0.0
    """Standard deviation of Gaussian noise on each observed yaw, drawn at each reset [rad]."""

    def check(self, num_components: int) -> None:
        if not 0.0 <= self.jam_probability <= 1.0:
            raise ConfigError(f"jam_probability must be in [0, 1], got {self.jam_probability}")
        if not 0 <= self.misreported_kinds <= num_components:
            raise ConfigError(f"misreported_kinds must be in 0..{num_components}, got {self.misreported_kinds}")
        if self.position_noise_std < 0.0 or self.yaw_noise_std < 0.0:
            raise ConfigError("noise standard deviations must be >= 0")


@dataclass(frozen=True)
class PuzzleEnvConfig:
    """Configuration of :class:`PuzzleEnv`."""

    max_actions: int = 50
    """Actions before the episode is truncated."""
    shuffle: bool = True
    """Shuffle the component order at every reset (the paper does); False keeps the spec's order."""
    goal_reward: float = 1.0
    """Reward on the action that reaches the goal."""
    step_reward: float = 0.0
    """Reward on every other action (e.g. -1 for a per-action cost)."""
    faults: FaultConfig = field(default_factory=FaultConfig)


class PuzzleEnv(gym.Env[dict[str, Any], np.int64]):
    """A puzzle spec as a gymnasium environment (see the module docstring).

    The puzzle is :attr:`puzzle` (``spec`` is gymnasium's registration record).

    Observation (a ``Dict``): ``states`` (N,) 0/1; ``kinds`` (N,) kind codes (index in :attr:`kind_names`,
    ``models.disassembly_kinds.family_kind_names(spec.kinds)``: the paper's three kinds, ``models.KIND_NAMES``,
    for a paper box; every registered kind (door, slide, wheel, drawer, lever) for a box with another kind; the
    disassembly kinds for a disassembly scene); ``poses`` (N, D) component poses in the
    world frame — ``[x, y, yaw]`` [m, m, rad] for planar puzzles, the box placed at ``box.pose`` (identity
    when absent), ``[x, y, z, roll, pitch, yaw]`` for disassembly scenes;
    ``goal`` the index of the goal component. Info: ``moved`` (bool) and ``num_actions``.
    """

    metadata = {"render_modes": ["ansi"], "render_fps": 1}

    def __init__(self, spec: PuzzleSpec, config: PuzzleEnvConfig | None = None, render_mode: str | None = None) -> None:
        if not isinstance(spec, PuzzleSpec):  # (a path: PuzzleSpec.from_json(Path(...).read_text()) reads one)
            raise ConfigError(f"spec must be a PuzzleSpec, got {type(spec).__name__} {spec!r:.60}")
        if config is not None and not isinstance(config, PuzzleEnvConfig):
            raise ConfigError(f"config must be a PuzzleEnvConfig or None, got {type(config).__name__}")
        self.puzzle = spec
        self.config = config or PuzzleEnvConfig()
        n = len(spec.components)
        self.config.faults.check(n)
        if self.config.max_actions < 1:
            raise ConfigError(f"max_actions must be >= 1, got {self.config.max_actions}")
        if render_mode not in (None, "ansi"):
            raise ConfigError(f"render_mode must be None or 'ansi', got {render_mode!r}")
        self.render_mode = render_mode
        self.table = LockTable.from_spec(spec)
        self._true_poses = spec.poses_in_world()
        self.kind_names = family_kind_names(spec.kinds)
        """The kind family of the spec: observed kind codes are indices here (``models.KIND_NAMES`` for
        paper boxes, every registered kind for boxes with another kind,
        ``models.disassembly_kinds.DISASSEMBLY_KIND_NAMES`` for disassembly scenes)."""
        self._true_kinds = np.array([self.kind_names.index(c.kind) for c in spec.components], dtype=np.int64)
        self.action_space = spaces.Discrete(n)
        self.observation_space = spaces.Dict(
            {
                "states": spaces.MultiBinary(n),
                "kinds": spaces.MultiDiscrete(np.full(n, len(self.kind_names))),
                "poses": pose_space(self._true_poses.shape),
                "goal": spaces.Discrete(n),
            }
        )
        self.state = 0  # bitmask over spec.components
        self.num_actions = 0
        self.order = np.arange(n)  # observation index -> spec index
        self._kinds = self._true_kinds.copy()  # as observed this episode, in spec order
        self._poses = self._true_poses.copy()

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed)
        rng = self.np_random
        n = len(self.puzzle.components)
        faults = self.config.faults
        self.state = 0
        self.num_actions = 0
        self.order = rng.permutation(n) if self.config.shuffle else np.arange(n)
        self._kinds = self._true_kinds.copy()
        if faults.misreported_kinds:
            family_codes = list(range(len(self.kind_names)))  # puzzle boxes: door, slide, wheel as before
            for j in rng.choice(n, size=faults.misreported_kinds, replace=False):
                others = [c for c in family_codes if c != self._true_kinds[j]]
                self._kinds[j] = others[int(rng.integers(len(others)))]
        self._poses = self._true_poses.copy()
        if faults.position_noise_std > 0.0:
            self._poses[:, :2] += rng.normal(0.0, faults.position_noise_std, size=(n, 2))
        if faults.yaw_noise_std > 0.0:
            yaw = self._poses[:, -1] + rng.normal(0.0, faults.yaw_noise_std, size=n)
            self._poses[:, -1] = wrap_angle(yaw)
        return self._observation(), {"moved": False, "num_actions": 0}

    def step(self, action: Any) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        n = len(self.puzzle.components)
        if not isinstance(action, int | np.integer) or not 0 <= int(action) < n:
            raise InvalidAction(f"action must be an integer in 0..{n - 1}, got {action!r}")
        j = int(self.order[int(action)])
        self.num_actions += 1
        moved = self.table.can_move(self.state, j)
        if moved and self.config.faults.jam_probability > 0.0:
            moved = bool(self.np_random.random() >= self.config.faults.jam_probability)
        if moved:
            self.state ^= 1 << j
        terminated = self.table.is_goal(self.state)
        truncated = not terminated and self.num_actions >= self.config.max_actions
        reward = self.config.goal_reward if terminated else self.config.step_reward
        return (
            self._observation(),
            float(reward),
            terminated,
            truncated,
            {
                "moved": moved,
                "num_actions": self.num_actions,
            },
        )

    def spec_index(self, index: int) -> int:
        """The spec component behind observation ``index`` (ground truth: for evaluation only)."""
        return int(self.order[index])

    def _observation(self) -> dict[str, Any]:
        states = (self.state >> self.order) & 1
        return {
            "states": states.astype(np.int8),
            "kinds": self._kinds[self.order].copy(),
            "poses": self._poses[self.order].copy(),
            "goal": np.int64(int(np.flatnonzero(self.order == self.table.goal)[0])),
        }

    def render(self) -> str | None:
        if self.render_mode != "ansi":
            return None
        obs = self._observation()
        lines = [f"{self.puzzle.name}: {self.num_actions} action(s)"]
        for i in range(len(self.order)):
            goal = " (goal)" if i == obs["goal"] else ""
            x, y = obs["poses"][i][:2]
            kind = self.kind_names[obs["kinds"][i]]
            lines.append(f"  [{i}] {kind:<6} at ({x:+.3f}, {y:+.3f}) m  state {obs['states'][i]}{goal}")
        return "\n".join(lines)


POSITION_BOUND = 100.0
"""Bound of the observed positions [m]: far beyond any table, finite so spaces can be sampled."""


def pose_space(shape: tuple[int, ...]) -> spaces.Box:
    """Positions within +-POSITION_BOUND [m], angles within [-pi, pi] [rad]."""
    n, dim = shape
    per_pose = np.array([POSITION_BOUND] * (dim - 1 if dim == 3 else 3) + [np.pi] * (1 if dim == 3 else 3))
    high = np.tile(per_pose, (n, 1))
    return spaces.Box(-high, high, dtype=np.float64)
