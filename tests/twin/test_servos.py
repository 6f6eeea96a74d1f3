"""The servo interface after a command stall: the backlog is taken in order, one command per controller cycle."""

from __future__ import annotations

import dataclasses

import numpy as np

from puzzlebox.models.generator import paper_family
from puzzlebox.twin.reality import PRESETS, ArmReality
from puzzlebox.twin.servos import CONTROLLER_CYCLE
from puzzlebox.twin.session import TwinSession

# the harsh arm's latency and stall length (twin/reality.py HARSH), stalls placed by hand below
ARM = ArmReality(command_latency=0.010, stall_rate=0.1, stall_duration=0.190)
BACKLOG = 10  # commands sent during the stall, one per 10 ms control tick


def now(s: TwinSession) -> int:
    """The session's physics step."""
    return round(s.time / s.timestep)


def stalled_backlog(s: TwinSession) -> tuple[list[np.ndarray], int]:
    """Start a stall 5 steps from now and send :data:`BACKLOG` targets during it; return them with one more
    target (for after the stall) and the stall's end (its last step + 1) [physics steps]."""
    start = now(s) + 5
    s.servos.set_state({**s.servos.get_state(), "stall_start": start})
    end = start + round(ARM.stall_duration / s.timestep)
    home = s.robot.joint_positions()
    targets = [home + 0.002 * (k + 1) for k in range(BACKLOG + 1)]
    s.step(10)
    for target in targets[:BACKLOG]:
        s.robot.command_joint_positions(target)
        s.step(5)
    assert now(s) < end
    return targets, end


def first_steps(
    s: TwinSession, targets: list[np.ndarray], until: int, send: tuple[int, np.ndarray] | None = None
) -> list[int | None]:
    """Step to ``until`` (sending ``send[1]`` at step ``send[0]``); the step at which each target was first
    the arm's servo target (None: never)."""
    first: list[int | None] = [None] * len(targets)
    while now(s) < until:
        if send is not None and now(s) == send[0]:
            s.robot.command_joint_positions(send[1])
        s.step(1)
        for i, target in enumerate(targets):
            if first[i] is None and np.array_equal(s.data.ctrl[s.arm_actuators], target):
                first[i] = now(s)
    return first


def test_a_stall_backlog_takes_effect_in_order_one_command_per_controller_cycle():
    reality = dataclasses.replace(PRESETS["ideal"], name="test", arm=ARM)
    with TwinSession(paper_family("test")[0], seed=0, reality=reality) as s:
        targets, end = stalled_backlog(s)
        cycle = round(CONTROLLER_CYCLE / s.timestep)
        assert cycle == 2  # 4 ms at 2 ms physics steps
        # the stall's end step took the first queued command, not the last
        first = first_steps(s, targets, end + 40, send=(end + 1, targets[BACKLOG]))
        assert first[0] == end
        # then one per cycle, in order; the one sent after the stall waited its turn behind the backlog
        assert first == [end + cycle * k for k in range(BACKLOG + 1)]


def test_a_draining_backlog_round_trips_through_the_session_state():
    reality = dataclasses.replace(PRESETS["ideal"], name="test", arm=ARM)
    with TwinSession(paper_family("test")[0], seed=0, reality=reality) as s:
        targets, end = stalled_backlog(s)
        s.step(end + 3 - now(s))  # two commands of the backlog taken, eight queued
        saved = s.get_state()
        late = (end + 5, targets[BACKLOG])  # must queue behind the restored backlog
        first = first_steps(s, targets[2:], end + 40, send=late)
        qpos = s.data.qpos.copy()
        s.set_state(saved)
        assert first_steps(s, targets[2:], end + 40, send=late) == first == [end + 2 * k for k in range(2, BACKLOG + 1)]
        assert np.array_equal(s.data.qpos, qpos)
