"""The force margin (issue 36): no try puts more than 45 N of true force on the wrist (the guard stops at 60 N).

A lock's pins leave play: a part held open closes up to ~30 % of its travel before they meet. Closed into them at
the pace of a free part, a slide was driven on to the 60 N guard (63 N true) and left part-way, where the next try
descended onto its post (65 N); a stall past the breakaway is now read as a hold, and the handle taken back."""

import contextlib
import dataclasses
import math

import mujoco
import numpy as np
import pytest
from world_fixtures import TrueForceWatch

from puzzlebox.lab.observers import ObservedRobot, TrialObserver
from puzzlebox.lab.twin_trial import evaluation_world
from puzzlebox.models.generator import generate_chain, paper_family
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.placement import placed
from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.primitives import PrimitiveConfig
from puzzlebox.twin.reality import ArmReality, ForceTorqueReality, PhysicsReality, RealityProfile, load_profile
from puzzlebox.twin.session import TwinSession

FORCE_MARGIN = 45.0
"""Largest true wrist force a try may put on the wrist [N]."""

LATE_READING = RealityProfile(
    name="late F/T",
    force_torque=ForceTorqueReality(rate_hz=100.0, delay=0.030),
    arm=ArmReality(command_latency=0.010),
)
"""The harsh profile's late reading alone: the F/T 30 ms late at 100 Hz (with the toggler's running median), commands
10 ms late."""


@contextlib.contextmanager
def _closed_against_its_locker(kinds: list[str], reality: RealityProfile | None = None):
    """A chain of two ``kinds`` (seed 1) in the twin: its first part opened, then its second, which then holds the first
    open, and the first tried again (closing it). Yields the session, the watched robot (``peak`` counted from that
    last try), the world, the first part's index in it and that try's result."""
    spec = generate_chain(kinds, seed=1)
    with TwinSession(spec, seed=0, reality=reality) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        held, locker = (world.markers.index(c.marker) for c in spec.components)
        assert world.try_toggle(held).moved and world.try_toggle(locker).moved
        robot.peak = 0.0
        yield session, robot, world, held, world.try_toggle(held)


def test_a_part_held_open_by_a_lock_with_play_reads_blocked_within_the_margin_and_is_taken_back():
    with _closed_against_its_locker(["slide", "wheel"]) as (session, robot, world, slide, held):
        assert held.outcome == "blocked" and held.cause is Cause.HELD_PART_WAY, held
        assert robot.peak <= FORCE_MARGIN, robot.peak_during
        assert session.component_states()[0] == 1 and world.log[-1].progress > 0.1  # taken back where it was
        # and tried again, the handle is where the fingers descend
        again = world.try_toggle(slide)
        assert again.outcome == "blocked" and robot.peak <= FORCE_MARGIN, robot.peak_during


def test_a_descent_onto_a_handle_beside_where_it_was_aimed_stops_at_a_light_touch():
    # a rigid but wrong hand-eye pose puts the grasp point beside the handle (issue 37): one finger lands on its top
    spec = generate_chain(["slide", "wheel"], seed=1)
    with TwinSession(spec, seed=0) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        jm = world.joint_models[spec.components[0].marker]
        beside = 0.02 * jm.axis  # the fingers close along a slide's axis: one of them over the post
        aimed = dataclasses.replace(jm, origin=jm.origin + beside, grasp_point=jm.grasp_point + beside)
        robot.peak = 0.0
        missed = world.toggler.toggle(aimed)
        assert missed.last_stop().cause is Cause.FORCE_LIMIT and missed.last_stop().stopped_while == "descending", (
            missed
        )
        assert robot.peak <= FORCE_MARGIN, robot.peak  # 85 N true with the whole descent at its normal pace
        assert session.component_states()[0] == 0


def _aimed_beside(world, marker: int, offset: float):
    """The joint model of ``marker`` as perceived through a wrong hand-eye pose: ``offset`` [m] beside the handle
    along the fingers' closing axis (the TCP's y axis of ``top_down``), where the descent misses the handle."""
    jm = world.joint_models[marker]
    yaw = world.toggler.pinch.grasp_yaw(jm)
    beside = offset * np.array([np.sin(yaw), -np.cos(yaw), 0.0])
    return dataclasses.replace(jm, origin=jm.origin + beside, grasp_point=jm.grasp_point + beside)


@pytest.mark.parametrize("offset", [0.008, -0.012])
def test_a_grasp_aimed_beside_a_free_lever_yields_onto_its_handle_and_opens_it(offset):
    # the first finger to meet the post pushed it with the whole grip while the stiff arm held the hand where it was
    # aimed: 62-63 N true while grasping, stopped by the guard, the free lever left closed (issue 37)
    spec = generate_chain(["lever", "slide"], seed=1)
    with TwinSession(spec, seed=0) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        robot.peak = 0.0
        result = world.toggler.toggle(_aimed_beside(world, spec.components[0].marker, offset))
        assert result.outcome == "moved" and session.component_states()[0] == 1, result
        assert robot.peak <= FORCE_MARGIN, robot.peak


def test_a_grasp_aimed_beside_a_locked_slide_reads_it_blocked_within_the_margin():
    # before: 63 N true while grasping, the try failed at the guard instead of feeling the lock
    spec = generate_chain(["wheel", "slide"], seed=1)  # the closed wheel locks the slide
    with TwinSession(spec, seed=0) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        robot.peak = 0.0
        result = world.toggler.toggle(_aimed_beside(world, spec.components[1].marker, 0.012))
        assert result.outcome == "blocked" and session.component_states()[1] == 0, result
        assert robot.peak <= FORCE_MARGIN, robot.peak


def test_a_lever_held_open_by_its_lock_is_lifted_at_a_light_force_and_read_held():
    # a lever is closed by pulling its handle up its post, which the pads carry by friction alone: held open by its
    # lock, it stopped after the lock's play (~27 %) while the realistic pads slid up the post at 15-19 N along the
    # motion, never stalling (the hand kept rising), until they slid off its top; seen standing at 80-89 %, the try
    # "failed", and again, until the episode gave the lever up (the twin's training episodes, runs/s8/lever-close)
    spec = generate_chain(["lever", "wheel"], seed=0)  # the wheel, opened, keeps the lever open
    with TwinSession(spec, seed=0, reality=load_profile("realistic")) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        lever, wheel = (world.markers.index(c.marker) for c in spec.components)
        assert world.try_toggle(lever).moved and world.try_toggle(wheel).moved
        robot.peak = 0.0
        held = world.try_toggle(lever)
        assert held.outcome == "blocked" and held.cause is Cause.HELD_PART_WAY, held
        assert robot.peak <= FORCE_MARGIN, robot.peak_during
        travel = session.data.qpos[session.component_qpos[0]] / session.travel[0]
        assert session.component_states()[0] == 1 and travel > 0.9  # taken back into its open stop


def test_a_lever_left_part_way_is_pressed_into_its_stop_and_read_open():
    # a lever rests up to ~20 % pressed once lifted, and a try taken back leaves it lower: the fingers, aimed at its
    # closed pose, met its stop at 57-73 % of their travel and read it held part-way, again and again
    spec = generate_chain(["lever", "wheel"], seed=4)
    lever = spec.index_of("lever-0")
    with TwinSession(spec, seed=0) as session:
        session.data.qpos[session.component_qpos[lever]] = 0.3 * session.travel[lever]
        mujoco.mj_forward(session.model, session.data)
        world = evaluation_world(session)
        index = world.markers.index(spec.components[lever].marker)
        opened = world.try_toggle(index)
        assert opened.moved and session.component_states()[lever] == 1, opened
        assert world.log[-1].true_moved


def test_a_locked_lever_pressed_by_a_weak_grip_reads_blocked_at_a_light_force():
    # the pads hold a post along its length by friction alone: the harsh grip's slid down a locked lever's post
    # until the fingers met its arm, and the load rose there to 46-57 N true before the stall was read (here, with
    # the harsh grip and F/T delay alone: 41 N, read held part-way)
    weak_grip = RealityProfile(
        name="weak grip, late F/T",
        physics=PhysicsReality(pad_friction=0.25, grip_force_scale=1 / 3),
        force_torque=ForceTorqueReality(delay=0.030, rate_hz=100.0),
    )
    spec = generate_chain(["slide", "lever", "door"], seed=1)  # the closed slide keeps the lever up
    lever = spec.index_of("lever-1")
    with TwinSession(spec, seed=0, reality=weak_grip) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        robot.peak = 0.0
        pressed = world.try_toggle(world.markers.index(spec.components[lever].marker))
        assert pressed.outcome == "blocked", pressed
        assert robot.peak < PrimitiveConfig().judgement.blocked_force, (
            robot.peak_during
        )  # lighter than a latch elsewhere
        assert session.component_states()[lever] == 0


class _ActuatingTime(TrialObserver):
    """Simulated time the toggler spends actuating [s], summed over its control ticks."""

    def __init__(self) -> None:
        self.world, self.seconds, self._last = None, 0.0, None

    def waited(self, now: float) -> None:
        if self._last is not None and self.world is not None and self.world.toggler.phase == "actuating":
            self.seconds += now - self._last
        self._last = now


def test_a_free_lever_pressed_along_its_post_is_actuated_at_press_pace_and_opens():
    # a locked lever's post let the harsh grip's pads slide 8 mm at 6-9 N along the motion (a free lever is pressed
    # with ~4 N: no force tells the two apart) until the fingers met its arm: +12 N true in the first tick at the usual
    # pace, 46.5 N before the late reading showed it; the pace of the meeting sets that rise, so pressed handles go at
    # press_pace (runs/s7/lever-force)
    spec = generate_chain(["lever", "wheel"], seed=4)
    lever = spec.index_of("lever-0")
    config = PrimitiveConfig()
    with TwinSession(spec, seed=0) as session:
        watch = _ActuatingTime()
        world = watch.world = evaluation_world(session, ObservedRobot(session.robot, [watch]))
        opened = world.try_toggle(world.markers.index(spec.components[lever].marker))
        assert opened.moved and session.component_states()[lever] == 1, opened
    assert watch.seconds >= config.actuation.actuate_time / config.actuation.press_pace, (
        watch.seconds
    )  # 6.95 s (4.08 at the usual pace)


@contextlib.contextmanager
def _door_standing_at(angle: float, sticky: bool):
    """Door-0 of paper-test-0 (placed at (0.38, 0.12, -0.9)) standing at ``angle`` [rad] under the late reading, held
    wherever it stands (``sticky``: it jams at every move) or free: the session, the watched robot (``peak`` counted
    from here), the world, the door's marker and its joint's qpos address."""
    reality = dataclasses.replace(
        LATE_READING, name="late F/T, sticky door", physics=PhysicsReality(jam_probability=1.0 if sticky else 0.0)
    )
    spec = placed(paper_family("test", seed=0)[0], (0.38, 0.12, -0.9))
    door = spec.index_of("door-0")
    with TwinSession(spec, seed=0, reality=reality) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        angle_adr = session.component_qpos[door]
        session.data.qpos[angle_adr] = angle
        session.robot.wait(1.0)
        robot.peak = 0.0
        yield session, robot, world, spec.components[door].marker, angle_adr


@pytest.mark.parametrize("held_at", [64.0, None], ids=["held at 64 deg", "in its end stop"])
def test_a_top_up_push_against_a_door_that_does_not_turn_stops_at_a_light_touch(held_at):
    # the top-up pushes a door it cannot see on up into its stop from under its plate, wherever it stands; one held
    # where it stands (a jam, a latch: here it jams at every move) or already in its stop presses back at once, and
    # under the harsh profile's late reading (F/T 30 ms late, a 5-tick median, commands 10 ms late) the push went on
    # to 40-50 N true before it was felt (paper-test-2 seeds 100 and 101): here 48 N held, 40 N in the stop
    standing = get_kind("door").travel if held_at is None else math.radians(held_at)
    with _door_standing_at(standing, sticky=held_at is not None) as (session, robot, world, marker, angle):
        result = world.toggler.toggle(world.joint_models[marker], opening=True, raised=True)
        assert robot.peak < 30.0, robot.peak_during  # two thirds of the margin: a reading may be later still
        if held_at is None:
            assert result.outcome == "moved" and math.degrees(session.data.qpos[angle]) > 83.0, result
        else:
            assert result.outcome == "failed" and math.degrees(session.data.qpos[angle]) > held_at - 5.0, result


@pytest.mark.parametrize("hinge_off", [0.0, 0.008], ids=["hinge where seen", "hinge 8 mm towards the handle"])
def test_a_door_pinched_into_its_end_stop_under_a_late_reading_stays_in_the_margin_and_ends_in_its_stop(hinge_off):
    # past the travel the fingers over-travel on the planned arc while the door rises on its own; held on that arc
    # the grasp loaded up across the motion (~32 N realistic, paper-test-2 seed 105) and the handle's stick-slip in
    # the pads put 45-48 N true spikes on it: here, with the F/T 30 ms late and commands 10 ms late, 56 N in the
    # stop, and with the hinge seen 8 mm off 71 N with the door left at 66 deg. The path yields across itself there
    # as on the arc, until the end stop is felt; a door that reaches it unfelt is topped up.
    spec = placed(paper_family("test", seed=0)[0], (0.38, 0.12, -0.9))
    door = spec.index_of("door-0")
    with TwinSession(spec, seed=0, reality=LATE_READING) as session:
        robot = TrueForceWatch(session.robot, session)
        world = evaluation_world(session, robot)
        jm = world.joint_models[spec.components[door].marker]
        radial = jm.grasp_point - jm.origin
        radial -= float(radial @ jm.axis) * jm.axis
        aimed = dataclasses.replace(jm, origin=jm.origin + hinge_off * radial / float(np.linalg.norm(radial)))
        robot.peak = 0.0
        result = world.toggler.toggle(aimed, opening=True)
        assert robot.peak <= FORCE_MARGIN, robot.peak_during
        session.robot.wait(2.0)  # a door short of its stop sinks back under its own weight
        angle = session.data.qpos[session.component_qpos[door]]
        assert result.outcome == "moved" and angle > session.travel[door] - math.radians(2.0), (result, angle)


@pytest.mark.parametrize("locker", ["slide", "drawer"])
def test_a_door_held_open_by_its_locker_pushed_closed_under_a_late_reading_reads_latched_within_the_margin(locker):
    # the door sinks onto its locker's pin under its own weight (84 -> 61 deg) while the pads search for its plate at
    # 10 mm/s, ~1.5 mm behind their command; pressed on the plate, that lag alone loads the wrist by the arm's
    # stiffness (15-35 N/mm), and sped up to the schedule's pace as the contact was felt the push put 91-104 N true on
    # the wrist (the guard stopped it at 61-65 N sensed; under harsh, hard-chain8-s36004 seed 36101: 56 N). Sent back
    # to where the pads are and pressed on at press_speed, the latch is read at ~30 N true.
    with _closed_against_its_locker(["door", locker], LATE_READING) as (session, robot, _, _, held):
        assert held.outcome == "blocked" and held.cause is Cause.LOCKED_PUSHED, held
        assert robot.peak <= 35.0, robot.peak  # a margin under 45 N: another pose may meet a stiffer arm
        assert list(session.component_states()) == [1, 1]


@pytest.mark.parametrize("stands_at", [25.0, 40.0, None], ids=["held at 25 deg", "held at 40 deg", "free at 30 deg"])
def test_a_door_pushed_on_from_part_way_where_it_is_held_stops_at_a_light_force(stands_at):
    # a pinch that loses a locked door at its lock's wall (~27 %) leaves it standing still there, and the push on from
    # where it stands met a face that does not give: at the usual pace the true load rose 19, 26, 32, 47 N in four
    # ticks before the filtered reading showed 19 N (paper-test-1 seed 87038, realistic; 45-46 N each of three tries).
    # Here a door held where it stands (it jams at every move), under the harsh profile's late reading: 42 N at 25 deg,
    # 46 N at 40 deg at the usual pace and ``blocked_force``; closed in on and pushed at ``part_way_pace`` and read
    # jammed at ``jam_force``, 30 and 23 N. A free door pushed on from there still goes to its stop.
    held = stands_at is not None
    with _door_standing_at(math.radians(stands_at or 30.0), sticky=held) as (session, robot, world, marker, angle):
        seen = world._fraction_open(marker)
        assert seen is not None and seen > world.toggler.config.judgement.blocked_progress, seen
        robot.peak = 0.0  # (the look is not the push)
        result = world.toggler.toggle(world.joint_models[marker], opening=True, door_at=seen)
        if held:
            assert (result.outcome, result.cause) == ("failed", Cause.JAMMED), result
            assert robot.peak < 35.0, robot.peak_during
        else:
            # (not read jammed; its end stop is met with 44 N true here, 50 N under the late reading, as before)
            assert result.outcome == "moved" and math.degrees(session.data.qpos[angle]) > 83.0, result
