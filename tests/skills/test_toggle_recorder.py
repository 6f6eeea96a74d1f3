"""The toggle recorder logs what the robot reported at every tick of a toggle, changes nothing the pipeline senses
or does, and keeps nothing of the simulator's truth."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from puzzlebox.lab.twin_trial import evaluation_world
from puzzlebox.models.generator import paper_family
from puzzlebox.models.toggle_log import PHASES, ToggleLog
from puzzlebox.skills.toggle_recorder import ToggleRecorder
from puzzlebox.twin.session import TwinSession

SPEC = paper_family("train")[0]  # door-0 is free at the start


class Spy:
    """What the robot gave the pipeline: every wrench and F/T orientation read, and every command sent."""

    def __init__(self, robot) -> None:
        self._robot = robot
        self.readings: list[tuple[float, np.ndarray, np.ndarray]] = []
        self.commands: list[np.ndarray] = []

    def __getattr__(self, name):
        return getattr(self._robot, name)

    def wrench(self):
        w = self._robot.wrench()
        self.readings.append((self._robot.time, self._robot.ft_rotation_in_base(), w))
        return w

    def command_joint_positions(self, q):
        self._robot.command_joint_positions(q)
        self.commands.append(np.array(q, dtype=float))


def open_door(recorded: bool):
    with TwinSession(SPEC, seed=3, reality="realistic") as session:
        spy = Spy(session.robot)
        robot = ToggleRecorder(spy, {"spec": SPEC.name}) if recorded else spy
        world = evaluation_world(session, robot, seed=3)
        if recorded:
            robot.attach(world)
        door = [world.names[m] for m in world.markers].index("door-0")
        outcome = world.try_toggle(door)
        return outcome, session.data.qpos.copy(), spy, (robot.toggles if recorded else [])


@pytest.fixture(scope="module")
def runs():
    return open_door(recorded=True), open_door(recorded=False)


def test_a_recorded_toggle_senses_and_does_exactly_what_an_unrecorded_one_does(runs):
    (outcome, qpos, spy, _), (plain_outcome, plain_qpos, plain_spy, _) = runs
    assert outcome == plain_outcome and outcome.outcome == "moved"
    np.testing.assert_array_equal(qpos, plain_qpos)  # bit for bit: no extra sensor reading, no other command
    assert len(spy.readings) == len(plain_spy.readings)


def test_every_tick_of_a_toggle_holds_what_the_robot_reported_then(runs):
    (_, _, spy, toggles), _ = runs
    assert len(toggles) >= 1
    log = toggles[0]
    by_time = {t: (R, w) for t, R, w in spy.readings}
    assert log.ticks > 300 and set(log.time) <= set(by_time)
    for k in range(0, log.ticks, 37):
        R, w = by_time[log.time[k]]
        np.testing.assert_allclose(log.force[k], R @ w[:3])
        np.testing.assert_allclose(log.torque[k], R @ w[3:])
    assert any(np.array_equal(log.joint_command[-1], q) for q in spy.commands)
    assert {PHASES[p] for p in log.phase} >= {"approaching", "descending", "grasping", "actuating"}
    assert log.kind == "door" and log.outcome == "moved" and log.opening


def test_a_log_keeps_robot_data_only(runs):
    (_, _, _, toggles), _ = runs
    log = toggles[0]
    assert log.truth is None  # the recorder writes none: an evaluator may add it, beside the robot data
    robot_fields = {
        "component", "marker", "kind", "joint", "axis", "origin", "grasp_point", "pose", "travel", "opening",
        "outcome", "reason", "progress", "time", "joints", "closure", "tcp", "force", "torque", "joint_command",
        "gripper_command", "phase", "context", "truth",
    }  # fmt: skip
    assert {f.name for f in dataclasses.fields(ToggleLog)} == robot_fields
