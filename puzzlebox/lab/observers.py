"""Observers of a trial: what watches a trial without changing it (peak wrist force, the sensed digest, a video,
a Rerun recording, one's own).

A trial hands every observer explicit events (:class:`TrialObserver`): :meth:`~TrialObserver.attach` once the
world and the agent exist, :meth:`~TrialObserver.sensed` after each reading the pipeline takes of the robot,
:meth:`~TrialObserver.commanded` after each command it gives, :meth:`~TrialObserver.waited` after each stretch of
robot time, :meth:`~TrialObserver.action_begins` / :meth:`~TrialObserver.action_ended` around each try,
:meth:`~TrialObserver.finish` at the end. The events come
from :class:`ObservedRobot` (the ``Robot`` the pipeline drives, forwarding each call to the cell's robot) and
from :class:`puzzlebox.lab.narrated_world.NarratedWorld`. An observer reads the cell (``session``: the twin's
physics; None on a real arm) and what the pipeline sensed; it senses nothing itself, so a trial is the same
trial, to the bit, with or without it.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from puzzlebox.models.robot import CameraImage, Robot

if TYPE_CHECKING:
    from puzzlebox.models import PuzzleSpec
    from puzzlebox.skills.robot_world import RobotWorld
    from puzzlebox.twin.rollout_video import Caption
    from puzzlebox.twin.session import TwinSession

__all__ = ["ObservedRobot", "PeakWristForce", "SensedDigest", "TrialContext", "TrialObserver"]


@dataclass
class TrialContext:
    """What a trial is made of, for its observers: the spec (as placed), the seed, the twin session (None on a
    real arm), the world the agent acts on and the agent (None until they exist)."""

    spec: PuzzleSpec
    seed: int
    session: TwinSession | None
    world: RobotWorld | None = None
    agent: Any = None


class TrialObserver:
    """Base of trial observers: every event is a no-op; override those you follow (module docstring)."""

    def attach(self, trial: TrialContext) -> None:
        """The trial's world and agent exist (``trial.world``, ``trial.agent``)."""

    def sensed(self, what: str, value: Any) -> None:
        """The pipeline read ``what`` (``"joint_positions"``, ``"wrench"`` or ``"capture:<camera>"``) and got
        ``value`` (an array, or a :class:`~puzzlebox.models.robot.CameraImage` or None)."""

    def commanded(self, what: str, value: Any) -> None:
        """The pipeline commanded ``what`` (``"joint_positions"``: an array [rad]; ``"gripper"``: a closure, 0 open
        .. 1 closed)."""

    def waited(self, now: float) -> None:
        """Robot time passed, to ``now`` [s] (every control tick of a motion, every settle and look)."""

    def action_begins(self, caption: Caption) -> None:
        """The agent chose a try, about to be made (the caption names it, with the agent's values)."""

    def action_ended(self, caption: Caption) -> None:
        """The try ended (the caption adds the outcome sensed and, in evaluation, the truth)."""

    def finish(self) -> None:
        """The trial is over (its last action ended, or it stopped early)."""


class ObservedRobot:
    """The ``Robot`` the pipeline drives: each call goes to ``robot`` and its readings and waits to ``observers``,
    in order. Implements exactly the :class:`~puzzlebox.models.robot.Robot` protocol."""

    def __init__(self, robot: Robot, observers: Sequence[TrialObserver]) -> None:
        self._robot = robot
        self._observers = tuple(observers)
        self.camera_names = robot.camera_names

    @property
    def time(self) -> float:
        return self._robot.time

    def joint_positions(self) -> np.ndarray:
        q = self._robot.joint_positions()
        for observer in self._observers:
            observer.sensed("joint_positions", q)
        return q

    def joint_velocities(self) -> np.ndarray:
        return self._robot.joint_velocities()

    def joint_limits(self) -> np.ndarray:
        return self._robot.joint_limits()

    def gripper_opening(self) -> float:
        return self._robot.gripper_opening()

    def tcp_pose_in_base(self) -> np.ndarray:
        return self._robot.tcp_pose_in_base()

    def ft_rotation_in_base(self) -> np.ndarray:
        return self._robot.ft_rotation_in_base()

    def wrench(self) -> np.ndarray:
        w = self._robot.wrench()
        for observer in self._observers:
            observer.sensed("wrench", w)
        return w

    def tare(self, samples: int = 10) -> None:
        self._robot.tare(samples)

    def command_joint_positions(self, q: np.ndarray) -> None:
        self._robot.command_joint_positions(q)
        for observer in self._observers:
            observer.commanded("joint_positions", q)

    def command_gripper(self, closure: float) -> None:
        self._robot.command_gripper(closure)
        for observer in self._observers:
            observer.commanded("gripper", closure)

    def wait(self, seconds: float) -> None:
        self._robot.wait(seconds)
        now = self._robot.time
        for observer in self._observers:
            observer.waited(now)

    def capture(self, camera: str) -> CameraImage | None:
        image = self._robot.capture(camera)
        for observer in self._observers:
            observer.sensed(f"capture:{camera}", image)
        return image


class PeakWristForce(TrialObserver):
    """Evaluation only: the largest true external force on the wrist over a trial [N], sampled after every
    robot wait (each 10 ms control tick) from the sensor model's noiseless load, less the weight of what hangs
    below the sensor — what the safety-limit target is checked against, whatever the robot sensed. Twin only."""

    def __init__(self, session: TwinSession) -> None:
        self._session = session
        m = session.model
        self._site = m.site(session.scene.names.ft_site).id
        hanging = m.body_subtreemass[m.site_bodyid[self._site]]  # the flange and the gripper: 7.37 N of weight
        self._weight_in_base = hanging * m.opt.gravity
        self.peak = 0.0
        """Largest true external wrist force so far [N]."""
        self.peak_during = ""
        """What the arm was doing at the peak (``"<toggler phase>, action <k>"``, or ``"surveying"``)."""
        self._world: RobotWorld | None = None

    def attach(self, trial: TrialContext) -> None:
        self._world = trial.world

    def waited(self, now: float) -> None:
        load_in_base = self._session.data.site_xmat[self._site].reshape(3, 3) @ self._session.ft.load_force()
        external = load_in_base - self._weight_in_base
        magnitude = math.sqrt(external @ external)  # np.linalg.norm, bit for bit, at a third of its cost
        if magnitude > self.peak:
            self.peak, self.peak_during = magnitude, self._doing()

    def _doing(self) -> str:
        world = self._world
        return "surveying" if world is None else f"{world.toggler.phase}, action {len(world.log) + 1}"


class SensedDigest(TrialObserver):
    """Evaluation only: a SHA-256 over everything the pipeline sensed (joint positions, wrenches, camera
    images), in the order it asked for them — a trial's fingerprint. Two executions of one task (in-process,
    in a worker, on Ray, after a resume) that agree on it sensed the same world and acted the same."""

    def __init__(self) -> None:
        self._digest = hashlib.sha256()

    def sensed(self, what: str, value: Any) -> None:
        if what.startswith("capture:"):
            camera = what.removeprefix("capture:")
            rgb = b"-" if value is None else np.ascontiguousarray(value.rgb).tobytes()
            self._digest.update(camera.encode() + rgb)
        else:
            self._digest.update(np.ascontiguousarray(value, dtype=np.float64).tobytes())

    def hexdigest(self) -> str:
        return self._digest.hexdigest()
