"""The toggle primitive opens free parts of each kind and feels latched ones through the wrist F/T
sensor; unreachable and non-finite IK targets are typed failures."""

import numpy as np
import pytest
from world_fixtures import TrueForceWatch

from puzzlebox.models.generator import generate_chain
from puzzlebox.skills import MarkerDetector, joint_model, lid_height, select_markers, upright_pose
from puzzlebox.skills.errors import IKFailure
from puzzlebox.skills.kinematics import ArmKinematics, top_down
from puzzlebox.skills.primitives import PrimitiveConfig, Toggler
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
    assert result.peak_opposing_force > 5.0 and result.progress < 0.1
    assert abs(session.component_positions()[j] - before) < 0.02  # the latch held against the pull
    assert session.robot.gripper_opening() <= PrimitiveConfig().pregrasp_closure + 0.05  # and the robot let go


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
    assert 5.0 < door.sim_time < 18.0  # a slow descent, the over-travel into the end stop, a return through the transit


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
    toggler.guard = False  # as in a withdrawal
    for _ in range(toggler.config.force_filter_samples):
        toggler._sense()
    assert np.linalg.norm(toggler.force_in_base) == pytest.approx(60.0, rel=0.02)
    toggler._relieve()
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
    ],
)
def test_a_config_with_an_impossible_pace_or_yield_is_a_clear_error(field, value, message):
    with pytest.raises(ValueError, match=message):
        PrimitiveConfig(**{field: value})
