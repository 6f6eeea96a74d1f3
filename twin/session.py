"""A running twin: the compiled scene of a spec, stepped with latches, checked for divergence.

A :class:`TwinSession` is a pure function of (spec, seed, commands): two sessions given the same
spec, seed and command sequence produce bit-identical trajectories. The seed drives the only
randomness, the wrist F/T sensor noise. MuJoCo's autoreset is disabled in the model, and every MuJoCo
warning raised while stepping becomes :class:`~twin.errors.SimulationDiverged` naming it — a session
never resets itself silently.

Ground truth (component joint positions and states) is available here for evaluation and logging;
the robot's pipeline must go through :attr:`TwinSession.robot` (:class:`~twin.robot_interface.RobotInterface`),
which offers only what a real xArm driver and camera give.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np

from models import PuzzleSpec, get_kind
from models.scene import Scene, SceneConfig, build_scene
from models.xarm7 import HOME_QPOS
from twin.component_states import ComponentStates, HysteresisConfig
from twin.errors import SimulationDiverged
from twin.latches import Latches

# Every physics warning is a divergence (mujoco 3.17 lists: bad ctrl/qacc/qpos/qvel, full constraint
# or contact buffers, bad inertia). Warnings outside the enum (future visual ones) are ignored.
_PHYSICS_WARNINGS = {int(w) for w in mujoco.mjtWarning.__members__.values()}
_STATE_SPEC = mujoco.mjtState.mjSTATE_INTEGRATION


@dataclass(frozen=True)
class TwinConfig:
    """Settings of a twin session."""

    scene: SceneConfig = field(default_factory=SceneConfig)
    hysteresis: HysteresisConfig = field(default_factory=HysteresisConfig)
    latch_period: int = 10
    """Physics steps between latch updates and divergence checks (10 x 2 ms: a latch falls into place
    within 20 ms, as a spring latch would; checking every step would cost ~a third of the stepping speed)."""
    force_noise_std: float = 0.05
    """Standard deviation of the wrist force noise [N] (a 6-axis F/T sensor of the xArm class)."""
    torque_noise_std: float = 0.002
    """Standard deviation of the wrist torque noise [N·m]."""
    home_qpos: tuple[float, ...] = HOME_QPOS
    """Arm joint positions at reset [rad]."""


@dataclass(frozen=True)
class TwinState:
    """Everything needed to put a session back exactly where it was."""

    physics: np.ndarray
    latch_targets: np.ndarray
    component_states: np.ndarray
    rng_state: dict
    wrench_offset: np.ndarray


class TwinSession:
    """The simulated world of one puzzle-box spec (see the module docstring)."""

    def __init__(self, spec: PuzzleSpec, seed: int = 0, config: TwinConfig | None = None) -> None:
        self.spec = spec
        self.seed = seed
        self.config = config or TwinConfig()
        if self.config.latch_period < 1:
            raise ValueError(f"latch_period must be >= 1, got {self.config.latch_period}")
        self.scene: Scene = build_scene(spec, self.config.scene)
        self.model = self.scene.compile()
        self.data = mujoco.MjData(self.model)
        names = self.scene.names
        m = self.model
        self.arm_qpos = np.array([m.joint(j).qposadr[0] for j in names.arm_joints])
        self.arm_dof = np.array([m.joint(j).dofadr[0] for j in names.arm_joints])
        self.arm_actuators = np.array([m.actuator(a).id for a in names.arm_actuators])
        self.gripper_actuator = m.actuator(names.gripper_actuator).id
        component_names = [names.components[c.name] for c in spec.components]
        self.component_qpos = np.array([m.joint(c.joint).qposadr[0] for c in component_names])
        self.travel = np.array([get_kind(c.kind).travel for c in spec.components])
        self.states = ComponentStates(self.travel, self.config.hysteresis)
        self.latches = Latches(m, spec, [c.latch for c in component_names], self.component_qpos)
        self._robot = None
        self.reset()

    # -- life cycle --------------------------------------------------------------------------------
    def reset(self) -> None:
        """Back to the initial state: box closed, arm at home, gripper open, noise re-seeded."""
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        d.qpos[self.arm_qpos] = self.config.home_qpos
        d.ctrl[self.arm_actuators] = self.config.home_qpos
        d.ctrl[self.gripper_actuator] = 0.0
        self.rng = np.random.default_rng(self.seed)
        self.wrench_offset = np.zeros(6)
        self.latches.engaged[:] = False
        d.eq_active[self.latches.eq_ids] = 0
        mujoco.mj_forward(m, d)
        self.states.reset(d.qpos[self.component_qpos])
        self.latches.apply(d, self.states.states)
        self._warnings = d.warning.number.copy()

    @property
    def time(self) -> float:
        """Simulated time since reset [s]."""
        return float(self.data.time)

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)

    def step(self, n: int = 1) -> None:
        """Advance ``n`` physics steps, updating latches every ``latch_period`` steps.

        Raises:
            SimulationDiverged: MuJoCo raised a warning (bad accelerations, a full contact buffer...).
        """
        period = self.config.latch_period
        while n > 0:
            k = min(n, period)
            mujoco.mj_step(self.model, self.data, nstep=k)
            n -= k
            self._after_steps()

    def advance(self, seconds: float) -> None:
        """Advance by ``seconds`` of simulated time (rounded to whole steps) [s]."""
        self.step(max(1, round(seconds / self.timestep)))

    def _after_steps(self) -> None:
        d = self.data
        if self.states.update(d.qpos[self.component_qpos]):
            self.latches.apply(d, self.states.states)  # rules change only when a state does
        counts = d.warning.number
        if np.any(counts > self._warnings):
            new = [i for i in np.flatnonzero(counts > self._warnings) if i in _PHYSICS_WARNINGS]
            self._warnings = counts.copy()
            if new:
                labels = ", ".join(mujoco.mjtWarning(int(i)).name for i in new)
                raise SimulationDiverged(
                    f"MuJoCo warning {labels} at t = {d.time:.3f} s in {self.spec.name!r} (autoreset disabled)"
                )

    # -- state -------------------------------------------------------------------------------------
    def get_state(self) -> TwinState:
        """A snapshot of the full state (physics, latches, hysteresis, noise generator, tare)."""
        physics = np.empty(mujoco.mj_stateSize(self.model, _STATE_SPEC))
        mujoco.mj_getState(self.model, self.data, physics, _STATE_SPEC)
        return TwinState(
            physics=physics,
            latch_targets=self.latches.targets(),
            component_states=self.states.states.copy(),
            rng_state=self.rng.bit_generator.state,
            wrench_offset=self.wrench_offset.copy(),
        )

    def set_state(self, state: TwinState) -> None:
        """Restore a snapshot from :meth:`get_state` of this session."""
        mujoco.mj_setState(self.model, self.data, state.physics, _STATE_SPEC)
        self.latches.restore(self.data, state.latch_targets)
        self.states.states = state.component_states.copy()
        self.rng.bit_generator.state = state.rng_state
        self.wrench_offset = state.wrench_offset.copy()
        mujoco.mj_forward(self.model, self.data)

    # -- ground truth (evaluation only) ------------------------------------------------------------
    def component_positions(self) -> np.ndarray:
        """Joint position of every component, in spec order [rad or m]. Ground truth: not for skills."""
        return self.data.qpos[self.component_qpos].copy()

    def component_states(self) -> np.ndarray:
        """State (0/1) of every component, in spec order. Ground truth: not for skills."""
        return self.states.states.copy()

    # -- the robot ---------------------------------------------------------------------------------
    @property
    def robot(self):  # -> RobotInterface (imported lazily: it pulls in the renderer)
        if self._robot is None:
            from twin.robot_interface import RobotInterface

            self._robot = RobotInterface(self)
        return self._robot

    def close(self) -> None:
        if self._robot is not None:
            self._robot.close()

    def __enter__(self) -> TwinSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
