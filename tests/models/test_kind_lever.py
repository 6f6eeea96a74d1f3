"""The lever kind (models/kinds/lever.py): registered from its module alone, raised on its bracket, balanced so
that it stays where it is left, opened by pressing its free end down, held by its latch, and read from where
its marker went."""

import math

import mujoco
import numpy as np
import pytest

from puzzlebox.models import Box, Component, Goal, LockRule, PuzzleSpec
from puzzlebox.models.generator import RandomGraphConfig, generate_chain, generate_random, paper_family
from puzzlebox.models.kinds import (
    KIND_NAMES,
    PAPER_FAMILY,
    family_named,
    registered_kind,
    registered_kinds,
    registry_family,
)
from puzzlebox.models.kinds.lever import LEVER, LEVER_LIFT
from puzzlebox.models.kinds.parts import PLATE_THICKNESS
from puzzlebox.models.scene import build_scene
from puzzlebox.skills.joint_model import joint_model


def lever_and_slide(locked: bool) -> PuzzleSpec:
    """A lever and a slide beside it; with ``locked``, the slide closed keeps the lever closed."""
    return PuzzleSpec(
        name="lever-test",
        components=(
            Component(name="lever", kind="lever", pose=(0.04, 0.0, 0.3), marker=0),
            Component(name="slide", kind="slide", pose=(-0.08, 0.0, math.pi / 2), marker=1),
        ),
        locks=(LockRule("slide", 0, "lever", 0),) if locked else (),
        goal=Goal("lever", 1),
        box=Box(size=(0.3, 0.2, 0.08)),
    )


def compiled(spec: PuzzleSpec) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = build_scene(spec).compile()
    return model, mujoco.MjData(model)


def test_the_lever_is_registered_from_its_module_and_joins_the_registry_family_only():
    assert "lever" in registered_kinds() and registered_kind("lever").template is LEVER
    assert "lever" in registry_family().kinds and "lever" not in PAPER_FAMILY.kinds
    assert all(registry_family().may_neighbour("lever", k) for k in ("door", "slide", "wheel"))
    assert KIND_NAMES == ("door", "slide", "wheel")
    assert all("lever" not in spec.kinds for spec in paper_family("all"))
    boxes = (generate_random(RandomGraphConfig(6, family=family_named("all")), s) for s in range(30))
    assert any("lever" in box.kinds for box in boxes)  # the random family draws it (stops at the first box)


def test_the_lever_stays_where_it_is_left_in_either_state_with_no_warnings():
    model, data = compiled(lever_and_slide(locked=False))
    joint = model.joint("box/lever:joint")
    for start in (0.0, LEVER.travel):
        mujoco.mj_resetData(model, data)
        data.qpos[joint.qposadr[0]] = start
        for _ in range(round(5.0 / model.opt.timestep)):  # 5 s untouched
            mujoco.mj_step(model, data)
        assert abs(data.qpos[joint.qposadr[0]] - start) < math.radians(0.2)
    assert not any(w.number for w in data.warning)


def test_a_lever_carrying_its_locks_mechanism_stays_where_it_is_left():
    # a lever's arm is balanced on its pin (gravcomp); the walls, rods, lugs and pawls of its locks (0.06-0.5 g each)
    # hung on it unbalanced turned a free lever open by ~0.4 deg in 30 s, to its stop within a training episode, where
    # a grasp aimed at its closed handle closed on nothing (runs/s8/lever-grasp)
    spec = generate_chain(["lever", "wheel"], seed=0)  # the lever locks the wheel: it carries the lock's mechanism
    model, data = compiled(spec)
    joint = model.joint("box/lever-0:joint")
    assert model.body_gravcomp[model.body("box/lever-0:arm").id] == 1.0
    for _ in range(round(20.0 / model.opt.timestep)):  # 20 s untouched, closed and free
        mujoco.mj_step(model, data)
    assert abs(data.qpos[joint.qposadr[0]]) < math.radians(0.02)


def test_pressing_the_free_end_down_opens_it_to_its_stop_above_the_lid():
    model, data = compiled(lever_and_slide(locked=False))
    joint = model.joint("box/lever:joint")
    handle = model.site("box/lever:handle_site").id
    z0 = None
    for k in range(round(1.0 / model.opt.timestep)):
        data.xfrc_applied[model.site_bodyid[handle], :3] = [0, 0, -3.0]  # 3 N down on the arm
        mujoco.mj_step(model, data)
        z0 = data.site_xpos[handle][2] if k == 0 else z0
    assert data.qpos[joint.qposadr[0]] == pytest.approx(LEVER.travel, abs=math.radians(0.5))
    assert data.site_xpos[handle][2] < z0 - 0.015  # the handle went down ~2 cm
    tip = data.geom("box/lever:plate")
    corners = (
        tip.xpos[:, None] + tip.xmat.reshape(3, 3) @ (np.array([[1, 1, -1], [1, -1, -1]]) * model.geom_size[tip.id]).T
    )
    lid_top = 0.08  # the box's height: the lid's top face in the world
    assert corners[2].min() > lid_top + 0.002  # the pressed arm's tip stops clear of the lid


def test_a_latched_lever_holds_against_a_hard_press():
    model, data = compiled(lever_and_slide(locked=True))
    latch = model.equality("box/lever:latch").id
    data.eq_active[latch] = 1  # as the twin engages it while the slide is closed
    joint = model.joint("box/lever:joint")
    handle = model.site("box/lever:handle_site").id
    for _ in range(round(0.5 / model.opt.timestep)):
        data.xfrc_applied[model.site_bodyid[handle], :3] = [0, 0, -50.0]  # 50 N down on the arm
        mujoco.mj_step(model, data)
    assert abs(data.qpos[joint.qposadr[0]]) < math.radians(0.5)


@pytest.mark.parametrize("fraction", [0.1, 0.25, 0.5, 1.0])
def test_the_marker_centre_tells_how_far_the_lever_was_pressed(fraction):
    """The skills' joint model, built from the marker pose in the lid's plane, reads the fraction of the
    travel from where the (raised) marker centre went, as the twin world's verdict does."""
    model, data = compiled(lever_and_slide(locked=False))
    joint = model.joint("box/lever:joint")
    mujoco.mj_forward(model, data)
    marker = data.geom("box/lever:marker")
    closed = marker.xpos.copy()
    assert closed[2] == pytest.approx(0.08 + LEVER_LIFT + PLATE_THICKNESS, abs=1e-3)  # raised on its bracket
    upright = np.eye(4)  # perception's pose: the closed marker turned upright, in the lid's plane
    upright[:3, :3], upright[:3, 3] = marker.xmat.reshape(3, 3), closed - [0, 0, LEVER_LIFT]
    jm = joint_model("lever", upright)
    data.qpos[joint.qposadr[0]] = fraction * LEVER.travel
    mujoco.mj_forward(model, data)
    assert jm.fraction_between(closed, marker.xpos) == pytest.approx(fraction, abs=0.01)
    assert 0.005 * fraction < np.linalg.norm(marker.xpos - closed) < 0.013 * fraction  # ~12 mm at the stop


def test_chains_with_levers_are_generated_and_valid():
    spec = generate_chain(["slide", "lever", "wheel"], seed=2)
    assert spec.kinds == ("slide", "lever", "wheel")
    model, data = compiled(spec)
    mujoco.mj_step(model, data)
    assert not any(w.number for w in data.warning)
