"""The drawer kind (models/kinds/drawer.py): registered from its module alone, a tray pulled out of its fixed
housing between rails, staying where it is left, held by its latch."""

import mujoco
import numpy as np
import pytest

from models import Box, Component, Goal, LockRule, PuzzleSpec
from models.generator import RandomGraphConfig, generate_chain, generate_random, paper_family
from models.kinds import KIND_NAMES, PAPER_FAMILY, family_named, registered_kind, registered_kinds, registry_family
from models.kinds.drawer import DRAWER, TRAVEL
from models.scene import build_scene


def drawer_and_wheel(locked: bool) -> PuzzleSpec:
    """A drawer and a wheel beside it; with ``locked``, the wheel closed keeps the drawer closed."""
    return PuzzleSpec(
        name="drawer-test",
        components=(
            Component(name="drawer", kind="drawer", pose=(0.0, 0.0, -0.4), marker=0),
            Component(name="wheel", kind="wheel", pose=(-0.04, 0.11, 0.0), marker=1),
        ),
        locks=(LockRule("wheel", 0, "drawer", 0),) if locked else (),
        goal=Goal("drawer", 1),
        box=Box(size=(0.3, 0.3, 0.08)),
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
    kinds = {k for s in range(30) for k in generate_random(RandomGraphConfig(6, family=family_named("all")), s).kinds}
    assert "drawer" in kinds


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
