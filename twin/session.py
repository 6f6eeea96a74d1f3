"""A running twin: the compiled scene of a spec, stepped with latches, checked for divergence, with the
cell's imperfections (a :class:`~twin.reality.RealityProfile`) built into its model and sensors.

A :class:`TwinSession` is a pure function of (spec, seed, profile, commands): two sessions given the
same spec, seed, reality profile and command sequence produce bit-identical trajectories, readings and
images. The profile's fixed imperfections (the box hardware's per-kind physics factors among them) come from
its ``cell_seed``; everything drawn per trial (placement, physics factors, sensor noise, bias and drift,
command stalls, jams, frame effects) comes from ``seed``, each concern from its own stream
(:class:`numpy.random.SeedSequence` children) so that, say, capturing one more image does not change the F/T
noise. MuJoCo's autoreset is disabled in the
model, and every MuJoCo warning raised while stepping becomes :class:`~twin.errors.SimulationDiverged`
naming it: a session never resets itself silently.

The session owns its sensor models (:attr:`ft`, :attr:`encoders`, :attr:`cameras`) and servo interface
(:attr:`servos`); :attr:`robot` (:class:`~twin.robot_interface.RobotInterface`, the ``models.robot.Robot``
protocol) only asks them, and offers only what a real xArm driver and camera give. Ground truth
(component joint positions and states, :meth:`camera_truth`, :attr:`box_pose`) is here for evaluation
and logging.

The default profile is ``ideal``: no imperfection at all, the nominal world (and noiseless sensors).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from puzzlebox.models import LockTable, PuzzleSpec, get_kind
from puzzlebox.models.calibration import CameraCalibration
from puzzlebox.models.placement import placed, sample_reachable_pose
from puzzlebox.models.scene import Scene, SceneConfig
from puzzlebox.models.xarm7 import HOME_QPOS
from puzzlebox.twin.cell import apply_cell, draw_cell
from puzzlebox.twin.component_states import ComponentStates, HysteresisConfig
from puzzlebox.twin.errors import SimulationDiverged
from puzzlebox.twin.jams import Jams
from puzzlebox.twin.latches import Latches, latched_rules
from puzzlebox.twin.nominal_calibration import camera_calibration
from puzzlebox.twin.physics_draws import apply_physics, draw_physics, subtree_bodies
from puzzlebox.twin.reality import RealityProfile, load_profile
from puzzlebox.twin.rendering import RenderConfig, pinhole_intrinsics
from puzzlebox.twin.robot_interface import RobotInterface
from puzzlebox.twin.scene_cache import compiled_scene
from puzzlebox.twin.sensors.cameras import Cameras, true_lens
from puzzlebox.twin.sensors.encoders import JointEncoders
from puzzlebox.twin.sensors.force_torque import ForceTorqueSensor
from puzzlebox.twin.servos import Servos

# Every physics warning is a divergence (mujoco 3.17 lists: bad ctrl/qacc/qpos/qvel, full constraint
# or contact buffers, bad inertia). Warnings outside the enum (future visual ones) are ignored.
_PHYSICS_WARNINGS = {int(w) for w in mujoco.mjtWarning.__members__.values()}
_STATE_SPEC = mujoco.mjtState.mjSTATE_INTEGRATION
# Per-trial random streams, children of SeedSequence(seed) in this order (cameras follow, one each).
_STREAMS = ("placement", "physics", "ft", "encoders", "servos", "jams")


@dataclass(frozen=True)
class TwinConfig:
    """Settings of a twin session (the cell's imperfections are the separate reality profile)."""

    scene: SceneConfig = field(default_factory=SceneConfig)
    hysteresis: HysteresisConfig = field(default_factory=HysteresisConfig)
    latch_period: int = 10
    """Physics steps between latch updates and divergence checks (10 x 2 ms: a latch falls into place
    within 20 ms, as a spring latch would; checking every step would cost ~a third of the stepping speed)."""
    home_qpos: tuple[float, ...] = HOME_QPOS
    """Arm joint positions at reset [rad]."""
    render: RenderConfig = field(default_factory=RenderConfig)
    """Size of the cameras' images (and how they are rendered)."""


@dataclass(frozen=True)
class TwinState:
    """Everything needed to put a session back exactly where it was."""

    physics: np.ndarray
    latch_targets: np.ndarray
    component_states: np.ndarray
    sensors: dict[str, Any]
    """States of the sensor models, the servo queue and the jams (their generators included)."""


class TwinSession:
    """The simulated world of one puzzle-box spec (see the module docstring).

    Args:
        spec: the puzzle box (with ``reality.placement`` set, it is placed at a pose drawn from ``seed``;
            :attr:`spec` is then the placed spec).
        seed: the trial's seed.
        config: the session's settings.
        reality: a reality profile, a preset name (``ideal``, ``realistic``, ``harsh``) or a profile
            JSON path (:func:`twin.reality.load_profile`); None is ``ideal``.
    """

    def __init__(
        self,
        spec: PuzzleSpec,
        seed: int = 0,
        config: TwinConfig | None = None,
        reality: RealityProfile | str | Path | None = None,
    ) -> None:
        self.seed = seed
        self.config = config or TwinConfig()
        self.reality = load_profile(reality)
        if self.config.latch_period < 1:
            raise ValueError(f"latch_period must be >= 1, got {self.config.latch_period}")
        root = np.random.SeedSequence(seed)
        self._streams = dict(zip(_STREAMS, root.spawn(len(_STREAMS)), strict=True))
        if self.reality.placement is not None:
            rng = np.random.default_rng(self._streams["placement"])
            spec = placed(spec, sample_reachable_pose(spec, rng, self.reality.placement, self.config.scene))
        self.spec = spec
        self.scene: Scene
        self.scene, self.model = compiled_scene(spec, self.config.scene)  # a copy: this session's own
        self.nominal_model = copy.deepcopy(self.model)
        """The model as designed: the nominal kinematics and cameras (what calibration starts from)."""
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
        self.rules = LockTable.from_spec(spec)
        """The spec's lock semantics (ground truth): what the mechanisms and latches enforce together."""
        self.latches = Latches(m, latched_rules(spec, self.config.scene.locks), [c.latch for c in component_names],
                               self.component_qpos)  # fmt: skip
        camera_names = (names.overview_camera, names.wrist_camera)
        # the next children of the same root: spawn keys follow on from the streams above
        self._camera_streams = dict(zip(camera_names, root.spawn(len(camera_names)), strict=True))

        # the cell (cell_seed) and this trial's physics (seed), built into the model
        flange = m.body(names.flange).id
        gripper_body = int(np.flatnonzero(m.body_parentid == flange)[0])
        handle_geoms = np.array([m.geom(c.handle).id for c in component_names], dtype=np.int64)
        self.cell = draw_cell(self.reality, camera_names)
        """The cell's fixed imperfections (evaluation only)."""
        changed = apply_cell(m, self.cell, gripper_body)
        self.physics_draw = draw_physics(
            self.reality.physics, len(spec.components), np.random.default_rng(self._streams["physics"])
        )
        """This trial's physics factors (evaluation only)."""
        kind_factors = self.cell.kinds.per_component([c.kind for c in spec.components])
        self.applied_physics = self.physics_draw.times(*kind_factors)
        """The physics factors built into the model: this trial's times its cell's kind factors (evaluation only)."""
        changed |= apply_physics(
            m,
            self.reality.physics,
            self.applied_physics,
            handle_geoms,
            np.array([m.joint(c.joint).dofadr[0] for c in component_names], dtype=np.int64),
            np.array([m.body(c.body).id for c in component_names], dtype=np.int64),
            self.latches.eq_ids,
        )
        size = (self.config.render.width, self.config.render.height)
        lenses = {}
        for name in camera_names:  # may widen a camera's render field of view: the true camera sees more
            cam, errors = m.camera(name).id, self.cell.cameras[name]
            K_true = errors.true_K(pinhole_intrinsics(self.nominal_model, cam, *size))
            lenses[name] = true_lens(m, cam, K_true, errors.dist, size)
        if changed:
            mujoco.mj_setConst(m, self.data)  # masses, inertias and poses changed: recompute what depends on them

        # the sensor models and the servo interface (the robot interface asks them)
        r = self.reality
        self.ft = ForceTorqueSensor(
            self.data, m.sensor(names.wrist_force).adr[0], m.sensor(names.wrist_torque).adr[0], r.force_torque,
            self.timestep,
        )  # fmt: skip
        self.encoders = JointEncoders(
            self.data,
            self.arm_qpos,
            m.site(names.tcp_site).id,
            m.site(names.ft_site).id,
            self.nominal_model,
            r.arm.encoder_noise,
            exact=not self.cell.tcp_bias.any(),
        )
        self.cameras = Cameras(m, self.data, camera_names, lenses, r.camera, self.config.render)
        self.servos = Servos(self.data, self.arm_actuators, self.gripper_actuator, r.arm, self.timestep)
        self.jams: Jams | None = None
        if r.physics.jam_probability > 0:
            gripper_bodies = subtree_bodies(m, gripper_body)
            part_geoms = [np.flatnonzero(np.isin(m.geom_bodyid, subtree_bodies(m, m.body(c.body).id)))
                          for c in component_names]  # fmt: skip
            self.jams = Jams(
                m, part_geoms, gripper_bodies, self.travel, r.physics.jam_probability, r.physics.jam_release_after
            )
        self._plain = self.ft.sample_steps == 0 and self.servos.immediate
        self._dt = float(m.opt.timestep)  # [s] read every run: a model attribute costs a binding call
        self._held_for: np.ndarray | None = None
        self._held_now = np.zeros(len(spec.components), dtype=bool)
        self._robot: RobotInterface | None = None
        self.reset()

    # -- life cycle --------------------------------------------------------------------------------
    def reset(self) -> None:
        """Back to the initial state: box closed, arm at home, gripper open, noise re-seeded, no tare."""
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        d.qpos[self.arm_qpos] = self.config.home_qpos
        d.ctrl[self.arm_actuators] = self.config.home_qpos
        d.ctrl[self.gripper_actuator] = 0.0
        self.latches.engaged[:] = False
        d.eq_active[self.latches.eq_ids] = 0
        mujoco.mj_forward(m, d)
        rng = {name: np.random.default_rng(s) for name, s in self._streams.items()}
        self.ft.reset(rng["ft"])
        self.encoders.reset(rng["encoders"])
        self.servos.reset(rng["servos"])
        self.cameras.reset({name: np.random.default_rng(s) for name, s in self._camera_streams.items()})
        q = d.qpos[self.component_qpos]
        if self.jams is not None:
            self.jams.reset(rng["jams"], q)
        self.states.reset(q)
        self.latches.apply(d, self.states.states, self._jammed())
        self._warnings = d.warning.number.copy()

    def _jammed(self) -> np.ndarray | None:
        return None if self.jams is None else self.jams.jammed

    @property
    def time(self) -> float:
        """Simulated time since reset [s]."""
        return float(self.data.time)

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)

    @property
    def box_pose(self) -> tuple[float, float, float]:
        """Where the box stands ``(x, y, yaw)`` [m, m, rad]. Ground truth: not for skills."""
        return self.scene.box_pose

    def step(self, n: int = 1) -> None:
        """Advance ``n`` physics steps, updating latches every ``latch_period`` steps.

        Raises:
            SimulationDiverged: MuJoCo raised a warning (bad accelerations, a full contact buffer...).
        """
        period = self.config.latch_period
        while n > 0:
            k = min(n, period)
            self._run(k)
            n -= k
            self._after_steps()

    def advance(self, seconds: float) -> None:
        """Advance by ``seconds`` of simulated time (rounded to whole steps) [s]."""
        self.step(max(1, round(seconds / self._dt)))

    def _steps(self, k: int, sense: bool = True) -> None:
        """``k`` ``mj_step``, the sensors computed in the last one only (``sense``) or in none: nothing reads them
        but an F/T sample and whoever reads the sensor after :meth:`step` returns, and the wrist F/T sensor's
        post-constraint pass was ~15 % of a step. (A step computes the sensors of the state it starts from, so
        ``sensordata`` after it is what computing them at every step gives: bit for bit.)"""
        m, d = self.model, self.data
        blind = k - 1 if sense else k
        if blind:
            flags = m.opt.disableflags
            m.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_SENSOR
            try:
                mujoco.mj_step(m, d, nstep=blind)
            finally:
                m.opt.disableflags = flags
        if sense:
            mujoco.mj_step(m, d)

    def _run(self, k: int) -> None:
        """``k`` physics steps, stopping at each F/T sample and queued command on the way."""
        if self._plain:
            self._steps(k)
            return
        every = self.ft.sample_steps
        while k > 0:
            j = k
            if every:
                j = min(j, every - round(self.data.time / self._dt) % every)
            due = self.servos.steps_to_next()
            if due is not None:
                j = min(j, due)
            sampling = bool(every) and round(self.data.time / self._dt + j) % every == 0
            self._steps(j, sense=sampling or j == k)  # a command falling due reads no sensor
            k -= j
            self.servos.apply_due()
            if every and round(self.data.time / self._dt) % every == 0:
                self.ft.sample()

    def _held(self) -> np.ndarray:
        """Which components the lock rules hold in the current states, whatever holds them (a mechanism or a
        latch), recomputed only when a state changed (``states.states`` is a new array then)."""
        if self._held_for is not self.states.states:
            self._held_for, self._held_now = self.states.states, self.rules.held(self.states.states)
        return self._held_now

    def held_by_rules(self) -> np.ndarray:
        """``(N,)`` bool: which components a lock rule of the spec holds in the current states (ground truth,
        whether a mechanism or a latch enforces it)."""
        return self.rules.held(self.states.states).copy()

    def _after_steps(self) -> None:
        d = self.data
        q = d.qpos[self.component_qpos]
        changed = self.states.update(q)
        if self.jams is not None:
            changed |= self.jams.update(d, q, self._held())
        if changed:
            self.latches.apply(d, self.states.states, self._jammed())  # rules change only when a state does
        counts = d.warning.number
        if (counts > self._warnings).any():
            new = [i for i in np.flatnonzero(counts > self._warnings) if i in _PHYSICS_WARNINGS]
            self._warnings = counts.copy()
            if new:
                labels = ", ".join(mujoco.mjtWarning(int(i)).name for i in new)
                raise SimulationDiverged(
                    f"MuJoCo warning {labels} at t = {d.time:.3f} s in {self.spec.name!r} (autoreset disabled)"
                )

    # -- state -------------------------------------------------------------------------------------
    def _sensor_models(self) -> dict[str, Any]:
        models = {"ft": self.ft, "encoders": self.encoders, "servos": self.servos, "cameras": self.cameras}
        if self.jams is not None:
            models["jams"] = self.jams
        return models

    def get_state(self) -> TwinState:
        """A snapshot of the full state (physics, latches, hysteresis, sensor models and their generators)."""
        physics = np.empty(mujoco.mj_stateSize(self.model, _STATE_SPEC))
        mujoco.mj_getState(self.model, self.data, physics, _STATE_SPEC)
        return TwinState(
            physics=physics,
            latch_targets=self.latches.targets(),
            component_states=self.states.states.copy(),
            sensors={name: model.get_state() for name, model in self._sensor_models().items()},  # copies
        )

    def set_state(self, state: TwinState) -> None:
        """Restore a snapshot from :meth:`get_state` of this session."""
        mujoco.mj_setState(self.model, self.data, state.physics, _STATE_SPEC)
        self.latches.restore(self.data, state.latch_targets)
        self.states.states = state.component_states.copy()
        for name, model in self._sensor_models().items():
            model.set_state(state.sensors[name])  # copies: the snapshot can be restored again
        mujoco.mj_forward(self.model, self.data)

    # -- ground truth (evaluation only) ------------------------------------------------------------
    def component_positions(self) -> np.ndarray:
        """Joint position of every component, in spec order [rad or m]. Ground truth: not for skills."""
        return self.data.qpos[self.component_qpos].copy()

    def component_states(self) -> np.ndarray:
        """State (0/1) of every component, in spec order. Ground truth: not for skills."""
        return self.states.states.copy()

    def camera_truth(self, camera: str) -> CameraCalibration:
        """The TRUE calibration of a camera: its intrinsics with the profile's errors, its true lens
        distortion, its true mounting pose (a wrist camera's relative to the TCP the arm reports).
        Evaluation only: for testing calibration procedures, never for skills."""
        lens = self.cameras.lens(camera)
        size = (self.config.render.width, self.config.render.height)
        T_base_tcp = self.encoders.nominal_tcp_pose(self.data.qpos[self.arm_qpos])
        extra = {"profile": self.reality.name, "cell_seed": self.reality.cell_seed}
        cam = self.model.camera(camera).id
        return camera_calibration(self.model, self.data.qpos, cam, lens.K, lens.dist, size, T_base_tcp, extra)

    # -- the robot ---------------------------------------------------------------------------------
    @property
    def robot(self) -> RobotInterface:
        """The robot as its pipeline sees it (the ``models.robot.Robot`` protocol)."""
        if self._robot is None:
            sensors = (self.encoders, self.ft, self.cameras)
            self._robot = RobotInterface(self.model, self.data, self.scene.names, sensors, self.servos, self.arm_dof,
                                         self.arm_actuators, self.advance)  # fmt: skip
        return self._robot

    def close(self) -> None:
        self.cameras.close()

    def __enter__(self) -> TwinSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
