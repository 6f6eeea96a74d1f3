"""``puzzlebox/BoxManipulation-v0``: a puzzle box in the twin at the low level, as a gymnasium environment.

The xArm-7 with its wrist F/T sensor, driven at :data:`~puzzlebox.lab.manipulation_control.CONTROL_HZ` (20 Hz) by
end-effector position deltas, a yaw delta and a gripper command within safe limits
(:mod:`puzzlebox.lab.manipulation_control`); observations are the robot's own readings plus the parts' joints or
small camera images (:mod:`puzzlebox.lab.manipulation_observation`); rewards sparse or shaped along a shortest
solution (:mod:`puzzlebox.lab.manipulation_reward`). An episode ends (``info["reason"]``):

- ``terminated`` with ``"goal"`` when the box's goal part reaches its goal state (``info["success"]``);
- ``terminated`` with ``"force limit"`` when the wrist force read exceeds the cell config's ``force_limit`` (60 N:
  a real arm's collision stop), or ``"diverged"`` when the physics did (a MuJoCo warning);
- ``truncated`` with ``"time limit"`` after ``max_steps`` steps.

Any puzzle-box spec (a :class:`~puzzlebox.models.PuzzleSpec`, a spec file, or a kind name for a one-part box of that
kind; default a one-part box with a free slide, :func:`puzzlebox.models.generator.single.single_part`), any reality
profile (its sensor noise in the observations, its physics in the box); ``random_pose`` stands the box at a random
reachable pose drawn from the seed at every reset (None: as the profile says, which ``realistic`` and ``harsh`` do).
``reset(seed=s)`` then the same actions give the same observations bit for bit: each seeded reset opens a new twin
session of seed ``s`` (a session whose profile draws nothing, ``ideal`` without placement, is reset in place).
``close()`` releases the session and every renderer.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any, cast

import gymnasium as gym
import numpy as np

from puzzlebox.lab.errors import ManipulationEnvError, SpecFileError
from puzzlebox.lab.manipulation_control import CONTROL_HZ, CONTROL_PERIOD, READY_QPOS, ArmController, ControlLimits
from puzzlebox.lab.manipulation_control import action_space as make_action_space
from puzzlebox.lab.manipulation_observation import OBS_MODES, Observer, observation_space
from puzzlebox.lab.manipulation_reward import REWARD_MODES, ProgressPotential
from puzzlebox.lab.spec_files import load_box_spec
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.errors import ModelsError
from puzzlebox.models.generator.single import single_part
from puzzlebox.models.kinds import get_kind, registered_kinds
from puzzlebox.models.mechanism_mjcf import LOCK_MODES, LockMode, mechanism_layout
from puzzlebox.models.placement import PlacementRange
from puzzlebox.models.scene import SceneConfig
from puzzlebox.skills.primitives import PrimitiveConfig
from puzzlebox.twin import renderer_pool
from puzzlebox.twin.cell_config import twin_cell_config
from puzzlebox.twin.errors import ProfileError, SimulationDiverged
from puzzlebox.twin.reality import IDEAL, PRESETS, RealityProfile, load_profile
from puzzlebox.twin.rendering import RenderConfig, Renderer
from puzzlebox.twin.scene_cache import compiled_scene
from puzzlebox.twin.session import TwinConfig, TwinSession

__all__ = ["BoxManipulationEnv"]

RENDER_SIZE = (640, 480)
"""Width and height of ``render()``'s frames [px]."""
SETTLE_TIME = 0.1
"""Physics run at reset before the F/T sensor is tared [s]."""
LATCH_PERIOD = TwinConfig().latch_period
"""Physics steps between the twin's latch updates where a latch may engage (its default)."""


def box_spec(spec: PuzzleSpec | str | Path | None) -> PuzzleSpec:
    """The puzzle box asked for: a spec, a spec file, a registered kind's name (a one-part box), or None (a slide)."""
    if spec is None:
        return single_part("slide")
    if isinstance(spec, str) and spec in registered_kinds() and not Path(spec).exists():
        return single_part(spec)
    if isinstance(spec, str | Path):
        try:
            return load_box_spec(spec, use="can be manipulated")
        except SpecFileError as err:
            raise ManipulationEnvError(f"spec: {err}") from err
    if not isinstance(spec, PuzzleSpec):
        raise ManipulationEnvError(
            f"spec must be a PuzzleSpec, a spec file, a kind name {list(registered_kinds())} or None, got "
            f"{type(spec).__name__}"
        )
    if spec.box is None:
        raise ManipulationEnvError(f"spec {spec.name!r} is a disassembly scene (no box): only puzzle boxes can be used")
    return spec


def _choice(name: str, value: object, choices: tuple[object, ...]) -> None:
    if value not in choices:
        raise ManipulationEnvError(f"{name} must be one of {list(choices)}, got {value!r}")


class BoxManipulationEnv(gym.Env[dict[str, Any], np.ndarray]):
    """A puzzle box under the xArm-7 at 20 Hz (see the module docstring).

    Args:
        spec: the box: a spec, a spec file, a kind name (a one-part box of it) or None (a one-part free slide).
        obs_mode: ``"state"`` (the robot's readings plus the parts' joints and handles, privileged) or ``"rgb"``
            (the robot's readings plus overview and wrist frames of ``image_size`` pixels square).
        reward_mode: ``"sparse"`` or ``"dense"`` (:mod:`puzzlebox.lab.manipulation_reward`).
        reality: a preset (``ideal``, ``realistic``, ``harsh``), a profile JSON file or a profile.
        random_pose: stand the box at a random reachable pose at each reset (None: as the profile does).
        control_yaw: let the actions turn the gripper (5 action dimensions; else 4).
        max_steps: steps before an episode is truncated (200: 10 s).
        image_size: side of the ``rgb`` frames [px].
        locks: ``contact`` (the box's lock mechanisms) or ``latch`` (rule-driven latches).
        limits: the control step's safe limits.
        render_mode: None or ``"rgb_array"`` (the overview camera at 640x480, without the profile's effects).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": CONTROL_HZ}

    def __init__(
        self,
        spec: PuzzleSpec | str | Path | None = None,
        obs_mode: str = "state",
        reward_mode: str = "dense",
        reality: str | Path | RealityProfile = "ideal",
        random_pose: bool | None = None,
        control_yaw: bool = True,
        max_steps: int = 200,
        image_size: int = 64,
        locks: str = "contact",
        limits: ControlLimits | None = None,
        render_mode: str | None = None,
    ) -> None:
        _choice("obs_mode", obs_mode, OBS_MODES)
        _choice("reward_mode", reward_mode, REWARD_MODES)
        _choice("locks", locks, LOCK_MODES)
        _choice("render_mode", render_mode, (None, "rgb_array"))
        if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
            raise ManipulationEnvError(f"max_steps must be an integer >= 1, got {max_steps!r}")
        if isinstance(image_size, bool) or not isinstance(image_size, int) or not 16 <= image_size <= 512:
            raise ManipulationEnvError(f"image_size must be an integer in 16..512 [px], got {image_size!r}")
        try:
            profile = load_profile(reality)
        except ProfileError as err:
            raise ManipulationEnvError(f"reality: {err} (presets: {sorted(PRESETS)})") from err
        if random_pose is not None:
            profile = dataclasses.replace(profile, placement=PlacementRange() if random_pose else None)
        self.max_steps, self.render_mode = max_steps, render_mode
        self.puzzle = box_spec(spec)
        self.obs_mode, self.reward_mode, self.reality = obs_mode, reward_mode, profile
        render = RenderConfig(width=image_size, height=image_size)
        scene = SceneConfig(locks=cast(LockMode, locks))
        self._check_box(scene)
        period = LATCH_PERIOD if self._latches_act(locks) else round(CONTROL_PERIOD / scene.timestep)
        self.twin_config = TwinConfig(scene=scene, home_qpos=READY_QPOS, render=render, latch_period=period)
        self.action_space = make_action_space(control_yaw)
        self._action_shape = (5,) if control_yaw else (4,)
        self.observation_space = observation_space(obs_mode, len(self.puzzle.components), image_size)
        self.controller = ArmController(limits or ControlLimits(), control_yaw)
        self.session: TwinSession | None = None
        """The episode's twin session (evaluation and rendering: the observations hold what the agent gets)."""
        self._observer: Observer | None = None
        self._potential: ProgressPotential | None = None
        self._primitives = PrimitiveConfig()  # the skills' force thresholds: the cell config's
        self._force_limit = self._primitives.sensing.force_limit
        self._reusable = dataclasses.replace(profile, name=IDEAL.name) == IDEAL  # draws nothing from its seed
        self._renderer: Renderer | None = None
        self._phi = 0.0
        self._steps = 0
        self._obs: dict[str, np.ndarray] = {}

    def _latches_act(self, locks: str) -> bool:
        """Whether a latch may ever engage: a rule no mechanism serves (every rule with ``locks="latch"``) or a jam.
        If not, the twin updates the parts' states and checks for divergence once a control step (its default,
        every 20 ms, lets a latch fall into place as a spring latch would), the physics unchanged."""
        rules = bool(self.puzzle.locks) and (locks == "latch" or bool(mechanism_layout(self.puzzle).unrealized))
        return rules or self.reality.physics.jam_probability > 0

    def _check_box(self, scene: SceneConfig) -> None:
        """Build the box now (kept for the first reset) unless it is placed anew at each reset: an unknown kind or
        a handle out of reach is refused here, not at the first reset."""
        try:
            for c in self.puzzle.components:
                get_kind(c.kind)
            if self.reality.placement is None:
                compiled_scene(self.puzzle, scene)
        except ModelsError as err:
            raise ManipulationEnvError(f"spec {self.puzzle.name!r} cannot be built: {err}") from err

    # -- episodes ----------------------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        seed = int(seed) if seed is not None else int(self.np_random.integers(2**31 - 1))
        session = self.session
        if session is not None and self._reusable:
            session.reset()
        else:
            self._close_session()
            try:
                session = self.session = TwinSession(self.puzzle, seed, self.twin_config, self.reality)
            except ModelsError as err:  # a box no reachable placement fits
                raise ManipulationEnvError(f"spec {self.puzzle.name!r} cannot be placed: {err}") from err
        observer = self._observer = Observer(session, self.obs_mode)
        potential = self._potential = ProgressPotential(session)
        self._steps = 0
        robot = session.robot
        robot.wait(SETTLE_TIME)
        robot.tare()
        primitives = self._primitives
        cell = twin_cell_config(
            session, force_limit=primitives.sensing.force_limit, blocked_force=primitives.judgement.blocked_force
        )
        self.controller.reset(robot, (cell.workspace_min, cell.workspace_max))
        self._force_limit = cell.force_limit
        self._obs = observer.observe()
        self._phi = potential(observer.grasp_points()) if self.reward_mode == "dense" else 0.0
        return self._obs, {"sim_time_s": session.time, "box_pose": session.box_pose, "seed": seed}

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        session, observer, potential = self.session, self._observer, self._potential
        if session is None or observer is None or potential is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        values = np.asarray(action, dtype=np.float64)
        a = values.tolist() if values.shape == self._action_shape else []
        if not a or not all(map(math.isfinite, a)):
            raise ManipulationEnvError(
                f"action must be {self._action_shape[0]} finite numbers in [-1, 1], got {action!r}"
            )
        reason = ""
        diverged = False
        try:
            a = [min(max(v, -1.0), 1.0) for v in a]
            self.controller.apply(a, session.robot, observer.tcp[:3, 3].tolist())
            session.robot.wait(CONTROL_PERIOD)
            self._obs = observer.observe()
        except SimulationDiverged as err:
            reason, diverged = f"diverged: {err}", True
        self._steps += 1
        force = math.sqrt(float(observer.wrench[:3] @ observer.wrench[:3]))  # [N]
        success = not reason and potential.solved()
        if success:
            reason = "goal"
        elif not reason and force > self._force_limit:
            reason = f"force limit: {force:.1f} N > {self._force_limit:.0f} N"
        terminated = bool(reason)
        truncated = not terminated and self._steps >= self.max_steps
        if truncated:
            reason = "time limit"
        reward = float(success)
        if self.reward_mode == "dense" and not diverged:
            phi = potential(observer.grasp_points())
            reward += phi - self._phi
            self._phi = phi
        info = {"success": success, "reason": reason, "force": force, "sim_time_s": session.time}
        return self._obs, reward, terminated, truncated, info

    # -- rendering and closing ---------------------------------------------------------------------
    def render(self) -> np.ndarray | None:
        session = self.session
        if self.render_mode != "rgb_array" or session is None:
            return None
        if self._renderer is None:  # one per session: a placed box is a model of its own
            self._renderer = Renderer(session.model, RenderConfig(*RENDER_SIZE))
        return self._renderer.render(session.data, session.scene.names.overview_camera)

    def _close_session(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        if self.session is not None:
            self.session.close()  # its cameras' renderer back to the process's pool
        self.session = self._observer = self._potential = None

    def close(self) -> None:
        """Release the session, the ``render()`` renderer and the cameras' (the pool's idle renderers closed)."""
        self._close_session()
        if self.obs_mode == "rgb":
            renderer_pool.clear()
