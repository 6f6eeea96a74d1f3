"""A logged toggle replayed in the nominal twin: what the wrist would have sensed, and how the component would
have moved, had the box's joints had given per-kind physics (:class:`KindScales`).

The replay is the twin's own scene (``models.scene``: the xArm-7 with its gripper, servos and wrist F/T sensor,
the table) with one component, the toggled one, placed where the robot perceived it (the log's ``pose``: the
robot never knew better) and in the state the toggle started from, latched if the robot felt it latched (a
``blocked`` outcome). From the descent onto the handle (the arm at rest above the part, where the pipeline tared
the sensor) to the end of the pinch's actuation, the arm servos and the gripper are sent, tick by tick, the very
commands the pipeline sent (the log's ``joint_command``, ``gripper_command``), and the F/T sensor is read at each
tick's end, as the pipeline read it. The arm starts settled at rest from the logged joint positions under the
logged targets, its fingers at the logged pre-grasp opening (the part out of their way meanwhile). The free
descent does not touch the part: it is simulated once per toggle, and later replays start where it ended.

Replaying commands rather than imposing the logged TCP path keeps what the sensor reads at a tick's end as the
twin makes it: the arm servos step towards a new target every 10 ms, and the gripper's inertia at the sampling
instant loads the sensor by ~0.15-0.5 N along a moving grasp — as much as a door's or a wheel's own friction.
The robot's timing (command latency, the F/T sensor's sampling rate and delay) and its grip (the pads' friction
on a handle at the grip force set) are properties of the robot, not of the box, given in :class:`ReplayConfig`
(a real cell takes them from its controller's, sensor's and gripper's datasheets and its own settings): replayed
with no latency, ideal-world toggles read ~1 N of joint load off on doors; pads gripping with the model's design
friction of 1 where the real ones slip at 0.2 carried 25 N across a door's path that the real pads let slide.

Frames and units: the robot base frame (the twin's world); metres, radians, seconds, newtons, newton-metres.
The predicted wrench is the load on the flange (what the gripper exerts on it) about the sensor's origin, in the
base frame, untared (:mod:`twin.toggle_scoring` zeroes logged and predicted wrenches alike).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from puzzlebox.models.kinds import get_kind
from puzzlebox.models.puzzle_box import MARKER_Z
from puzzlebox.models.scene import SceneConfig
from puzzlebox.models.spec import Box, Component, Goal, PuzzleSpec
from puzzlebox.models.toggle_log import ToggleLog
from puzzlebox.twin.physics_draws import subtree_bodies
from puzzlebox.twin.reality import ArmReality, ForceTorqueReality
from puzzlebox.twin.robot_interface import GRIPPER_CTRL_MAX
from puzzlebox.twin.scene_cache import compiled_scene
from puzzlebox.twin.sensors.force_torque import ForceTorqueSensor
from puzzlebox.twin.servos import Servos

_STATE = mujoco.mjtState.mjSTATE_INTEGRATION


class ReplayError(ValueError):
    """A log that cannot be replayed (no pinch in it, or a part the arm cannot reach)."""


@dataclass(frozen=True)
class KindScales:
    """The physics of one component kind relative to the nominal model (the factors a fit identifies) [-]."""

    damping: float = 1.0
    """Multiplier of the joint's viscous damping."""
    friction: float = 1.0
    """Multiplier of the joint's dry friction (frictionloss)."""
    latch: float = 1.0
    """Multiplier of the latch constraint's time constant (``solref[0]``): > 1 is a softer latch."""

    def as_array(self) -> np.ndarray:
        return np.array([self.damping, self.friction, self.latch])


NOMINAL = KindScales()


@dataclass(frozen=True)
class ReplayConfig:
    """How a toggle is replayed, and the robot's own timing."""

    settle_time: float = 0.3
    """Time the fingers are given to settle at the logged pre-grasp opening before the replay, the part out of
    their way [s]."""
    command_latency: float = 0.0
    """Delay before a joint command reaches the arm servos [s] (the robot's; ``ArmReality.command_latency``)."""
    ft_rate_hz: float = 0.0
    """Rate at which the F/T sensor samples the load [Hz]; 0: continuously."""
    ft_delay: float = 0.0
    """Age of the sample an F/T reading returns [s] (needs ``ft_rate_hz`` > 0)."""
    handle_friction: float | None = None
    """Sliding friction of the pads on a handle [-], as the twin applies a grip's force and pad friction
    (:mod:`twin.physics_draws`: the holding capacity 2 mu N scales with mu as with N); None: the model's 1.0 (a
    design value, chosen to hold the handles). A property of the robot's gripper and grip setting."""

    def __post_init__(self) -> None:
        if self.settle_time < 0 or min(self.command_latency, self.ft_rate_hz) < 0:
            raise ValueError(f"invalid replay config {self}")
        if self.ft_delay and not self.ft_rate_hz:
            raise ValueError("ft_delay needs ft_rate_hz > 0")
        if self.handle_friction is not None and not self.handle_friction > 0:
            raise ValueError(f"handle_friction must be > 0, got {self.handle_friction}")


@dataclass
class ReplayResult:
    """What the nominal twin predicts over a toggle's replayed ticks (``ToggleReplay.window``)."""

    force: np.ndarray
    """``(n, 3)`` load force on the flange in the base frame, untared [N]."""
    torque: np.ndarray
    """``(n, 3)`` load torque about the sensor's origin in the base frame, untared [N·m]."""
    tcp: np.ndarray
    """``(n, 4, 4)`` TCP pose in the base frame [m]."""
    joint: np.ndarray
    """``(n,)`` the component's joint position [rad or m] (0 closed, ``travel`` open)."""
    rotation: np.ndarray
    """``(n, 3, 3)`` orientation of the F/T sensor frame in the base frame: a tare is an offset fixed in it."""

    def tared(self, zero: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """``(force [N], torque [N·m])`` in the base frame less the tare ``zero``, an offset fixed in the sensor
        frame (as a sensor tares), turned with the sensor at each tick."""
        return self.force - self.rotation @ zero[0], self.torque - self.rotation @ zero[1]


def pinch_window(log: ToggleLog) -> slice:
    """The ticks of ``log`` a replay covers: from the descent onto the handle (the arm at rest above the part, the
    sensor just tared, before it) through the end of the actuation that follows the grasp (a door pushed on
    afterwards is not part of it).

    Raises:
        ReplayError: the toggle has no pinch (a push, or a try that ended before the grasp).
    """
    grasping = np.flatnonzero(log.in_phase("grasping"))
    actuating = log.in_phase("actuating")
    if not len(grasping) or not actuating[grasping[-1] + 1 :].any():
        raise ReplayError(f"{log.component}: no pinch in this toggle (outcome {log.outcome}: {log.reason!r})")
    descending = np.flatnonzero(log.in_phase("descending")[: grasping[0]])
    if not len(descending) or descending[0] < 1:
        raise ReplayError(f"{log.component}: no descent onto the handle logged before the grasp")
    first = grasping[-1] + 1 + int(np.argmax(actuating[grasping[-1] + 1 :]))
    end = first
    while end + 1 < log.ticks and actuating[end + 1]:
        end += 1
    return slice(int(descending[0]), int(end) + 1)


def replay_spec(log: ToggleLog) -> PuzzleSpec:
    """A box carrying only the toggled component, where the robot perceived it (its frame = the box's lid frame)."""
    T = log.pose
    yaw = math.atan2(T[1, 0], T[0, 0])
    height = float(T[2, 3]) - MARKER_Z  # the marker lies MARKER_Z above the lid (models.puzzle_box)
    component = Component("part", log.kind, (0.0, 0.0, 0.0), max(int(log.marker), 0))
    box = Box((0.2, 0.2, height), (float(T[0, 3]), float(T[1, 3]), yaw))
    return PuzzleSpec(f"replay-{log.component}", (component,), (), Goal("part", 1), box)


class ToggleReplay:
    """The nominal twin of one logged toggle (see the module docstring): :meth:`run` replays it under given
    physics scales of its kind."""

    def __init__(self, log: ToggleLog, config: ReplayConfig | None = None) -> None:
        self.log = log
        self.config = config or ReplayConfig()
        self.window = pinch_window(log)
        self.descent = int(np.argmax(log.in_phase("grasping")[self.window]))
        """Ticks of the window before the gripper starts closing: the free descent onto the handle."""
        self._checkpoint: tuple[Any, ...] | None = None
        try:
            scene, self.model = compiled_scene(replay_spec(log), SceneConfig(with_markers=False))
        except Exception as err:  # noqa: BLE001 - an unreachable or unbuildable pose: not replayable
            raise ReplayError(f"{log.component}: cannot build its replay ({type(err).__name__}: {err})") from None
        m = self.model
        names, part = scene.names, scene.names.components["part"]
        self.data = mujoco.MjData(m)
        self._arm_qpos = np.array([m.joint(j).qposadr[0] for j in names.arm_joints])
        self._arm_act = np.array([m.actuator(a).id for a in names.arm_actuators])
        self._gripper_act = m.actuator(names.gripper_actuator).id
        joint = m.joint(part.joint)
        self._qpos, self._dof = int(joint.qposadr[0]), int(joint.dofadr[0])
        self._latch = m.equality(part.latch).id
        self._part_geoms = np.flatnonzero(np.isin(m.geom_bodyid, subtree_bodies(m, m.body(part.body).id)))
        driver = m.joint(names.gripper_actuator.replace("fingers", "right_driver_joint"))
        self._driver_qpos, self._driver_range = int(driver.qposadr[0]), driver.range.copy()
        if self.config.handle_friction is not None:
            m.geom_friction[m.geom(part.handle).id, 0] = self.config.handle_friction
        self._site = m.site(names.ft_site).id
        self._tcp = m.site(names.tcp_site).id
        self._force_adr = m.sensor(names.wrist_force).adr[0]
        self._torque_adr = m.sensor(names.wrist_torque).adr[0]
        self._nominal = (m.dof_damping[self._dof], m.dof_frictionloss[self._dof], m.eq_solref[self._latch, 0])
        self.travel = get_kind(log.kind).travel
        self.start_joint = 0.0 if log.opening else self.travel
        self.latched = log.outcome == "blocked"
        """Whether the part is replayed latched: the robot felt it held (a lock, or a jam: the same to it)."""

    def run(self, scales: KindScales = NOMINAL, ticks: int | None = None) -> ReplayResult:
        """Replay the window (its first ``ticks`` only, when given) under ``scales`` (this kind's physics relative to
        the nominal model). The free descent does not touch the part: it is simulated once, and later runs start
        from the state it ended in."""
        m, d, c = self.model, self.data, self.config
        damping, friction, solref = self._nominal
        m.dof_damping[self._dof] = damping * scales.damping
        m.dof_frictionloss[self._dof] = friction * scales.friction
        m.eq_solref[self._latch, 0] = solref * scales.latch
        n = self.window.stop - self.window.start if ticks is None else min(ticks, self.window.stop - self.window.start)
        out = ReplayResult(np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 4, 4)), np.empty(n), np.empty((n, 3, 3)))
        if self._checkpoint is None:
            self._settle(self.window.start - 1)
            servos = Servos(d, self._arm_act, self._gripper_act, ArmReality(command_latency=c.command_latency),
                            m.opt.timestep)  # fmt: skip
            servos.reset(np.random.default_rng(0))  # (no stalls: nothing is drawn)
            sensor = ForceTorqueReality(rate_hz=c.ft_rate_hz, delay=c.ft_delay)
            ft = ForceTorqueSensor(d, self._force_adr, self._torque_adr, sensor, m.opt.timestep)
            ft.reset(np.random.default_rng(0))  # (no noise, no bias: nothing is drawn)
            descent = ReplayResult(*(np.empty((self.descent, *a.shape[1:])) for a in out.__dict__.values()))
            self._simulate(range(self.descent), descent, servos, ft)
            state = np.empty(mujoco.mj_stateSize(m, _STATE))
            mujoco.mj_getState(m, d, state, _STATE)
            self._checkpoint = (state, servos, servos.get_state(), ft, ft.get_state(), descent)
        state, servos, servo_state, ft, ft_state, descent = self._checkpoint
        mujoco.mj_setState(m, d, state, _STATE)
        servos.set_state(servo_state)
        ft.set_state(ft_state)
        mujoco.mj_forward(m, d)
        k = min(self.descent, n)
        for mine, cached in zip(out.__dict__.values(), descent.__dict__.values(), strict=True):
            mine[:k] = cached[:k]
        self._simulate(range(k, n), out, servos, ft)
        return out

    def _simulate(self, indices: range, out: ReplayResult, servos: Servos, ft: ForceTorqueSensor) -> None:
        """Replay window ticks ``indices`` (from the present state) into ``out``."""
        m, d, log = self.model, self.data, self.log
        dt = float(m.opt.timestep)
        for i in indices:
            k = self.window.start + i
            servos.command_joints(log.joint_command[k])
            servos.command_gripper(float(log.gripper_command[k]) * GRIPPER_CTRL_MAX)
            self._advance(round(float(log.time[k] - log.time[k - 1]) / dt), servos, ft)
            R = d.site_xmat[self._site].reshape(3, 3)
            load = ft.read(float(d.time))
            out.force[i], out.torque[i], out.rotation[i] = R @ load[:3], R @ load[3:], R
            out.tcp[i, :3, :3] = d.site_xmat[self._tcp].reshape(3, 3)
            out.tcp[i, :3, 3] = d.site_xpos[self._tcp]
            out.tcp[i, 3] = (0.0, 0.0, 0.0, 1.0)
            out.joint[i] = d.qpos[self._qpos]

    def _settle(self, k: int) -> None:
        """The state at logged tick ``k`` (the arm at rest above the part): the arm settled from its logged joints
        with its servos at the logged targets, the fingers brought to the logged closure under the logged gripper
        target, the part out of their way meanwhile (its collisions off), then the part at its start, latched if
        it was."""
        m, d, log = self.model, self.data, self.log
        mujoco.mj_resetData(m, d)
        d.qpos[self._arm_qpos] = log.joints[k]
        d.ctrl[self._arm_act] = log.joint_command[k]
        d.ctrl[self._gripper_act] = float(log.gripper_command[k]) * GRIPPER_CTRL_MAX
        d.qpos[self._qpos] = self.start_joint
        contype, conaffinity = m.geom_contype[self._part_geoms].copy(), m.geom_conaffinity[self._part_geoms].copy()
        m.geom_contype[self._part_geoms] = 0
        m.geom_conaffinity[self._part_geoms] = 0
        try:
            steps = max(1, round(self.config.settle_time / m.opt.timestep))
            mujoco.mj_step(m, d, nstep=steps)
            # the fingers where the real ones stood: their joints' dry friction holds them wherever they came to
            # rest (0.57-0.61 closed at a 0.6 target, by the way they came), and a pinch closes from there
            target, command = float(log.closure[k]), float(log.gripper_command[k]) * GRIPPER_CTRL_MAX
            push = command
            for _ in range(8):
                push += 0.5 * (target - self._closure()) * GRIPPER_CTRL_MAX
                push = float(np.clip(push, command - 40.0, command + 40.0))
                d.ctrl[self._gripper_act] = float(np.clip(push, 0.0, GRIPPER_CTRL_MAX))
                mujoco.mj_step(m, d, nstep=max(1, steps // 4))
            d.ctrl[self._gripper_act] = command
            mujoco.mj_step(m, d, nstep=max(1, steps // 3))
        finally:
            m.geom_contype[self._part_geoms] = contype
            m.geom_conaffinity[self._part_geoms] = conaffinity
        d.time = float(log.time[k])  # the arm where the servos hold it at the logged targets: at rest, as the real
        d.qpos[self._qpos] = self.start_joint  # one was above the part (imposing the noisy encoders' made it jolt)
        d.qvel[self._dof] = 0.0
        d.eq_active[self._latch] = int(self.latched)
        m.eq_data[self._latch, 0] = self.start_joint  # the joint equality's target, as twin.latches sets it
        mujoco.mj_forward(m, d)

    def _closure(self) -> float:
        """The gripper's closure, 0 open .. 1 closed, as the robot interface reads it."""
        low, high = self._driver_range
        return float(np.clip((self.data.qpos[self._driver_qpos] - low) / (high - low), 0.0, 1.0))

    def _advance(self, steps: int, servos: Servos, ft: ForceTorqueSensor) -> None:
        """``steps`` physics steps, writing queued commands when due and sampling the F/T sensor at its rate."""
        m, d = self.model, self.data
        if servos.immediate and not ft.sample_steps:
            mujoco.mj_step(m, d, nstep=max(steps, 1))
            return
        dt, every = float(m.opt.timestep), ft.sample_steps
        for _ in range(max(steps, 1)):
            servos.apply_due()
            mujoco.mj_step(m, d)
            if every and round(d.time / dt) % every == 0:
                ft.sample()
        servos.apply_due()


__all__ = ["NOMINAL", "KindScales", "ReplayConfig", "ReplayError", "ReplayResult", "ToggleReplay", "pinch_window"]
