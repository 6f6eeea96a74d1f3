"""Trials on a real cell for scripts/trial.py (``--robot xarm``): one run of an agent on the box on the table,
through the same pipeline as a twin trial — the survey, ArUco perception, the agent, the primitives, F/T
outcomes — over any :class:`models.robot.Robot` (``real.XArmRobot``), configured by the cell's config
(:class:`models.cell_config.CellConfig`) and camera calibration.

Nothing here reads a simulator: there is no ground truth, so the record holds only what was sensed (each
action's outcome as the F/T sensor and the cameras told it, whether the goal was reached as perceived, the
wall and robot time). A stop by the arm's safety limits (:class:`real.errors.ArmStopped`: its force limit, its
workspace) ends the trial: the record says so (``stopped``) and keeps every action finished before it.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from puzzlebox.lab.narrated_world import NarratedWorld
from puzzlebox.lab.observers import ObservedRobot, TrialContext, TrialObserver
from puzzlebox.learning import Agent, RunResult, make_agent, run_episode
from puzzlebox.learning.belief import CELL_BELIEF
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.learning.trial import ActionRecord
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.cell_config import CellConfig
from puzzlebox.models.robot import Robot
from puzzlebox.real.errors import ArmStopped
from puzzlebox.skills import SkillError
from puzzlebox.skills.perception import MarkerDetector, PerceptionConfig
from puzzlebox.skills.primitives import PrimitiveConfig, Toggler
from puzzlebox.skills.robot_world import RobotWorld, WorldConfig
from puzzlebox.skills.scene_survey import SurveyConfig

REST_TOLERANCE = 0.01
"""A handed-over arm farther than this from the cell's rest posture on any joint is moved there first [rad]."""


def cell_configs(cell: CellConfig) -> tuple[WorldConfig, PerceptionConfig]:
    """The pipeline's configs for ``cell``: its force limit and latch threshold (the world's primitives), its
    cameras (the world's survey), its markers' dictionary and size (the rest the defaults). A force limit the
    primitives cannot work under (at or below their 35 N sideways-latch magnitude) is a :class:`ValueError`
    naming it."""
    world = WorldConfig(survey=SurveyConfig.for_cell(cell), primitives=PrimitiveConfig.for_cell(cell))
    return world, PerceptionConfig.for_cell(cell)


def go_to_rest(robot: Robot, cell: CellConfig, primitives: PrimitiveConfig) -> bool:
    """Move the arm to the cell's rest posture (out of the overview camera's view) unless it is there already;
    the toggler's rest posture is where the arm is handed over to it. Returns whether it moved."""
    rest = np.asarray(cell.rest_posture, dtype=float)
    if np.max(np.abs(robot.joint_positions() - rest)) <= REST_TOLERANCE:
        return False
    toggler = Toggler(robot, primitives)
    toggler.rest_posture = rest
    toggler.go_rest()
    return True


def _entry(
    result: RunResult, world: RobotWorld | None, spec: PuzzleSpec, robot: Robot, wall: float, stopped: str
) -> dict[str, Any]:
    by_marker = {c.marker: c.name for c in spec.components}
    entry = result.to_dict()
    entry["wall_time_s"] = time.perf_counter() - wall
    entry["robot_time_s"] = float(robot.time)
    entry["stopped"] = stopped
    entry["perceived_closed_poses"] = (
        {by_marker[m]: [float(v) for v in pose] for m, pose in world.closed_poses.items()} if world else {}
    )
    entry["timeline"] = [{**a.to_dict(), "component": by_marker[a.marker]} for a in (world.log if world else [])]
    for action in entry["timeline"]:
        del action["true_moved"]  # no ground truth on a real cell
    return entry


def run_real_trial(
    robot: Robot,
    calibration: CellCalibration,
    spec: PuzzleSpec,
    cell: CellConfig,
    agent_name: str,
    seed: int,
    max_actions: int,
    memory: MemoryStore | None = None,
    checkpoint: str | None = None,
    on_action: Callable[[Any], None] | None = None,
    on_record: Callable[[dict[str, Any]], None] | None = None,
    primitives: PrimitiveConfig | None = None,
    max_lockers: int | None = None,
    agent: Agent | None = None,
    observers: Sequence[TrialObserver] = (),
) -> dict[str, Any]:
    """One trial of ``agent_name`` on the box ``spec`` describes, standing in front of ``robot``; returns its
    record (the contract's run entry plus ``timeline``, ``stopped``, ``robot_time_s``, ``perceived_closed_poses``).

    ``calibration`` is the cell's camera calibration, ``cell`` its config (cameras, markers, force thresholds,
    rest posture: :func:`cell_configs`; ``primitives`` overrides the primitives' config). The world knows the
    spec's marker map and goal, never the box's state. ``on_action`` is called after every action as
    ``learning.run_episode`` calls it, ``on_record`` with the record so far after every action and once at the
    end (after a stop too): a caller writes it as it grows. ``max_lockers``: the most lockers the agent's belief
    allows one component (1: the paper's; None: what fits the scene and the memory). ``agent``: an agent object of
    one's own instead of ``agent_name``'s;
    ``observers`` see every reading, wait and action as in a twin trial (:mod:`puzzlebox.lab.observers`; no
    session: a real cell has no simulator to read)."""
    wall = time.perf_counter()
    world_config, perception = cell_configs(cell)
    if primitives is not None:
        world_config = replace(world_config, primitives=primitives)
    by_marker = {c.marker: c for c in spec.components}
    world: RobotWorld | None = None
    stopped = ""

    def progress(action: Any) -> None:
        if on_action is not None:
            on_action(action)
        if on_record is not None and world is not None:
            on_record(_entry(_unfinished(spec, seed, world, wall, ""), world, spec, robot, wall, ""))

    trial = TrialContext(spec, seed, None)
    if observers:
        robot = ObservedRobot(robot, observers)
    try:
        go_to_rest(robot, cell, world_config.primitives)
        world = RobotWorld(
            robot,
            calibration,
            {c.marker: c.kind for c in spec.components},
            spec.components[spec.index_of(spec.goal.component)].marker,
            goal_state=spec.goal.state,
            seed=seed,
            config=world_config,
            names={m: c.name for m, c in by_marker.items()},  # the spec's names, for the record
            detector=MarkerDetector(perception),
        )
        if agent is None:
            agent = make_agent(agent_name, spec, memory, checkpoint, belief=CELL_BELIEF, max_lockers=max_lockers)
        trial.world, trial.agent = world, agent
        for observer in observers:
            observer.attach(trial)
        acting = NarratedWorld(world, observers, lambda: getattr(agent, "decisions", [])) if observers else world
        result = run_episode(agent, acting, spec.name, seed, max_actions, progress)
    except ArmStopped as err:  # the arm was stopped (force, workspace): what was done before stays in the record
        stopped = str(err)
        result = _unfinished(spec, seed, world, wall, f"{type(err).__name__}: {err}")
    except SkillError as err:  # the cell could not run this trial (markers not seen...): say why
        result = _unfinished(spec, seed, world, wall, f"{type(err).__name__}: {err}")
    for observer in observers:
        observer.finish()
    entry = _entry(result, world, spec, robot, wall, stopped)
    if on_record is not None:
        on_record(entry)
    return entry


def _unfinished(spec: PuzzleSpec, seed: int, world: RobotWorld | None, wall: float, why: str) -> RunResult:
    """The run of a trial that ended early (or so far): the actions the world logged, its goal as perceived."""
    log = world.log if world else []
    names = world.names if world else {}
    assert names is not None  # run_real_trial's world is made with the spec's names
    actions = [ActionRecord(names[a.marker], a.result) for a in log]
    solved = bool(world is not None and world.observe().solved)
    return RunResult(spec.name, seed, solved, len(log), time.perf_counter() - wall, actions, ended=why)


__all__ = ["cell_configs", "go_to_rest", "run_real_trial"]
