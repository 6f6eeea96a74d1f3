"""The drawer kind (models/kinds/drawer.py): registered from its module alone, a tray pulled out of the box's
side wall (its housing and rails on the lid at the lid's edge), staying where it is left, held by its latch."""

import functools
import math

import mujoco
import numpy as np
import pytest

from puzzlebox.models import Box, Component, Goal, LockRule, PuzzleSpec
from puzzlebox.models.box_export import compile_box
from puzzlebox.models.generator import RandomGraphConfig, generate_chain, generate_random, paper_family
from puzzlebox.models.generator.layout import Layout, LayoutConfig
from puzzlebox.models.kinds import (
    KIND_NAMES,
    PAPER_FAMILY,
    family_named,
    registered_kind,
    registered_kinds,
    registry_family,
)
from puzzlebox.models.kinds.drawer import DRAWER, DRAWER_BACK, HOUSING_DEPTH, RAIL_OUTER, TRAVEL
from puzzlebox.models.puzzle_box import lid_to_world
from puzzlebox.models.scene import DEFAULT_BOX_POSE, build_scene
from puzzlebox.models.validation import validate_data

LID = (0.3, 0.3, 0.08)
"""The hand-made test box: lid length, width and height [m]."""


def drawer_and_wheel(locked: bool) -> PuzzleSpec:
    """A drawer at the lid's -y edge pointing out (-y) and a wheel beside it; with ``locked``, the wheel closed
    keeps the drawer closed."""
    return PuzzleSpec(
        name="drawer-test",
        components=(
            Component(name="drawer", kind="drawer", pose=(0.0, -(LID[1] / 2 - DRAWER.edge_x), -math.pi / 2), marker=0),
            Component(name="wheel", kind="wheel", pose=(0.09, -0.08, 0.0), marker=1),
        ),
        locks=(LockRule("wheel", 0, "drawer", 0),) if locked else (),
        goal=Goal("drawer", 1),
        box=Box(size=LID),
    )


def compiled(spec: PuzzleSpec) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = build_scene(spec).compile()
    return model, mujoco.MjData(model)


def pull(model, data, force: float, seconds: float) -> None:
    """Pull the drawer's handle along its opening direction with ``force`` [N] for ``seconds`` [s]."""
    handle = model.site("box/drawer:handle_site").id
    joint = model.joint("box/drawer:joint")
    mujoco.mj_forward(model, data)
    direction = data.xaxis[joint.id]  # the slide axis in the world
    for _ in range(round(seconds / model.opt.timestep)):
        data.xfrc_applied[model.site_bodyid[handle], :3] = force * direction
        mujoco.mj_step(model, data)


def test_the_drawer_is_registered_from_its_module_and_joins_the_registry_family_only():
    assert "drawer" in registered_kinds() and registered_kind("drawer").template is DRAWER
    assert "drawer" in registry_family().kinds and "drawer" not in PAPER_FAMILY.kinds
    assert KIND_NAMES == ("door", "slide", "wheel")
    assert all("drawer" not in spec.kinds for spec in paper_family("all"))
    boxes = (generate_random(RandomGraphConfig(6, family=family_named("all")), s) for s in range(30))
    assert any("drawer" in box.kinds for box in boxes)  # the random family draws it (stops at the first box)


def test_pulling_the_handle_draws_the_tray_out_of_its_housing_to_its_stop():
    model, data = compiled(drawer_and_wheel(locked=False))
    joint = model.joint("box/drawer:joint")
    mujoco.mj_forward(model, data)
    marker0 = data.geom("box/drawer:marker").xpos.copy()
    pull(model, data, 3.0, 1.0)  # a 3 N pull beats the rails' 0.3 N of dry friction and 1 N·s/m of damping
    assert data.qpos[joint.qposadr[0]] == pytest.approx(TRAVEL, abs=5e-4)
    moved = data.geom("box/drawer:marker").xpos - marker0
    assert np.linalg.norm(moved) == pytest.approx(TRAVEL, abs=1e-3) and abs(moved[2]) < 1e-4  # out, level
    assert not any(w.number for w in data.warning)


def test_the_drawer_stays_where_it_is_left():
    model, data = compiled(drawer_and_wheel(locked=False))
    joint = model.joint("box/drawer:joint")
    for start in (0.0, TRAVEL / 2, TRAVEL):
        mujoco.mj_resetData(model, data)
        data.qpos[joint.qposadr[0]] = start
        for _ in range(round(3.0 / model.opt.timestep)):
            mujoco.mj_step(model, data)
        assert abs(data.qpos[joint.qposadr[0]] - start) < 2e-4


def test_a_latched_drawer_holds_against_a_hard_pull():
    model, data = compiled(drawer_and_wheel(locked=True))
    data.eq_active[model.equality("box/drawer:latch").id] = 1  # as the twin engages it while the wheel is closed
    pull(model, data, 50.0, 0.5)
    assert abs(data.qpos[model.joint("box/drawer:joint").qposadr[0]]) < 1e-3  # 0.7 mm of the 45 mm travel


def test_the_housing_and_rails_stay_put_while_the_tray_moves():
    model, data = compiled(drawer_and_wheel(locked=False))
    mujoco.mj_forward(model, data)
    fixed = {g: data.geom(f"box/drawer:{g}").xpos.copy() for g in ("housing", "rail_left", "rail_right")}
    pull(model, data, 3.0, 1.0)
    for name, before in fixed.items():
        assert np.allclose(data.geom(f"box/drawer:{name}").xpos, before, atol=1e-9), name
    body = int(model.geom("box/drawer:plate").bodyid[0])
    assert model.body(body).name == "box/drawer:tray"


def test_chains_with_drawers_are_generated_and_valid():
    spec = generate_chain(["door", "drawer", "wheel"], seed=2)
    assert spec.kinds == ("door", "drawer", "wheel")
    model, data = compiled(spec)
    mujoco.mj_step(model, data)
    assert not any(w.number for w in data.warning)


def drawers_of(spec: PuzzleSpec) -> list[Component]:
    return [c for c in spec.components if c.kind == "drawer"]


def front_on_edge(spec: PuzzleSpec, drawer: Component) -> tuple[float, float]:
    """Of the lid edge nearest the drawer's front face: how far the front face lies beyond it [m] (0 when
    flush) and the cosine between the drawer's +x and that edge's outward normal (1 when it points out)."""
    x, y, yaw = drawer.pose
    out = np.array([math.cos(yaw), math.sin(yaw)])
    front = np.array([x, y]) + DRAWER.edge_x * out
    half = np.array(spec.box.size[:2]) / 2
    edges = [(front @ n - half @ abs(n), n) for n in np.array([[1, 0], [-1, 0], [0, 1], [0, -1]], dtype=float)]
    off, normal = min(edges, key=lambda e: abs(e[0]))
    return float(off), float(out @ normal)


@functools.cache  # 36 boxes generated once per worker, for the tests that read them
def specs_with_drawers() -> tuple[PuzzleSpec, ...]:
    chains = [
        generate_chain(kinds, seed)
        for kinds in (
            ["door", "drawer", "wheel"],
            ["drawer", "door"],
            ["wheel", "drawer", "lever"],
            ["drawer", "lever", "drawer"],
        )
        for seed in range(4)
    ]
    randoms = [generate_random(RandomGraphConfig(6, family=family_named("all")), seed) for seed in range(20)]
    return tuple(spec for spec in chains + randoms if drawers_of(spec))


def test_the_hand_made_drawer_box_is_valid():
    assert validate_data(drawer_and_wheel(locked=True).to_dict()) == []


def test_generated_drawers_sit_at_the_lid_edge_pointing_out_and_the_boxes_are_valid():
    specs = specs_with_drawers()
    assert len(specs) >= 20
    for spec in specs:
        assert validate_data(spec.to_dict()) == [], spec.name
        for drawer in drawers_of(spec):
            off, outward = front_on_edge(spec, drawer)
            assert abs(off) < 2e-6, (spec.name, drawer.name, off)  # flush with the box's side wall
            assert outward == pytest.approx(1.0, abs=1e-9), (spec.name, drawer.name)  # +x points out of the lid


def test_drawers_on_opposite_sides_set_the_lid_between_their_fronts():
    opposite = []
    for seed in range(30):
        spec = generate_chain(["drawer", "lever", "drawer"], seed)
        yaws = {round(math.degrees(d.pose[2])) % 360 for d in drawers_of(spec)}
        if yaws in ({0, 180}, {90, 270}):
            opposite.append(spec)
            for drawer in drawers_of(spec):
                assert abs(front_on_edge(spec, drawer)[0]) < 2e-6, (spec.name, drawer.name)
    assert opposite  # the layout does put drawers on opposite sides


def test_the_open_tray_lies_beyond_the_lid_edge():
    for spec in specs_with_drawers()[:6]:
        model = build_scene(spec).compile()
        data = mujoco.MjData(model)
        T_world_lid = lid_to_world(spec.box.pose or DEFAULT_BOX_POSE, spec.box.size[2])
        lid_from_world = np.linalg.inv(T_world_lid)
        half = np.array(spec.box.size[:2]) / 2
        for drawer in drawers_of(spec):
            joint = model.joint(f"box/{drawer.name}:joint")
            mujoco.mj_forward(model, data)
            closed = (lid_from_world @ np.append(data.geom(f"box/{drawer.name}:plate").xpos, 1))[:2]
            assert np.all(abs(closed) < half), (spec.name, drawer.name)  # closed: on the lid
            data.qpos[joint.qposadr[0]] = TRAVEL
            mujoco.mj_forward(model, data)
            for where in (data.geom(f"box/{drawer.name}:plate").xpos, data.site(f"box/{drawer.name}:handle_site").xpos):
                plan = (lid_from_world @ np.append(where, 1))[:2]
                assert np.any(abs(plan) > half), (spec.name, drawer.name, plan)  # open: past the box's side
            data.qpos[joint.qposadr[0]] = 0.0


def moved_drawer(change) -> tuple[dict, str]:
    spec = generate_chain(["door", "drawer", "wheel"], seed=2)
    data = spec.to_dict()
    drawer = drawers_of(spec)[0]
    entry = next(c for c in data["components"] if c["name"] == drawer.name)
    entry["pose"] = list(change(*drawer.pose))
    return data, drawer.name


def test_validation_rejects_a_drawer_moved_inward_from_the_edge():
    data, name = moved_drawer(lambda x, y, yaw: (x - 0.01 * math.cos(yaw), y - 0.01 * math.sin(yaw), yaw))
    problems = validate_data(data)
    assert len(problems) == 1 and problems[0].where == f"component {name!r}", problems
    assert "front face" in problems[0].message and "10.0 mm inside" in problems[0].message


def test_validation_rejects_a_drawer_turned_to_point_inward():
    # turned half round about its front face's centre: the front stays on the edge line, the drawer points in
    def turned(x, y, yaw):
        fx, fy = x + DRAWER.edge_x * math.cos(yaw), y + DRAWER.edge_x * math.sin(yaw)
        return (fx + DRAWER.edge_x * math.cos(yaw), fy + DRAWER.edge_x * math.sin(yaw), yaw + math.pi)

    data, name = moved_drawer(turned)
    problems = [p for p in validate_data(data) if "front face" in p.message]
    assert len(problems) == 1 and problems[0].where == f"component {name!r}", validate_data(data)
    assert "points into the lid" in problems[0].message


def test_validation_rejects_a_drawer_not_facing_an_edge():
    data, name = moved_drawer(lambda x, y, yaw: (x, y, yaw + 0.3))
    problems = [p for p in validate_data(data) if p.where == f"component {name!r}"]
    assert any("multiple of 90 degrees" in p.message for p in problems), problems


def test_the_layout_cuts_the_lid_at_a_drawers_front_and_keeps_the_margin_elsewhere():
    config = LayoutConfig()
    layout = Layout(config)
    layout.place_first("drawer")
    length, width = layout.lid_size()
    ((x, y, _),) = layout.poses_in_lid()
    assert x + DRAWER.edge_x == pytest.approx(length / 2, abs=1e-12)  # no margin ahead of the front
    back_margin = (x - DRAWER_BACK - HOUSING_DEPTH) + length / 2
    assert config.margin - 1e-12 <= back_margin < config.margin + 0.005  # the margin, rounded up to 5 mm, behind
    assert width == pytest.approx(math.ceil((2 * (RAIL_OUTER + config.margin)) / 0.005 - 1e-9) * 0.005)
    assert y == pytest.approx(0.0, abs=1e-12)


def test_the_layout_puts_nothing_past_a_drawers_front():
    layout = Layout(LayoutConfig())
    layout.place_first("drawer")
    assert layout.candidate(0, "wheel", 0.0) is None  # straight ahead: in front of the drawer, past its front
    assert layout.candidate(0, "wheel", math.pi / 2) is not None  # beside it


def test_no_moving_part_touches_the_shell_anywhere_in_its_travel():
    """A drawer's tray rests on the shell's top face (0 mm apart) and is kept out of contact with it, as every
    part on the lid is: with that contact, the lid pressed a tray drawn at the hand's pace (15 mm/s) up with 20 N
    and held it with as much friction (MuJoCo's pyramidal cone couples a contact's damping to the sliding
    speed), and the hand read a free drawer as locked."""
    spec = generate_random(RandomGraphConfig(8, family=family_named("all")), 93000)  # two drawers
    assert sum(c.kind == "drawer" for c in spec.components) >= 1
    model, _ = compile_box(spec)  # the box alone
    data = mujoco.MjData(model)
    shell = model.geom("shell").id
    joints = [model.joint(f"{c.name}:joint") for c in spec.components]
    for fraction in np.linspace(0.0, 1.0, 11):
        for joint in joints:
            data.qpos[joint.qposadr[0]] = fraction * joint.range[1]
        mujoco.mj_forward(model, data)
        touching = [c for c in data.contact if shell in (c.geom1, c.geom2)]
        names = [model.geom(c.geom2 if c.geom1 == shell else c.geom1).name for c in touching]
        assert not names, f"at {fraction:.0%} of the travel"
