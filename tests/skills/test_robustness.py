"""The pipeline where it was not tuned: failures are not locks, force is capped, boxes away from the
overview camera are found and solved, and the goal state of the spec is honoured."""

import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from world_fixtures import TrueForceWatch, twin_world

from puzzlebox.learning import OracleAgent, run_episode
from puzzlebox.models import Goal, Robot
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.generator import generate_chain, paper_family
from puzzlebox.models.placement import placed
from puzzlebox.models.scene import SceneConfig
from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills import MarkerDetector, joint_model, lid_height, select_markers, upright_pose
from puzzlebox.skills.primitives import PrimitiveConfig, Toggler
from puzzlebox.skills.robot_world import RobotWorld
from puzzlebox.twin.errors import CommandError
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.reality import ArmReality, ForceTorqueReality, PhysicsReality, RealityProfile
from puzzlebox.twin.session import TwinConfig, TwinSession


def _joint_models(session: TwinSession, kinds: dict[int, str] | None = None) -> dict:
    spec = session.spec
    calibration = nominal_calibration(session).camera("overview")
    seen = MarkerDetector().detect(session.robot.capture("overview"), calibration)
    detections = select_markers(seen, {c.marker for c in spec.components}, ("overview",))
    height = lid_height(detections)
    kinds = kinds or {}
    return {
        c.name: joint_model(kinds.get(c.marker, c.kind), upright_pose(detections[c.marker].planar_pose, height))
        for c in spec.components
    }


def test_the_twin_robot_keeps_the_robot_protocols_promises():
    """Driven through the protocol's methods alone, the twin's robot does what ``models.robot`` promises: readings
    in their units and ranges, time that advances by exactly what ``wait`` lets pass, a joint command that is
    reached and turns the reported TCP about the base axis, a gripper that closes and opens, the gripper's weight
    on the wrist until a tare, and frames of each camera's calibrated size showing the box where it stands."""
    spec = generate_chain(["slide", "door"], seed=0)
    with TwinSession(spec, seed=0) as session:
        robot: Robot = session.robot
        calibration = nominal_calibration(session)
        assert isinstance(robot, Robot)
        # readings: seven joints within their (7, 2) limits [rad], at rest, gripper open
        limits, q = robot.joint_limits(), robot.joint_positions()
        assert limits.shape == (7, 2) and np.all(limits[:, 0] < limits[:, 1])
        assert q.shape == (7,) and np.all((limits[:, 0] <= q) & (q <= limits[:, 1]))
        np.testing.assert_allclose(robot.joint_velocities(), np.zeros(7), atol=1e-6)
        assert robot.gripper_opening() == pytest.approx(0.0, abs=0.01)
        # poses: a rigid TCP pose and a rotation for the F/T frame; untared, the wrist carries the gripper's weight,
        # 7.37 N straight down in the base frame; a tare zeroes it
        T = robot.tcp_pose_in_base()
        assert T.shape == (4, 4) and T[3].tolist() == [0.0, 0.0, 0.0, 1.0]
        for R in (T[:3, :3], robot.ft_rotation_in_base()):
            np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-9)
            assert np.linalg.det(R) == pytest.approx(1.0)
        assert 0.0 < T[2, 3] < 1.0  # above the table, within the arm's reach [m]
        wrench = robot.wrench()
        assert wrench.shape == (6,)
        np.testing.assert_allclose(robot.ft_rotation_in_base() @ wrench[:3], [0.0, 0.0, -7.37], atol=0.05)
        robot.tare()
        np.testing.assert_allclose(robot.wrench(), np.zeros(6), atol=1e-6)
        # cameras: a frame of the calibrated size, stamped with the robot's time, in which the box's markers are
        # found where the spec puts them
        for camera in robot.camera_names:
            frame = robot.capture(camera)
            width, height = calibration.camera(camera).image_size
            assert frame.camera == camera and frame.time == robot.time
            assert frame.rgb.shape == (height, width, 3) and frame.rgb.dtype == np.uint8
        seen = MarkerDetector().detect(robot.capture("overview"), calibration.camera("overview"))
        truth = {c.marker: pose for c, pose in zip(spec.components, spec.poses_in_world(), strict=True)}
        assert sorted(d.marker_id for d in seen) == sorted(truth)
        for d in seen:
            assert np.linalg.norm(d.T_base_marker[:2, 3] - truth[d.marker_id][:2]) < 0.005
        # wait lets exactly that much robot time pass; a joint command is reached, joint 1 turning the TCP about
        # the base's vertical axis by its own angle, at the same radius and height; meanwhile the velocities are
        # the rate of change of the positions [rad/s]
        start = robot.time
        target = q + np.array([0.2, 0, 0, 0, 0, 0, 0])
        robot.command_joint_positions(target)
        robot.wait(0.1)
        assert robot.time == pytest.approx(start + 0.1)
        q_a, v_a = robot.joint_positions(), robot.joint_velocities()
        robot.wait(0.01)
        q_b, v_b = robot.joint_positions(), robot.joint_velocities()
        assert v_a[0] > 0.1
        np.testing.assert_allclose((q_b - q_a) / 0.01, (v_a + v_b) / 2, rtol=0.05, atol=0.01)
        robot.wait(1.39)
        assert robot.time == pytest.approx(start + 1.5)
        np.testing.assert_allclose(robot.joint_positions(), target, atol=1e-3)
        T_turned = robot.tcp_pose_in_base()
        turn = np.arctan2(T_turned[1, 3], T_turned[0, 3]) - np.arctan2(T[1, 3], T[0, 3])
        assert turn == pytest.approx(0.2, abs=1e-3)
        assert np.hypot(*T_turned[:2, 3]) == pytest.approx(np.hypot(*T[:2, 3]), abs=1e-4)
        assert T_turned[2, 3] == pytest.approx(T[2, 3], abs=1e-4)
        assert robot.capture("overview").time == robot.time  # a later frame, a later stamp
        # a refused command (out of range) moves nothing
        with pytest.raises(CommandError):
            robot.command_joint_positions(limits[:, 1] + 0.5)
        robot.wait(0.5)
        np.testing.assert_allclose(robot.joint_positions(), target, atol=1e-3)
        # the gripper closes (on nothing: all the way) and opens again
        robot.command_gripper(1.0)
        robot.wait(1.0)
        assert robot.gripper_opening() > 0.9
        robot.command_gripper(0.0)
        robot.wait(1.0)
        assert robot.gripper_opening() < 0.1


def test_a_grasp_that_closes_on_nothing_is_failed_not_blocked():
    spec = generate_chain(["slide", "door"], seed=2)
    with TwinSession(spec, seed=0) as session:
        jm = _joint_models(session)[spec.components[0].name]
        off = replace(jm, grasp_point=jm.grasp_point + np.array([0.0, 0.0, 0.03]), origin=jm.origin + (0, 0, 0.03))
        result = Toggler(session.robot).toggle(off)
        assert result.outcome == "failed" and result.cause is Cause.GRASP_EMPTY, result.reason
        assert session.component_states()[0] == 0


def test_a_toggle_with_the_wrong_kind_is_stopped_below_the_force_limit():
    """A slide perceived as a wheel is pulled along an arc it cannot follow: the try must end (blocked or
    failed), the part must not be forced, and the filtered wrist force must stay under the limit."""
    spec = generate_chain(["slide", "door"], seed=2)
    limit = PrimitiveConfig().sensing.force_limit
    with TwinSession(spec, seed=0) as session:
        slide = spec.components[0]
        jm = _joint_models(session, {slide.marker: "wheel"})[slide.name]
        result = Toggler(session.robot).toggle(jm)
        assert result.outcome in ("blocked", "failed")
        assert max(result.forces, default=0.0) < limit + 5.0


def test_a_cautious_descent_meets_a_part_in_its_way_at_a_light_touch():
    """A pad landing on the top of a handle post (the fingers 23 mm off along their closing axis): a cautious
    descent (beside a door that may stand open) stops at ``cautious_contact_force`` with the true force well under
    the 60 N limit, and so does a normal one, whose last ``touch_height`` runs at ``touch_speed`` (at its full pace
    the guard stopped it at the limit, the true force past it)."""
    spec = generate_chain(["slide", "door"], seed=2)
    true_peak, reasons = {}, {}
    for cautious in (False, True):
        with TwinSession(spec, seed=0) as session:
            jm = _joint_models(session)[spec.components[0].name]
            shift = 0.023 * jm.motion_direction(0.0)  # the slide's fingers close along its motion
            on_post = replace(jm, grasp_point=jm.grasp_point + shift, origin=jm.origin + shift)
            watch = TrueForceWatch(session.robot, session)
            result = Toggler(watch).toggle(on_post, cautious=cautious)
            assert result.cause is Cause.FORCE_LIMIT and result.stopped_while == "descending", result.reason
            assert session.component_states()[0] == 0
            true_peak[cautious], reasons[cautious] = watch.peak, result.reason
    config = PrimitiveConfig()
    for cautious in (False, True):
        assert f"> {config.approach.cautious_contact_force:.0f} N" in reasons[cautious]
        assert true_peak[cautious] < config.approach.cautious_contact_force + 15.0 < config.sensing.force_limit


@pytest.mark.parametrize("seed", [0, 1])
def test_a_cautious_descent_is_not_stopped_by_sensor_noise(seed):
    """At 7 N of F/T force noise the 15 N stop of a cautious descent is passed by noise alone (both seeds here
    stop with nothing in the way when it is fixed); the stop rises with the noise measured as the arm comes to
    rest above the part, and the free part is moved."""
    noisy = RealityProfile(name="noisy-ft", force_torque=ForceTorqueReality(force_noise=7.0))
    spec = generate_chain(["slide", "door"], seed=2)
    fixed = PrimitiveConfig.of(cautious_noise_margin=0.0, tare_noise=1e9)  # and a ten-reading tare
    for config, outcome in ((PrimitiveConfig(), "moved"), (fixed, "failed")):
        with TwinSession(spec, seed=seed, reality=noisy) as session:
            jm = _joint_models(session)[spec.components[0].name]
            toggler = Toggler(session.robot, config)
            result = toggler.toggle(jm, cautious=True)
            assert result.outcome == outcome, result
            assert toggler.watch.noise() == pytest.approx(7.0, rel=0.2)


@pytest.mark.parametrize("seed", [4, 6])
def test_at_15_n_of_sensor_noise_a_latched_part_reads_blocked_and_a_free_one_moved(seed):
    """At 15 N of F/T force noise (rms per axis) a 5-tick median and a 10-reading tare read a free slide latched
    (both seeds here; 2 of seeds 0-7, 4 before the descents' last ``touch_height`` ran slowly); a filter and a tare
    sized to the noise measured above the part read both parts right (all 8)."""
    noisy = RealityProfile(name="noisy-ft", force_torque=ForceTorqueReality(force_noise=15.0))
    spec = generate_chain(["slide", "door"], seed=2)  # the door is latched until the slide is open
    fixed = PrimitiveConfig.of(filtered_noise=1e9, tare_noise=1e9)
    for config, slide_outcome in ((PrimitiveConfig(), "moved"), (fixed, "blocked")):
        with TwinSession(spec, seed=seed, reality=noisy) as session:
            slide, door = (_joint_models(session)[c.name] for c in spec.components)
            toggler = Toggler(session.robot, config)
            assert toggler.toggle(door).outcome == "blocked"
            assert toggler.toggle(slide).outcome == slide_outcome
            assert session.component_states().tolist() == [int(slide_outcome == "moved"), 0]
    toggler = Toggler(session.robot)
    assert (toggler.watch.filter_samples(15.0), toggler.watch.tare_samples(15.0)) == (23, 225)
    assert (toggler.watch.filter_samples(0.3), toggler.watch.tare_samples(0.3)) == (5, 10)  # the realistic sensor's


def test_a_box_far_from_the_overview_camera_is_found_and_solved_end_to_end():
    spec = paper_family("test")[1]
    spec = replace(spec, box=replace(spec.box, pose=(0.3083, 0.1521, 0.2397)))  # corner of the workspace
    with TwinSession(spec, seed=1) as session:
        world = twin_world(session, seed=1)
        truth = spec.poses_in_world()
        for marker, seen in zip(world.markers, world.observe().components, strict=True):
            index = next(i for i, c in enumerate(spec.components) if c.marker == marker)
            assert np.linalg.norm(seen.pose_in_world[:2] - truth[index, :2]) < 0.005
        assert len(world.seen_by_overview) < len(spec.components), "the overview should miss part of this box"
        result = run_episode(OracleAgent(spec), world, spec.name, 1, max_actions=10)
        assert result.solved
        assert all(a.moved == a.true_moved for a in world.log)


def test_the_twin_world_honours_the_specs_goal_state():
    spec = generate_chain(["slide", "door"], seed=1)
    spec = replace(spec, goal=Goal(spec.goal.component, 0))  # every part starts closed: solved at once
    with TwinSession(spec, seed=0) as session:
        observation = twin_world(session).observe()
        assert observation.goal_state == 0 and observation.solved


ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def realistic_calibration(tmp_path_factory) -> CellCalibration:
    """The cell calibration ``scripts/calibrate.py`` makes for the ``realistic`` profile (cell seed 0)."""
    out = tmp_path_factory.mktemp("calibration") / "realistic.json"
    command = [sys.executable, str(ROOT / "scripts/calibrate.py"), "--out", str(out), "--reality", "realistic"]
    result = subprocess.run(command, capture_output=True, text=True, cwd=ROOT)
    assert result.returncode == 0, result.stderr
    return CellCalibration.load(out)


@pytest.mark.parametrize(("variant", "seed"), [(2, 100), (0, 7), (1, 11)])
def test_a_calibrated_realistic_cell_perceives_boxes_at_new_placements_within_5_mm(
    realistic_calibration, variant, seed
):
    """Noise, distortion, mounting and TCP errors, the box anywhere reachable: every marker within 5 mm.
    (Seed 100 puts paper-test-2 where the overview sees one marker obliquely, a corner hidden by its
    handle, and posed it 19 mm off before overview poses were checked against the lid's plane.)"""
    spec = paper_family("test")[variant]
    with TwinSession(spec, seed=seed, reality="realistic") as session:
        spec = session.spec  # placed by the profile
        world = RobotWorld(
            session.robot,
            realistic_calibration,
            {c.marker: c.kind for c in spec.components},
            spec.components[spec.index_of(spec.goal.component)].marker,
        )
        for c in spec.components:
            truth = session.data.site(session.scene.names.components[c.name].frame_site).xpos
            error = np.linalg.norm(world.closed_poses[c.marker][:2] - truth[:2])
            assert error < 0.005, f"{c.name} at box pose {session.box_pose}: {1000 * error:.1f} mm"


def test_an_opened_door_stands_at_its_full_travel_clear_of_its_neighbours_handle():
    """At this placement the door's handle lags the fingers by ~15 mm along the arc: driven only to the
    nominal travel the door stopped at 74 deg, leaning over the slide beside it, and the next descent onto
    the slide's handle hit the door (100 N). Over-travel to the end stop leaves it at 85 deg."""
    spec = placed(paper_family("test", seed=0)[1], (0.410, -0.107, -0.740))
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session)
        names = [c.name for c in spec.components]
        for name in ("slide-0", "wheel-1", "slide-2", "door-3", "slide-4"):  # the solution, in order
            result = world.try_toggle(world.markers.index(spec.components[names.index(name)].marker))
            assert result.outcome == "moved", (name, result)
            if name == "door-3":
                door = session.component_qpos[names.index("door-3")]
                assert np.degrees(session.data.qpos[door]) > 83.0
        assert session.component_states().tolist() == [1, 1, 1, 1, 1]


WEAK_GRIP = RealityProfile(name="weak-grip", physics=PhysicsReality(pad_friction=0.25, grip_force_scale=1 / 3))
"""The harsh profile's gripper alone: 10 N of grip on pads of mu 0.25."""


def test_a_latched_door_under_a_weak_grip_is_never_read_as_moved():
    """With a weak grip (10 N, pad mu 0.25: harsh) a latched door's handle slides up out of the pads with
    hardly any force: the fingers travelled the arc, the door did not (this read "moved"). The slip is seen
    from the gripper or from the marker that did not move; the try is failed (no evidence) or blocked."""
    spec = placed(paper_family("test", seed=0)[1], (0.331, 0.222, 2.574))  # where it was seen, realistic seed 1006
    with TwinSession(spec, seed=0, reality=WEAK_GRIP) as session:
        world = twin_world(session)
        door = spec.components[spec.index_of("door-3")]  # locked closed while slide-2 is closed
        result = world.try_toggle(world.markers.index(door.marker))
        assert result.cause is not None and result.cause.family in ("slipped", "locked"), result
        assert world.log[-1].true_moved is False and world.states.tolist() == [0] * 5


def test_a_door_whose_handle_slips_out_of_the_pads_is_pushed_open_and_shut():
    """A pinched handle moves its door by pad friction alone. With almost none (pad mu 0.1 at a third of the
    grip) the handle slips out; the primitive then pushes the door in the same attempt: open to its end stop
    under a pad on the back of the handle. Closing, a pinch that cannot hold the handle (here it first hit
    the force limit, then closed on nothing where the door no longer was) is followed by a push of the pads'
    edges on the plate, which lays the door flat."""
    slippery = RealityProfile(name="slippery", physics=PhysicsReality(pad_friction=0.1, grip_force_scale=1 / 3))
    spec = placed(paper_family("test", seed=0)[0], (0.45, -0.15, 2.2))
    with TwinSession(spec, seed=0, reality=slippery) as session:
        world = twin_world(session)
        door = spec.index_of("door-0")
        index = world.markers.index(spec.components[door].marker)
        angle = session.component_qpos[door]
        assert world.try_toggle(index).outcome == "moved"
        assert np.degrees(session.data.qpos[angle]) > 83.0 and world.log[-1].attempts == 1
        assert world.try_toggle(index).outcome == "moved"
        assert np.degrees(session.data.qpos[angle]) < 3.0
        assert session.component_states()[door] == 0


def test_closing_on_a_handle_puts_no_impact_on_the_wrist():
    """The pads meet a wheel's post a few millimetres off their centre here; snapped shut by the servo
    they hit it with a 30 ms, 62 N true wrist force (past the 60 N safety limit, too short for the
    filtered guard to see). Closed at a ramped command (0.4 closure/s), it is ~30 N."""
    spec = paper_family("test", seed=0)[1]
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session)
        m, d = session.model, session.data
        site = m.site(session.scene.names.ft_site).id
        weight = m.body_subtreemass[m.site_bodyid[site]] * m.opt.gravity
        peak = {"grasping": 0.0}
        wait = session.robot.wait

        def watched_wait(seconds: float) -> None:
            wait(seconds)
            if world.toggler.phase == "grasping":
                true_force = d.site_xmat[site].reshape(3, 3) @ session.ft.load()[:3] - weight
                peak["grasping"] = max(peak["grasping"], float(np.linalg.norm(true_force)))

        session.robot.wait = watched_wait
        for name in ("slide-0", "wheel-1"):
            result = world.try_toggle(world.markers.index(spec.components[spec.index_of(name)].marker))
            assert result.outcome == "moved", (name, result)
        assert 5.0 < peak["grasping"] < 35.0, peak


def test_a_door_left_part_way_open_is_pushed_on_from_where_it_stands():
    """A try that lost its hold on a door part-way leaves it raised: its handle is no longer where a pinch
    descends (the grasp closes on nothing), and a push placed behind the closed handle lands on the raised
    post (60-100 N). The door is looked at from over its hinge (``RobotWorld`` does before a retry) and pushed
    on from the angle seen."""
    spec = placed(paper_family("test", seed=0)[0], (0.45, -0.15, 2.2))
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session)
        door = spec.index_of("door-0")
        angle = session.component_qpos[door]
        session.data.qpos[angle] = np.radians(40.0)  # where a slipping pinch left it
        session.robot.wait(1.0)
        assert 30.0 < np.degrees(session.data.qpos[angle]) < 45.0  # it stays raised on its own
        capture, at_capture = session.robot.capture, []

        def capture_noting_the_door(camera: str):
            at_capture.append(np.degrees(session.data.qpos[angle]))  # it sinks slowly meanwhile
            return capture(camera)

        session.robot.capture = capture_noting_the_door
        seen = world._fraction_open(spec.components[door].marker)
        session.robot.capture = capture
        assert seen * 85.0 == pytest.approx(at_capture[-1], abs=1.0)
        marker = spec.components[door].marker
        result = world.toggler.toggle(world.joint_models[marker], opening=True, door_at=seen)  # as a retry does
        assert result.outcome == "moved" and np.degrees(session.data.qpos[angle]) > 83.0
        assert result.peak_force < PrimitiveConfig().sensing.force_limit


@pytest.mark.parametrize("degrees", [72.0, 50.0])
def test_a_door_left_short_of_its_end_stop_is_pushed_into_it_under_its_plate(degrees):
    """A door let go short of its 85 deg stop sinks under its own weight over its neighbour (78 -> 66 deg in
    45 s under the harsh grip), where the next descent lands on it. Where it stands is not seen (its handle hides
    its marker), so the pads come in under the plate from outside its reach and turn it into its stop. At 50
    deg, the lowest it is placed for, the plate's free edge stands just above the pads' entry height: they
    meet it side-on, diving under it (at their entry height they pressed a door at 47 deg down to 43 deg, and
    under the harsh profile one at 49 deg on its end face, along the plate into the hinge, at 90 N)."""
    spec = placed(paper_family("test", seed=0)[0], (0.38, 0.12, -0.9))  # not the placement of the tests above
    with TwinSession(spec, seed=0) as session:
        world = twin_world(session)
        door = spec.index_of("door-0")
        angle = session.component_qpos[door]
        session.data.qpos[angle] = np.radians(degrees)
        session.robot.wait(0.5)
        assert np.degrees(session.data.qpos[angle]) < degrees + 3.0
        marker = spec.components[door].marker
        result = world.toggler.toggle(world.joint_models[marker], opening=True, raised=True)
        assert result.outcome == "moved" and np.degrees(session.data.qpos[angle]) > 83.0
        assert result.peak_force < PrimitiveConfig().sensing.force_limit


def test_a_door_held_open_is_pushed_shut_in_vain_under_the_force_limit():
    """A door that jams as soon as it moves (a sticky hinge, every try), pushed shut by the pads' edges on its
    plate, with the F/T reading 30 ms late and commands 10 ms late: the push ends blocked or failed, the door
    where it stood, the true wrist force under the limit (~30 N here)."""
    sticky = RealityProfile(
        name="sticky-and-late",
        force_torque=ForceTorqueReality(rate_hz=100.0, delay=0.030),
        arm=ArmReality(command_latency=0.010),
        physics=PhysicsReality(jam_probability=1.0),
    )
    spec = placed(paper_family("test", seed=0)[0], (0.45, -0.15, 2.2))
    with TwinSession(spec, seed=0, reality=sticky) as session:
        world = twin_world(session)
        door = spec.index_of("door-0")
        angle = session.component_qpos[door]
        session.data.qpos[angle] = np.radians(84.0)
        session.robot.wait(1.0)  # (the jam this move started is released half a second after it)
        watch = TrueForceWatch(session.robot, session)
        world.toggler.robot = watch
        result = world.toggler.toggle(world.joint_models[spec.components[door].marker], opening=False)
        assert result.outcome in ("blocked", "failed") and np.degrees(session.data.qpos[angle]) > 75.0, result
        assert watch.peak < PrimitiveConfig().sensing.force_limit, watch.peak_during


class _ArcForceWatch(TrueForceWatch):
    """The true wrist force's peak while a door is still short of ``below`` degrees (its arc, not its end stop)."""

    def __init__(self, robot, session: TwinSession, door: int, below: float) -> None:
        super().__init__(robot, session)
        self._angle, self._below = session.component_qpos[door], below

    def wait(self, seconds: float) -> None:
        if np.degrees(self._session.data.qpos[self._angle]) < self._below:
            super().wait(seconds)
        else:
            self._robot.wait(seconds)


def test_a_door_arc_planned_from_a_wrong_hinge_yields_to_the_load_across_it():
    """A door whose hinge is perceived 15 mm too close to its handle is pulled along an arc that drags the handle
    across its true one: yielding to the load across the path opens it with well under the true wrist force of the
    rigid path along the arc (up to 60 deg: measured 21 N against 36 N; past the travel the path returns to the
    plan, to feel the end stop)."""
    spec = placed(paper_family("test", seed=0)[0], (0.45, -0.15, 2.2))
    late = RealityProfile(
        name="late", force_torque=ForceTorqueReality(rate_hz=100.0, delay=0.030), arm=ArmReality(command_latency=0.010)
    )
    results = {}
    for gain in (PrimitiveConfig().motion.comply_gain, 0.0):
        with TwinSession(spec, seed=0, reality=late) as session:
            world = twin_world(session)
            door = spec.index_of("door-0")
            jm = world.joint_models[spec.components[door].marker]
            radius = (jm.grasp_point - jm.origin) - np.dot(jm.grasp_point - jm.origin, jm.axis) * jm.axis
            jm = replace(jm, origin=jm.origin + 0.015 * radius / np.linalg.norm(radius))
            watch = _ArcForceWatch(session.robot, session, door, below=60.0)
            world.toggler.robot = watch
            world.toggler.config = world.toggler.config.changed(comply_gain=gain)
            result = world.toggler.toggle(jm, opening=True)
            results[gain] = (result.outcome, np.degrees(session.data.qpos[session.component_qpos[door]]), watch.peak)
    (yielding, rigid) = results.values()
    assert yielding[0] == rigid[0] == "moved", results
    assert yielding[2] < 0.75 * rigid[2], results


LATCHED_OPEN = TwinConfig(scene=SceneConfig(locks="latch"))
"""A latch holds a door rigidly where it stands (the worst case, as a door jammed open)."""


def test_the_lift_off_a_handle_steps_around_an_open_door_standing_over_it():
    """paper-train-0 at one reachable placement: opening slide-3 brings the open gripper under the post of door-0,
    which stands open past vertical over it (balanced on its hinge, it stays at its stop under the pad). Lifted at
    full pace the pad met the post with ~80 N true before the filtered reading stopped it; lifted slowly at first,
    stopped at a light touch and stepped sideways along the pads, the toggle ends well under the force limit. (The
    gripper upright, as the toggle is called here: the world leans it away from the door and meets no post.)"""
    spec = placed(paper_family("train")[0], (0.432, 0.2434, 2.0084))
    limit = PrimitiveConfig().sensing.force_limit
    peaks = {}
    full_pace = PrimitiveConfig.of(lift_slow_height=0.0, lift_contact_force=59.0)
    for name, config in (("guarded", PrimitiveConfig()), ("full pace", full_pace)):
        with TwinSession(spec, seed=0) as session:
            world = twin_world(session)
            watch = TrueForceWatch(session.robot, session)
            world.toggler.robot, world.toggler.config = watch, config
            for component in ("door-0", "slide-1", "door-2", "slide-3"):
                watch.peak = 0.0
                marker = spec.components[spec.index_of(component)].marker
                result = world.toggler.toggle(world.joint_models[marker], opening=True)
                assert result.outcome == "moved", (name, component, result)
            peaks[name] = watch.peak  # slide-3's toggle: approach, grasp, pull, let go, lift
    assert peaks["guarded"] < limit < peaks["full pace"], peaks


def test_a_slide_opening_under_an_open_doors_post_is_grasped_leaning_away_from_it():
    """paper-train-0 at another reachable placement: door-0, open at its stop, reaches its post out over slide-3,
    which opens along door-0's hinge line, held rigidly at its stop by a latch. Upright, the gripper's knuckles run
    into the post as the slide moves: the post stops the slide at 14 % of its travel and the try reads it held
    part-way, a false blocked (before doors were balanced, 51 N and moved; under the realistic profile 61 N and the
    force stop, every try); leaning away from the door about its closing axis, the gripper passes it and the slide
    opens with the pads' own load alone."""
    spec = placed(paper_family("train")[0], (0.3785, -0.0679, 1.7884))
    peaks = {}
    for name, config in (("leaning", PrimitiveConfig()), ("upright", PrimitiveConfig.of(lean_angle=0.0))):
        with TwinSession(spec, seed=0, config=LATCHED_OPEN) as session:
            world = twin_world(session)
            watch = TrueForceWatch(session.robot, session)
            world.toggler.robot, world.toggler.config = watch, config
            names = [world.ground_truth_name(k) for k in range(len(world.markers))]
            for component in ("door-0", "slide-1", "door-2", "slide-3"):
                watch.peak = 0.0
                result = world.try_toggle(names.index(component))
                assert result.moved or (name, component) == ("upright", "slide-3"), (name, component, result)
            peaks[name] = (result.moved, watch.peak)  # slide-3's try
    assert peaks["leaning"][0] and peaks["leaning"][1] < 20.0, peaks
    assert not peaks["upright"][0] or peaks["upright"][1] > 40.0, peaks  # upright, the post holds it or is struck
