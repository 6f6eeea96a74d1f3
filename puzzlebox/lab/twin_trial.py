"""Twin trials for scripts/trial.py: one seeded end-to-end run of an agent on a spec in the twin —
perception, the agent, the primitives, physics — with a timeline and, optionally, a video."""

from __future__ import annotations

import collections
import contextlib
import hashlib
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.learning import RunResult, make_agent, run_episode
from puzzlebox.learning.belief import CELL_BELIEF
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.kinds import PUZZLE_KINDS
from puzzlebox.models.scene import SceneConfig
from puzzlebox.skills import MarkerDetector, SkillError
from puzzlebox.skills.twin_world import TwinWorld
from puzzlebox.twin.errors import SimulationDiverged
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.reality import RealityProfile
from puzzlebox.twin.rerun_log import TrialRecording
from puzzlebox.twin.rollout_video import BackgroundRollout, Caption, RolloutFrame, SceneCameras
from puzzlebox.twin.session import TwinConfig, TwinSession


class RolloutRecorder:
    """The robot interface, handing a :class:`twin.rollout_video.RolloutFrame` to the background drawer every
    ``RolloutConfig.period`` of simulated time: the joint positions, the caption of the action under way, the
    pipeline's latest detections (:class:`RecordingDetector`) and the recent wrist force the primitives
    sensed. It reads nothing the pipeline senses (no extra F/T or camera reading: the trial is the same trial
    with or without video); drawing happens in the other process."""

    def __init__(self, robot, session: TwinSession, rollout: BackgroundRollout, detector: RecordingDetector) -> None:
        self._robot, self._session, self._rollout, self._detector = robot, session, rollout, detector
        self._period = rollout.config.period
        self._window = rollout.config.plot_window
        self._next = 0.0
        self.caption = Caption()
        self.force: Callable[[], float | None] = lambda: None
        """The wrist force the primitives sensed last [N] (set once the world exists)."""
        self.phase: Callable[[], str] = lambda: "surveying"
        self._forces: collections.deque[tuple[float, float]] = collections.deque()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)

    def wait(self, seconds: float) -> None:
        self._robot.wait(seconds)  # never cut: where a wait is cut moves the twin's latch updates
        now = self._robot.time
        force = self.force()
        if force is not None:
            self._forces.append((now, force))
            while self._forces and self._forces[0][0] < now - self._window:
                self._forces.popleft()
        while self._next <= now:  # a frame per grid time 0, period, 2 period, ... this wait passed: the state
            self._frame(self._next)  # at its end (a 10 ms control tick; a look or a settle waits up to ~1 s)
            self._next += self._period

    def begin(self, caption: Caption) -> None:
        self.caption = caption

    end = begin

    def last_frame(self) -> None:
        """The trial's last frame, whatever the time: it shows how the last action ended."""
        self._frame(self._robot.time)

    def _frame(self, now: float) -> None:
        self._rollout.add(
            RolloutFrame(
                time=now, qpos=self._session.data.qpos.copy(), caption=replace(self.caption, phase=self.phase()),
                detections=dict(self._detector.latest), forces=np.array(self._forces, dtype=float).reshape(-1, 2),
            )
        )  # fmt: skip


class RecordingDetector(MarkerDetector):
    """The pipeline's marker detector, keeping its latest detections per camera for the rollout video (the
    video shows what the pipeline detected, never detecting again)."""

    def __init__(self) -> None:
        super().__init__()
        self.latest: dict[str, tuple[float, list[tuple[int, np.ndarray]]]] = {}
        """Camera name -> capture time [s] and detections (marker id, corners [px]) of its latest look."""
        self.listeners: list[Callable[[str, float, list[tuple[int, np.ndarray]]], None]] = []
        """Called with (camera, capture time, detections) after every look (a Rerun recording's)."""

    def detect(self, image, camera, T_base_tcp=None):
        found = super().detect(image, camera, T_base_tcp)
        if image is not None:
            seen = [(d.marker_id, d.corners_px.copy()) for d in found]
            self.latest[image.camera] = (image.time, seen)
            for listener in self.listeners:
                listener(image.camera, image.time, seen)
        return found


class NarratedWorld:
    """The world, telling its listeners (the rollout video, the Rerun recording) which action is under way and
    how it ended: ``begin(caption)`` before the try, ``end(caption)`` after it with the outcome as sensed and,
    in evaluation, the truth; ``decisions`` gives the agent's decisions so far (its ``w`` and ``Q``)."""

    def __init__(self, world: TwinWorld, listeners: list[Any], decisions: Callable[[], list]) -> None:
        self._world, self._listeners, self._decisions = world, listeners, decisions
        self._last = Caption()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._world, name)

    def try_toggle(self, index: int):
        world = self._world
        marker = world.markers[index]
        name = (world.names or {}).get(marker, f"marker {marker}")
        decisions = self._decisions()
        decision = decisions[-1] if decisions else None
        caption = Caption(
            previous=self._last.ending(),
            action=len(world.log) + 1,
            component=f"{name} ({world.marker_map[marker]})",
            weight_info=None if decision is None else float(decision.weight_info),
            q_info=None if decision is None else float(decision.q_info[index]),
            q_exploit=None if decision is None else float(decision.q_exploit[index]),
        )
        for listener in self._listeners:
            listener.begin(caption)
        result = world.try_toggle(index)
        truth = world.log[-1].true_moved if world.log else None
        self._last = replace(
            caption, sensed=result.outcome, truth="" if truth is None else ("moved" if truth else "did not move")
        )
        for listener in self._listeners:
            listener.end(self._last)
        return result


class RerunRecorder:
    """The robot interface, logging the trial into a :class:`twin.rerun_log.TrialRecording`: every image the
    pipeline captured (as captured), and every ``RecordConfig.period`` of simulated time the arm's and the
    components' poses, the TCP and the wrist force the primitives sensed; as a :class:`NarratedWorld` listener,
    every decision, outcome and the agent's belief after it. It reads nothing the pipeline senses beyond what the
    pipeline itself asked for (the same trial with or without a recording)."""

    def __init__(self, robot, session: TwinSession, recording: TrialRecording) -> None:
        self._robot, self._session, self.recording = robot, session, recording
        m = session.model
        names = session.scene.names
        self._arm = [b for b in range(m.nbody) if m.body(b).name.startswith("xarm7/")]
        self._arm_names = [m.body(b).name.removeprefix("xarm7/") for b in self._arm]
        self._components = [m.body(c.body).id for c in names.components.values()]
        self._component_names = list(names.components)
        self._tcp = m.site(names.tcp_site).id
        self._next = 0.0
        self.force: Callable[[], np.ndarray | None] = lambda: None
        self.belief: Callable[[], np.ndarray | None] = lambda: None

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)

    def capture(self, camera: str):
        image = self._robot.capture(camera)
        if image is not None:
            self.recording.at(image.time)
            self.recording.image(camera, image.rgb)
        return image

    def markers(self, camera: str, time: float, detections: list) -> None:
        self.recording.at(time)
        self.recording.markers(camera, detections)

    def wait(self, seconds: float) -> None:
        self._robot.wait(seconds)
        now = self._robot.time
        if now < self._next:
            return
        while self._next <= now:  # on the grid 0, period, 2 period, ... (a long wait skips points)
            self._next += self.recording.config.period
        d = self._session.data
        bodies = {
            "world/arm": (self._arm_names, d.xpos[self._arm], d.xquat[self._arm]),
            "world/components": (self._component_names, d.xpos[self._components], d.xquat[self._components]),
        }
        self.recording.sample(now, bodies, d.site_xpos[self._tcp], self.force())

    def begin(self, caption: Caption) -> None:
        self.recording.at(self._robot.time)
        values = "" if caption.q_info is None else f": w {caption.weight_info:.3f}, Q_info {caption.q_info:.4f}, "
        values += "" if caption.q_exploit is None else f"Q_exploit {caption.q_exploit:.4f}"
        self.recording.decision(f"action {caption.action}: try {caption.component}{values}", caption.weight_info)

    def end(self, caption: Caption) -> None:
        self.recording.at(self._robot.time)
        truth = f" (truth: {caption.truth})" if caption.truth else ""
        self.recording.decision(f"action {caption.action} {caption.component}: {caption.sensed}{truth}")
        belief = self.belief()
        if belief is not None:
            self.recording.belief(belief)


class TrueForceWatch:
    """Evaluation only: the largest true external force on the wrist over a trial [N], sampled after
    every robot wait (each 10 ms control tick) from the sensor model's noiseless load, less the weight of
    what hangs below the sensor — what the safety-limit target is checked against, whatever the robot
    sensed."""

    def __init__(self, robot, session: TwinSession) -> None:
        self._robot, self._session = robot, session
        m = session.model
        self._site = m.site(session.scene.names.ft_site).id
        hanging = m.body_subtreemass[m.site_bodyid[self._site]]  # the flange and the gripper: 7.37 N of weight
        self._weight_in_base = hanging * m.opt.gravity
        self.peak = 0.0
        self.peak_during = ""
        """What the arm was doing at the peak (from :attr:`doing`)."""
        self.doing: Any = lambda: "surveying"
        """Callable naming what the arm is doing, for :attr:`peak_during`."""

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)

    def wait(self, seconds: float) -> None:
        self._robot.wait(seconds)
        load_in_base = self._session.data.site_xmat[self._site].reshape(3, 3) @ self._session.ft.load_force()
        external = load_in_base - self._weight_in_base
        magnitude = math.sqrt(external @ external)  # np.linalg.norm, bit for bit, at a third of its cost
        if magnitude > self.peak:
            self.peak, self.peak_during = magnitude, self.doing()


class SensedDigest:
    """Evaluation only: a SHA-256 over everything the pipeline sensed (joint positions, wrenches, camera
    images), in the order it asked for them — a trial's fingerprint. Two executions of one task (in-process,
    in a worker, on Ray, after a resume) that agree on it sensed the same world and acted the same."""

    def __init__(self, robot) -> None:
        self._robot = robot
        self._digest = hashlib.sha256()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)

    def joint_positions(self) -> np.ndarray:
        q = self._robot.joint_positions()
        self._digest.update(np.ascontiguousarray(q, dtype=np.float64).tobytes())
        return q

    def wrench(self) -> np.ndarray:
        w = self._robot.wrench()
        self._digest.update(np.ascontiguousarray(w, dtype=np.float64).tobytes())
        return w

    def capture(self, camera: str):
        image = self._robot.capture(camera)
        self._digest.update(camera.encode() + (b"-" if image is None else np.ascontiguousarray(image.rgb).tobytes()))
        return image

    def hexdigest(self) -> str:
        return self._digest.hexdigest()


def evaluation_world(
    session: TwinSession,
    robot: Any = None,
    calibration: CellCalibration | None = None,
    seed: int = 0,
    told_kinds: Mapping[str, str] | None = None,
    detector: MarkerDetector | None = None,
) -> TwinWorld:
    """The world a twin trial runs on ``session`` (through ``robot``, default the session's): the spec's
    goal and markers, ``calibration`` (default: the nominal one, exact only under ``ideal``), and — for
    scoring only, never for deciding — the simulator's component states and names. ``told_kinds`` (component
    name -> kind) overrides what the pipeline is told of those components' kinds (a misreported kind)."""
    spec = session.spec
    by_marker = {c.marker: i for i, c in enumerate(spec.components)}
    told = told_kinds or {}
    return TwinWorld(
        robot if robot is not None else session.robot,
        calibration if calibration is not None else nominal_calibration(session),
        {c.marker: told.get(c.name, c.kind) for c in spec.components},
        spec.components[spec.index_of(spec.goal.component)].marker,
        goal_state=spec.goal.state,
        seed=seed,
        ground_truth=lambda m: int(session.component_states()[by_marker[m]]),
        names={c.marker: c.name for c in spec.components},
        detector=detector,
    )


def agent_belief(agent: Any) -> np.ndarray | None:
    """The agent's belief as one-locker categoricals ``(N, 2, 1 + 2N)``, or None for an agent without one."""
    belief = getattr(agent, "belief", None)
    return None if belief is None else np.array(belief.single_locker_probs(), dtype=float)


def scene_cameras(session: TwinSession) -> SceneCameras:
    """What the rollout video's views look at in ``session``: its cameras, and its lid for the perspective view."""
    length, width, _ = session.spec.box.size
    names, render = session.scene.names, session.config.render
    return SceneCameras(
        overview=names.overview_camera,
        wrist=names.wrist_camera,
        lid_centre=tuple(float(v) for v in session.scene.T_world_lid[:3, 3]),
        lid_diagonal=float(np.hypot(length, width)),
        capture_size=(render.width, render.height),
    )


def wrong_kind(spec: PuzzleSpec, seed: int) -> dict[str, str]:
    """One component of ``spec`` and a kind it is not, drawn from ``seed``: the symbolic protocols' "wrong
    kind" fault (``FaultConfig.misreported_kinds = 1``) for a twin trial."""
    rng = np.random.default_rng([seed, 0x6B1D])
    component = spec.components[int(rng.integers(len(spec.components)))]
    others = [k for k in PUZZLE_KINDS if k != component.kind]
    return {component.name: others[int(rng.integers(len(others)))]}


def run_twin_trial(
    spec: PuzzleSpec,
    seed: int,
    agent_name: str,
    memory: MemoryStore | None,
    max_actions: int,
    video: Path | None,
    checkpoint: str | None = None,
    reality: RealityProfile | str | None = None,
    calibration: CellCalibration | None = None,
    on_action: Callable[[Any], None] | None = None,
    misreport_kind: bool = False,
    max_lockers: int = 1,
    record: Path | None = None,
    locks: str = "contact",
) -> dict[str, Any]:
    """One end-to-end trial; returns the contract's run entry plus a ``timeline`` and figures.

    ``reality`` is the twin's reality profile (default ``ideal``); ``calibration`` the cell's camera
    calibration (default: the twin's nominal, datasheet calibration — exact only under ``ideal``);
    ``misreport_kind``: the pipeline is told one component's kind wrong (:func:`wrong_kind`; in the entry as
    ``told_kinds``); ``max_lockers``: the most lockers the agent's belief allows one component (1: the paper's);
    ``record``: a Rerun recording of the trial written there (:mod:`twin.rerun_log`); ``locks``: the box's locks,
    ``contact`` mechanisms or ``latch`` (:attr:`models.scene.SceneConfig.locks`)."""
    wall = time.perf_counter()
    by_marker = {c.marker: i for i, c in enumerate(spec.components)}
    config = TwinConfig(scene=SceneConfig(locks=locks))
    with TwinSession(spec, seed=seed, reality=reality, config=config) as session:
        spec = session.spec  # placed by the profile, if it places boxes
        told_kinds = wrong_kind(spec, seed) if misreport_kind else {}
        robot = session.robot
        # the video and the recording are published when this block ends, discarded if it raises
        with contextlib.ExitStack() as outputs:
            recorder = detector = logger = None
            if video is not None or record is not None:
                detector = RecordingDetector()
            if video is not None:
                rollout = outputs.enter_context(BackgroundRollout(video, session.model, scene_cameras(session)))
                robot = recorder = RolloutRecorder(robot, session, rollout, detector)
            if record is not None:
                recording = outputs.enter_context(TrialRecording(record, f"{spec.name}-seed{seed}"))
                robot = logger = RerunRecorder(robot, session, recording)
                detector.listeners.append(logger.markers)
            robot = watch = TrueForceWatch(robot, session)
            robot = sensed = SensedDigest(robot)
            world = None
            pose_errors: dict[str, float] = {}
            try:
                world = evaluation_world(session, robot, calibration, seed, told_kinds, detector)
                watch.doing = lambda: f"{world.toggler.phase}, action {len(world.log) + 1}"
                for c in spec.components:  # perceived closed pose against the simulator's (evaluation only)
                    truth = session.data.site(session.scene.names.components[c.name].frame_site).xpos
                    pose_errors[c.name] = float(np.linalg.norm(world.closed_poses[c.marker][:2] - truth[:2]))
                agent = make_agent(agent_name, spec, memory, checkpoint, belief=CELL_BELIEF, max_lockers=max_lockers)
                acting: Any = world
                if recorder is not None:
                    recorder.phase = lambda: world.toggler.phase
                    recorder.force = lambda: math.sqrt(world.toggler.force_in_base @ world.toggler.force_in_base)
                if logger is not None:
                    logger.force = lambda: np.array(world.toggler.force_in_base, dtype=float)
                    logger.belief = lambda: agent_belief(agent)
                listeners = [x for x in (recorder, logger) if x is not None]
                if listeners:
                    acting = NarratedWorld(world, listeners, lambda: getattr(agent, "decisions", []))
                result = run_episode(agent, acting, spec.name, seed, max_actions, on_action)
            except (SkillError, SimulationDiverged) as err:  # the cell could not run this trial: say why
                result = RunResult(spec.name, seed, False, len(world.log) if world else 0, 0.0,
                                   ended=f"{type(err).__name__}: {err}")  # fmt: skip
            if recorder is not None:
                recorder.last_frame()
        sim_time = session.time
    entry = result.to_dict()
    entry["wall_time_s"] = time.perf_counter() - wall
    entry["sim_time_s"] = sim_time
    entry["perceived_position_error_m"] = pose_errors
    entry["box_pose"] = list(session.box_pose)
    entry["reality"] = session.reality.name
    entry["peak_true_wrist_force_n"] = watch.peak
    entry["peak_true_wrist_force_during"] = watch.peak_during
    entry["sensed_sha256"] = sensed.hexdigest()
    if misreport_kind:
        entry["told_kinds"] = told_kinds
    entry["timeline"] = [
        {**asdict(a), "component": spec.components[by_marker[a.marker]].name,
         "pose_error_m": pose_errors.get(spec.components[by_marker[a.marker]].name)}
        for a in (world.log if world else [])
    ]  # fmt: skip
    return entry
