"""Twin trials: one seeded end-to-end run of an agent on a spec in the twin — perception, the agent, the
primitives, physics — observed by its observers (:mod:`puzzlebox.lab.observers`), with a timeline."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.lab.narrated_world import NarratedWorld
from puzzlebox.lab.observers import ObservedRobot, PeakWristForce, SensedDigest, TrialContext, TrialObserver
from puzzlebox.lab.process_memory import release_freed_memory
from puzzlebox.lab.rollout_observers import RecordingDetector, RerunRecording, RolloutVideo, scene_cameras
from puzzlebox.lab.state_log import StateLog, scene_of
from puzzlebox.lab.trial_config import TrialConfig
from puzzlebox.lab.trial_record import TrialRecord
from puzzlebox.learning import Agent, RunResult, make_agent, run_episode
from puzzlebox.learning.belief import CELL_BELIEF
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.kinds import PUZZLE_KINDS
from puzzlebox.models.robot import Robot
from puzzlebox.models.scene import SceneConfig
from puzzlebox.skills import MarkerDetector, SkillError
from puzzlebox.skills.robot_world import RobotWorld
from puzzlebox.twin.errors import SimulationDiverged
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.rerun_log import TrialRecording
from puzzlebox.twin.rollout_video import BackgroundRollout
from puzzlebox.twin.session import TwinConfig, TwinSession

__all__ = ["evaluation_world", "open_twin_world", "run_twin_trial", "trial_world", "twin_session", "wrong_kind"]


def evaluation_world(
    session: TwinSession,
    robot: Any = None,
    calibration: CellCalibration | None = None,
    seed: int = 0,
    told_kinds: Mapping[str, str] | None = None,
    detector: MarkerDetector | None = None,
) -> RobotWorld:
    """The world a twin trial runs on ``session`` (through ``robot``, default the session's): the spec's
    goal and markers, ``calibration`` (default: the nominal one, exact only under ``ideal``), and — for
    scoring only, never for deciding — the simulator's component states and names. ``told_kinds`` (component
    name -> kind) overrides what the pipeline is told of those components' kinds (a misreported kind)."""
    spec = session.spec
    by_marker = {c.marker: i for i, c in enumerate(spec.components)}
    told = told_kinds or {}
    return RobotWorld(
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


def wrong_kind(spec: PuzzleSpec, seed: int) -> dict[str, str]:
    """One component of ``spec`` and a kind it is not, drawn from ``seed``: the symbolic protocols' "wrong
    kind" fault (``FaultConfig.misreported_kinds = 1``) for a twin trial."""
    rng = np.random.default_rng([seed, 0x6B1D])
    component = spec.components[int(rng.integers(len(spec.components)))]
    others = [k for k in PUZZLE_KINDS if k != component.kind]
    return {component.name: others[int(rng.integers(len(others)))]}


def twin_session(spec: PuzzleSpec, config: TrialConfig) -> TwinSession:
    """The twin session of a trial: ``spec`` under ``config``'s reality profile, seed and locks (a context
    manager; the profile may place the box elsewhere: the session's ``spec`` is the placed one)."""
    return TwinSession(
        spec, seed=config.seed, reality=config.reality, config=TwinConfig(scene=SceneConfig(locks=config.locks))
    )


def trial_world(session: TwinSession, config: TrialConfig, robot: Robot | None = None) -> RobotWorld:
    """The world of a trial of ``config`` on ``session`` (through ``robot``, default the session's): its
    calibration, seed and, with ``misreport_kind``, one kind told wrong (:func:`evaluation_world`)."""
    told = wrong_kind(session.spec, config.seed) if config.misreport_kind else {}
    return evaluation_world(session, robot, config.calibration, config.seed, told)


@contextlib.contextmanager
def open_twin_world(
    spec: PuzzleSpec, config: TrialConfig, observers: Sequence[TrialObserver] = ()
) -> Iterator[RobotWorld]:
    """The world of a twin trial, for one's own loop: ``world.observe()``, ``world.try_toggle(i)`` drive the robot
    through perception and the primitives; ``observers`` see every reading and wait (not the actions: a loop of
    one's own tells no caption). The session closes when the block ends."""
    with twin_session(spec, config) as session:
        world = trial_world(session, config, ObservedRobot(session.robot, observers) if observers else None)
        trial = TrialContext(session.spec, config.seed, session, world)
        for observer in observers:
            observer.attach(trial)
        try:
            yield world
        finally:
            for observer in observers:
                observer.finish()


def run_twin_trial(
    spec: PuzzleSpec,
    config: TrialConfig,
    agent: Agent | None = None,
    memory: MemoryStore | None = None,
    observers: Sequence[TrialObserver] = (),
    video: Path | None = None,
    recording: Path | None = None,
    on_action: Callable[[Any], None] | None = None,
    state_log: Path | None = None,
) -> TrialRecord:
    """One end-to-end twin trial of ``agent`` (default: ``config.agent`` made for the spec, with ``memory``):
    the record, with a ``timeline``. ``video``: an MP4 of the rollout written there; ``recording``: a Rerun
    recording (``.rrd``); ``state_log``: the trial's state at every control tick (``.npz``,
    :mod:`puzzlebox.lab.state_log`); each is published when the trial ends and discarded if it raises.
    ``observers`` see every reading, command, wait and action; ``on_action`` is called after every try (a
    progress bar)."""
    wall = time.perf_counter()
    scene = scene_of(spec, config) if state_log is not None else None  # (the spec as given: placed alike again)
    with twin_session(spec, config) as session:
        spec = session.spec  # placed by the profile, if it places boxes
        seed = config.seed
        told_kinds = wrong_kind(spec, seed) if config.misreport_kind else {}
        peak, digest = PeakWristForce(session), SensedDigest()
        with contextlib.ExitStack() as outputs:
            watching: list[TrialObserver] = []
            detector = None
            if video is not None or recording is not None or scene is not None:
                detector = RecordingDetector()
                if video is not None:
                    rollout = outputs.enter_context(BackgroundRollout(video, session.model, scene_cameras(session)))
                    watching.append(RolloutVideo(session, rollout, detector))
                if recording is not None:
                    rrd = outputs.enter_context(TrialRecording(recording, f"{spec.name}-seed{seed}"))
                    watching.append(RerunRecording(session, rrd, detector))
            states = StateLog(session, scene, detector) if scene is not None else None
            watching += [peak, digest, *observers, *([states] if states is not None else [])]
            robot = ObservedRobot(session.robot, watching)
            trial = TrialContext(spec, seed, session)
            world = None
            pose_errors: dict[str, float] = {}
            try:
                world = evaluation_world(session, robot, config.calibration, seed, told_kinds, detector)
                trial.world = world
                for c in spec.components:  # perceived closed pose against the simulator's (evaluation only)
                    truth = session.data.site(session.scene.names.components[c.name].frame_site).xpos
                    pose_errors[c.name] = float(np.linalg.norm(world.closed_poses[c.marker][:2] - truth[:2]))
                if agent is None:
                    checkpoint = None if config.checkpoint is None else str(config.checkpoint)
                    agent = make_agent(
                        config.agent, spec, memory, checkpoint, belief=CELL_BELIEF, max_lockers=config.max_lockers
                    )
                trial.agent = agent
                for observer in watching:
                    observer.attach(trial)
                acting = NarratedWorld(world, watching, lambda: getattr(agent, "decisions", []))
                result = run_episode(agent, acting, spec.name, seed, config.max_actions, on_action)
            except (SkillError, SimulationDiverged) as err:  # the cell could not run this trial: say why
                result = RunResult(spec.name, seed, False, len(world.log) if world else 0, 0.0,
                                   ended=f"{type(err).__name__}: {err}")  # fmt: skip
            for observer in watching:
                observer.finish()
            if states is not None and state_log is not None:  # (not written if the trial raised)
                states.save(state_log)
        sim_time = session.time
        box_pose = tuple(session.box_pose)
        reality = session.reality.name
    by_marker = {c.marker: i for i, c in enumerate(spec.components)}
    found = {spec.components[by_marker[m]].name: kind for m, kind in (world.found_kinds if world else {}).items()}
    timeline = tuple(
        {**a.to_dict(), "component": spec.components[by_marker[a.marker]].name,
         "pose_error_m": pose_errors.get(spec.components[by_marker[a.marker]].name)}
        for a in (world.log if world else [])
    )  # fmt: skip
    # the session's scene, frames and logs are garbage now: hand them back, or a long worker grows (issue 37)
    release_freed_memory()
    return TrialRecord.of_run(
        result,
        wall_time_s=time.perf_counter() - wall,
        sim_time_s=sim_time,
        perceived_position_error_m=pose_errors,
        box_pose=box_pose,
        reality=reality,
        peak_true_wrist_force_n=peak.peak,
        peak_true_wrist_force_during=peak.peak_during,
        sensed_sha256=digest.hexdigest(),
        told_kinds=told_kinds if config.misreport_kind else None,
        found_kinds=found if found or config.misreport_kind else None,
        timeline=timeline,
    )
