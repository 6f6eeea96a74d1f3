"""The toggle primitive opens free parts of each kind and feels latched ones through the wrist F/T
sensor; unreachable and non-finite IK targets are typed failures."""

import dataclasses
import json
from pathlib import Path

import mujoco
import numpy as np
import pytest
from dm_control import mjcf
from world_fixtures import TrueForceWatch

from puzzlebox.models.generator import generate_chain
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.lock_check import HELD_FRACTION
from puzzlebox.models.lock_mechanisms import IN_STATE
from puzzlebox.models.try_outcome import Cause
from puzzlebox.models.xarm7 import HOME_QPOS, build_xarm7
from puzzlebox.skills import MarkerDetector, joint_model, lid_height, select_markers, upright_pose
from puzzlebox.skills.errors import ConfigError, IKFailure
from puzzlebox.skills.kinematics import ArmKinematics, top_down
from puzzlebox.skills.pinch import TryArgs
from puzzlebox.skills.primitives import PrimitiveConfig, Toggler
from puzzlebox.skills.settings import DOOR_PARTS, PHASES
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.session import TwinSession


def perceived_joint_models(session: TwinSession) -> dict:
    spec = session.spec
    image = session.robot.capture("overview")
    detections = select_markers(
        MarkerDetector().detect(image, nominal_calibration(session).camera("overview")),
        {c.marker for c in spec.components},
        ("overview",),
    )
    height = lid_height(detections)
    return {
        c.name: joint_model(c.kind, upright_pose(detections[c.marker].planar_pose, height)) for c in spec.components
    }


@pytest.fixture(scope="module")
def chain():
    # slide-0 free; door-1 held by slide-0; slide-2 held by door-1; wheel-3 held by slide-2
    with TwinSession(generate_chain(["slide", "door", "slide", "wheel"], seed=1), seed=0) as session:
        yield session, perceived_joint_models(session)


@pytest.mark.parametrize("name", ["door-1", "slide-2", "wheel-3"])
def test_a_latched_part_of_each_kind_is_reported_blocked_and_stays_put(chain, name):
    session, models = chain
    session.reset()
    j = session.spec.index_of(name)
    before = session.component_positions()[j]
    result = Toggler(session.robot).toggle(models[name])
    assert result.outcome == "blocked", result.reason
    # an interlock holds a closed part once it has left its closed band (anywhere in it the part must leave its
    # locker free), short of half its travel: held part-way, and taken back to where it was grasped
    assert result.peak_opposing_force > 5.0 and IN_STATE - 0.05 < result.progress < HELD_FRACTION
    assert result.cause is Cause.HELD_PART_WAY
    assert session.component_states()[j] == 0
    assert abs(session.component_positions()[j] - before) < 0.02  # the lock held against the pull, the part back
    assert session.robot.gripper_opening() <= PrimitiveConfig().approach.pregrasp_closure + 0.05  # and the robot let go


def test_a_locked_door_pushed_from_closed_is_held_part_way_where_its_lock_stops_it(chain):
    """A pad pushing a locked door's handle carries it until the lock's rod meets its wall, past the closed band;
    there the door stops while the pad slides up its face: held part-way (a lock), not a push that fell short
    (before, the pad slid over the post and the try read ``IncompleteTravel``, and was tried again and again)."""
    session, models = chain
    session.reset()
    j = session.spec.index_of("door-1")
    travel = get_kind("door").travel
    watch = TrueForceWatch(session.robot, session)
    result = Toggler(watch).toggle(models["door-1"], push=True)
    assert result.outcome == "blocked" and result.cause is Cause.HELD_PART_WAY, result.reason
    assert session.component_states()[j] == 0  # the truth: not open
    assert watch.peak < 45.0
    met = result.held_at  # where the face stood still, of the travel
    assert met is not None and result.reason == f"latched: held part-way ({met:.0%} of the travel)"
    assert (
        PrimitiveConfig().judgement.blocked_progress < met < HELD_FRACTION
    )  # carried, then held short of half its travel
    # the door stands where it was read held: the face's turn since the pad first pressed on it, measured about the
    # hinge as perceived (the marker's pose, millimetres off), reads ~85 % of the door's own turn here (23 % for 27 %)
    assert abs(session.component_positions()[j] / travel - met) < 0.05


def test_a_blocked_try_is_felt_against_a_mechanism_not_a_latch(chain):
    # the default box locks by contact: the wrist meets the slide's pin through the door's wall, no constraint
    session, models = chain
    session.reset()
    result = Toggler(session.robot).toggle(models["door-1"])
    assert result.outcome == "blocked", result.reason
    assert not session.data.eq_active[session.latches.eq_ids].any()
    assert session.latches.table.locker.size == 0  # every rule of this chain is a mechanism
    assert result.peak_opposing_force > 5.0  # felt through the F/T
    assert session.component_states()[session.spec.index_of("door-1")] == 0


def test_a_free_slide_then_the_door_it_released_are_opened(chain):
    session, models = chain
    session.reset()
    toggler = Toggler(session.robot)
    slide = toggler.toggle(models["slide-0"])
    assert slide.outcome == "moved" and session.component_states()[0] == 1
    door = toggler.toggle(models["door-1"])
    assert door.outcome == "moved", door.reason
    assert session.component_states()[1] == 1
    # a slow descent (its last touch_height at touch_speed), the over-travel into the end stop, a return through the
    # transit (< 21 s), and a top-up push when the over-travel, yielding across its arc, did not feel the stop
    assert 5.0 < door.sim_time < (45.0 if not door.end_stop_felt else 21.0)


@pytest.mark.parametrize("seed", [0, 1])
def test_a_free_door_opened_then_closed_by_a_push_is_read_closed_both_ways(seed):
    """Pushed over its top, a door falls shut under its own weight ahead of the pads, which first press on it
    on the lid: closed, not latched (read "latched: pushed without progress" on every seed here before), and
    met there gently (the pads stop as the plate is felt on the lid)."""
    spec = generate_chain(["door", "slide"], seed=seed)
    with TwinSession(spec, seed=0) as session:
        door = perceived_joint_models(session)["door-0"]
        watch = TrueForceWatch(session.robot, session)
        toggler = Toggler(watch)
        assert toggler.toggle(door).outcome == "moved" and session.component_states()[0] == 1
        watch.peak = 0.0
        closing = toggler.toggle(door, opening=False)
        assert closing.outcome == "moved", closing.reason
        assert session.component_states()[0] == 0
        assert watch.peak < 45.0


def test_a_free_wheel_is_turned_open():
    with TwinSession(generate_chain(["wheel", "slide"], seed=2), seed=0) as session:
        result = Toggler(session.robot).toggle(perceived_joint_models(session)["wheel-0"])
        assert result.outcome == "moved", result.reason
        assert session.component_states()[0] == 1


def test_an_out_of_reach_target_is_a_typed_ik_failure():
    ik = ArmKinematics()
    with pytest.raises(IKFailure, match="out of reach"):
        ik.solve(top_down(np.array([1.2, 0.0, 0.1]), 0.0))
    with pytest.raises(IKFailure, match="not finite"):
        ik.step_towards(np.full((4, 4), np.nan))


def test_ik_reaches_targets_over_the_box_to_a_millimetre():
    ik = ArmKinematics()
    for target in ([0.45, 0.0, 0.2], [0.55, 0.15, 0.15], [0.30, -0.15, 0.12], [0.60, 0.0, 0.12]):
        q = ik.solve(top_down(np.array(target), 0.3))
        ik.set_joints(q)
        assert np.linalg.norm(ik.tcp_pose()[:3, 3] - target) < 0.001


class _HeldTCP:
    """A robot whose TCP is held by a spring along base x (fingers closed on a handle that jammed): the
    wrist force is ``stiffness`` times the TCP's displacement from ``neutral`` [N], the servos ideal."""

    def __init__(self, stiffness: float, stretch: float) -> None:
        self.kinematics = ArmKinematics()
        self.q = solve_reachable(self.kinematics)
        self.kinematics.set_joints(self.q)
        self.neutral = self.kinematics.tcp_pose()[0, 3] - stretch
        self.stiffness = stiffness
        self.time = 0.0

    def tcp_pose_in_base(self) -> np.ndarray:
        self.kinematics.set_joints(self.q)
        return self.kinematics.tcp_pose()

    def wrench(self) -> np.ndarray:  # the spring pulls the TCP back towards neutral
        return np.array([-self.stiffness * (self.tcp_pose_in_base()[0, 3] - self.neutral), 0, 0, 0, 0, 0])

    def ft_rotation_in_base(self) -> np.ndarray:
        return np.eye(3)

    def joint_positions(self) -> np.ndarray:
        return self.q.copy()

    def joint_limits(self) -> np.ndarray:
        return np.array([[-6.3, 6.3]] * 7)

    def command_joint_positions(self, q: np.ndarray) -> None:
        self.q = np.array(q, dtype=float)

    def wait(self, seconds: float) -> None:
        self.time += seconds


def solve_reachable(kinematics: ArmKinematics) -> np.ndarray:
    return kinematics.solve(top_down(np.array([0.45, 0.0, 0.2]), 0.0))


def test_a_withdrawal_backs_off_a_held_grip_only_until_the_load_is_relieved():
    """Stopped with 60 N on a grip that a jam holds (3 mm of stretch), the arm backs off along the load and
    stops there: carried the whole ``relieve_distance`` (5 mm) it would push the held handle 2 mm the other
    way (-40 N)."""
    robot = _HeldTCP(stiffness=20_000.0, stretch=0.003)
    toggler = Toggler(robot)
    toggler.watch.guard = False  # as in a withdrawal
    for _ in range(toggler.config.sensing.force_filter_samples):
        toggler.watch.sense()
    assert np.linalg.norm(toggler.force_in_base) == pytest.approx(60.0, rel=0.02)
    toggler.motion.relieve()
    load = robot.wrench()[0]
    assert abs(load) < 10.0, load


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("breakaway_pace", 0.0, "breakaway_pace"),
        ("breakaway_pace", 1.5, "breakaway_pace"),
        ("breakaway_fraction", 1.0, "breakaway_fraction"),
        ("comply_gain", -0.001, "comply_gain"),
        ("comply_limit", -0.01, "comply_limit"),
        ("comply_return_time", 0.0, "comply_return_time"),
        ("filtered_noise", 0.0, "filtered_noise"),
        ("tare_noise", -1.0, "tare_noise"),
        ("tare_max_samples", 5, "tare_max_samples"),
        ("force_filter_max_samples", 4, "force_filter_max_samples"),
        ("lift_contact_force", 60.0, "lift_contact_force"),
        ("lift_sidestep", -0.01, "lift_sidestep"),
        ("lift_slow_time", 0.0, "lift_slow_time"),
        ("gentle_release_speed", 0.0, "gentle_release_speed"),
        ("base_rise", -0.01, "base_rise"),
    ],
)
def test_a_config_with_an_impossible_pace_or_yield_is_a_clear_error(field, value, message):
    with pytest.raises(ConfigError, match=message):
        PrimitiveConfig.of(**{field: value})


def test_the_settings_by_phase_keep_every_default_and_name_what_exists():
    """Grouped by phase, every setting keeps its name, type and default (taken from the flat config they replaced,
    tests/skills/data/settings_defaults.json); each is changed by its own name; a wrong name lists the real ones."""
    before = json.loads((Path(__file__).parent / "data" / "settings_defaults.json").read_text())
    assert {k: repr(v) for k, v in PrimitiveConfig().flat().items()} == before
    changed = PrimitiveConfig.of(force_limit=45.0, rest_time=2.0, lean_angle=0.0)
    assert (changed.sensing.force_limit, changed.retreat.rest_time, changed.approach.lean_angle) == (45.0, 2.0, 0.0)
    assert changed.changed(force_limit=60.0).flat() == {**changed.flat(), "force_limit": 60.0}
    door = PrimitiveConfig().push.changed(held_turn=0.1, top_up=False)
    assert (door.judgement.held_turn, door.top_up, door.plan.lead) == (0.1, False, 0.010)
    with pytest.raises(ConfigError, match=r"no setting named \['forse_limit'\].*'force_limit'"):
        PrimitiveConfig.of(forse_limit=45.0)
    for phase in PHASES + DOOR_PARTS:
        assert len(dataclasses.fields(phase)) <= 15, phase


class _FreeTCP(_HeldTCP):
    """A robot with ideal servos and nothing in contact that records its TCP at every command."""

    def __init__(self, tcp: np.ndarray) -> None:
        super().__init__(stiffness=0.0, stretch=0.0)
        self.q = self.kinematics.solve(tcp, self.q)
        self.path: list[np.ndarray] = []

    def command_joint_positions(self, q: np.ndarray) -> None:
        super().command_joint_positions(q)
        self.path.append(self.tcp_pose_in_base()[:3, 3].copy())


@pytest.mark.parametrize("radius", [0.176, 0.30])
def test_a_lift_near_the_base_rises_over_the_post_then_moves_out_before_rising_on(radius):
    """Let go 0.176 m from the base's axis (a drawer pulled towards the robot), the arm is folded over its own
    shoulder: straight up, the gripper's knuckle met link 2 six centimetres up (224 N). The lift first clears the
    35 mm post it straddled, then moves out to ``base_radius``, then rises; farther out it goes straight up."""
    c = PrimitiveConfig()
    azimuth = np.radians(69.7)
    start = np.array([radius * np.cos(azimuth), radius * np.sin(azimuth), 0.108])
    robot = _FreeTCP(top_down(start, 0.5))
    Toggler(robot).retreat.lift_clear(c.approach.approach_height)
    path = np.array(robot.path)
    out = np.hypot(path[:, 0], path[:, 1])
    end = path[-1]
    assert end[2] == pytest.approx(start[2] + c.approach.approach_height, abs=0.003)
    if radius < c.approach.base_radius:
        low = path[:, 2] < start[2] + c.approach.base_rise - 0.003
        assert np.all(out[low] < radius + 0.002)  # not across the post
        high = path[:, 2] > start[2] + c.approach.base_rise + 0.003
        assert np.all(out[high] > c.approach.base_radius - 0.003)  # out before rising on
    else:
        assert np.all(np.abs(out - radius) < 0.002)  # straight up


class _ApproachingArm(_FreeTCP):
    """A :class:`_FreeTCP` handed over at the rest posture, with an ideal gripper and F/T tare, that records its
    joints at every command."""

    def __init__(self) -> None:
        super().__init__(top_down(np.array([0.42, 0.0, 0.35]), 0.0))
        self.q = np.array(HOME_QPOS, dtype=float)
        self.joints: list[np.ndarray] = []

    def command_joint_positions(self, q: np.ndarray) -> None:
        super().command_joint_positions(q)
        self.joints.append(self.q.copy())

    def command_gripper(self, closure: float) -> None:
        pass

    def tare(self, samples: int) -> None:
        pass


def _gripper_clearance_from_the_shoulder(joints: list[np.ndarray]) -> float:
    """Least distance between the gripper's collision geoms and those of the arm's base and links 1-3 over
    ``joints`` (every 5th), the gripper at the pre-grasp closure, in the robot's own model [m]."""
    root = mjcf.RootElement(model="arm")
    root.attach(build_xarm7())
    m = mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())
    d = mujoco.MjData(m)
    body = [m.body(m.geom_bodyid[g]).name for g in range(m.ngeom)]
    live = [g for g in range(m.ngeom) if m.geom_contype[g] or m.geom_conaffinity[g]]
    grip = [g for g in live if "gripper" in body[g]]
    shoulder = [g for g in live if body[g] in ("xarm7/base", "xarm7/link1", "xarm7/link2", "xarm7/link3")]
    arm = np.array([m.joint(f"xarm7/joint{i}").qposadr[0] for i in range(1, 8)])
    fingers = [
        m.jnt_qposadr[j] for j in range(m.njnt) if any(n in m.joint(j).name for n in ("driver", "inner_knuckle"))
    ]
    pregrasp = PrimitiveConfig().approach.pregrasp_closure * 0.85  # closure 0..1 over the driver's 0..0.85 rad
    fromto = np.zeros(6)
    least = 1.0
    for q in joints[::5]:
        d.qpos[:] = 0.0
        d.qpos[fingers] = pregrasp
        d.qpos[arm] = q
        mujoco.mj_kinematics(m, d)
        least = min(least, *(mujoco.mj_geomDistance(m, d, a, b, 0.1, fromto) for a in grip for b in shoulder))
    return least


@pytest.mark.parametrize("radius", [0.176, 0.30])
def test_an_approach_to_a_handle_near_the_base_comes_in_low_from_outside_and_keeps_clear_of_the_arm(radius):
    """The pre-grasp point 8 cm above a drawer's handle pulled to 0.176 m from the base's axis is reached only
    with the arm folded over its own shoulder: every route there put the gripper's knuckle on link 2 (101-137 N,
    chain8 harsh). The approach comes in ``base_rise`` above the grasp point from ``base_radius`` out, and the
    gripper keeps clear of the base and links 1-3 (robot model); farther out it arrives ``approach_height`` above."""
    c = PrimitiveConfig()
    azimuth = np.radians(69.7)
    target = top_down(np.array([radius * np.cos(azimuth), radius * np.sin(azimuth), 0.108]), np.radians(-47.6))
    robot = _ApproachingArm()
    toggler = Toggler(robot)
    toggler.pinch.descend_to(target, TryArgs())
    path = np.array(robot.path)
    out = np.hypot(path[:, 0], path[:, 1])
    assert path[-1] == pytest.approx(target[:3, 3], abs=0.003)
    if radius < c.approach.base_radius:
        low = path[:, 2] < target[2, 3] + c.approach.approach_height - 0.003
        # in from base_radius (the straight line from the transit waypoint cuts ~3 mm inside it), then down
        assert np.all(
            (out[low] > c.approach.base_radius - 0.01) | (path[low, 2] < target[2, 3] + c.approach.base_rise + 0.003)
        )
        assert _gripper_clearance_from_the_shoulder(robot.joints) > 0.002  # 3.1 mm; -17.4 mm at 8 cm (before)
    else:
        assert path[:, 2].max() > target[2, 3] + c.approach.approach_height - 0.003


def test_a_cautious_descent_runs_at_a_constant_speed_no_faster_than_its_mean():
    """Beside a door that may stand open over the part, the descent meets its plate anywhere on the way down: at the
    2.4 cm/s peak of a smooth profile the pad bounced on it for 11 ticks (47 N true) before the filtered reading
    passed the light touch (paper-test-2, harsh); at a constant speed it is met at the mean, 1.6 cm/s."""
    c = PrimitiveConfig()
    target = top_down(np.array([0.40, 0.10, 0.108]), 0.3)
    robot = _ApproachingArm()
    toggler = Toggler(robot)
    toggler.pinch.descend_to(target, TryArgs(cautious=True))
    path = np.array(robot.path)
    over = np.hypot(*(path[:, :2] - target[:2, 3]).T) < 1e-3  # the descent: straight down over the grasp point
    assert path[over, 2].max() == pytest.approx(target[2, 3] + c.approach.approach_height, abs=0.002)
    below = path[
        over & (path[:, 2] < target[2, 3] + c.approach.approach_height - 0.001), 2
    ]  # after the travel's arrival
    speed = -np.diff(below) / c.motion.tick
    assert speed.max() < 1.1 * c.approach.approach_height / c.approach.cautious_descend_time


class _PlateBesideKnuckle(_HeldTCP):
    """A gripper closed on a handle with a plate beside one knuckle, along base +y: the knuckle meets it once the
    gripper opens past ``block`` (less as the TCP moves off towards -y, ``travel`` [m] of knuckle per unit of
    closure); its servo then presses into the plate with ``stiffness`` [N per unit of closure] times how far its
    command goes past, up to ``most`` [N], and moves at most ``speed`` [1/s] (the xArm gripper snaps at ~2/s)."""

    def __init__(self, block: float = 0.85, stiffness: float = 400.0, travel: float = 0.04) -> None:
        super().__init__(stiffness=0.0, stretch=0.0)
        self.block, self.press, self.travel, self.most, self.speed = block, stiffness, travel, 100.0, 2.0
        self.y0 = self.tcp_pose_in_base()[1, 3]
        self.closure = self.command = 0.93
        self.peak = 0.0

    def _blocked_at(self) -> float:
        return self.block - (self.y0 - self.tcp_pose_in_base()[1, 3]) / self.travel

    def command_gripper(self, closure: float) -> None:
        self.command = closure

    def gripper_opening(self) -> float:
        return self.closure

    def wrench(self) -> np.ndarray:
        load = min(self.most, self.press * max(0.0, self._blocked_at() - self.command))
        self.peak = max(self.peak, load)
        return np.array([0.0, -load, 0.0, 0.0, 0.0, 0.0])

    def wait(self, seconds: float) -> None:
        super().wait(seconds)
        step = float(np.clip(self.command - self.closure, -self.speed * seconds, self.speed * seconds))
        self.closure = max(self.closure + step, min(self._blocked_at(), self.closure))


def test_an_opening_finger_that_meets_a_plate_stops_at_a_light_touch_and_lets_go_as_far_as_there_is_room():
    """Snapped open beside an open door's plate, a knuckle pressed into it with the gripper's whole force (93 N
    true, paper-test-2 harsh); ramped open, it stops at the lift's light touch, backs off and opens on."""
    c = PrimitiveConfig()
    snapped = _PlateBesideKnuckle()
    snapping = Toggler(snapped)
    snapping.watch.guard = False  # (it stops at the 60 N guard: the true force has passed it by then)
    snapped.command_gripper(c.approach.pregrasp_closure)  # the servo alone snaps the fingers open
    for _ in range(round(c.motion.release_time / c.motion.tick)):
        snapping.motion.tick(snapping.ik.tcp_pose())
    assert snapped.peak >= 90.0
    robot = _PlateBesideKnuckle()
    Toggler(robot).retreat.open_gently(c.approach.pregrasp_closure)
    assert robot.peak < c.retreat.lift_contact_force + 10.0, robot.peak
    assert robot.closure < 0.93 - 0.1  # the handle let go
