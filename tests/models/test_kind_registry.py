"""The kind registry: unknown and duplicate kinds are refused clearly, a new kind leaves the paper's family
and boxes untouched, and every registered kind's template agrees with the MJCF its module builds."""

import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from models import Box, Component, Goal, PuzzleSpec, UnknownKindError
from models.generator import paper_family
from models.geometry import rectangle, transform_points
from models.kinds import (
    ALLOWED_NEIGHBOURS,
    KIND_NAMES,
    PAPER_FAMILY,
    SLIDE,
    DuplicateKindError,
    JointDynamics,
    Kind,
    KindRegistry,
    get_kind,
    kind_code,
    may_neighbour,
    registered_kind,
    registered_kinds,
    registry,
)
from models.kinds.parts import PLATE_THICKNESS, add_handle, add_joint, add_plate
from models.kinds.template import HANDLE_HEIGHT
from models.puzzle_box import build_puzzle_box

LEVER = replace(  # a slide along y with its own travel, handle and footprint
    SLIDE,
    name="lever",
    joint_axis=(0.0, 1.0, 0.0),
    travel=0.03,
    handle_xy=(0.0, -0.035),
    footprint=rectangle(-0.03, 0.03, -0.05, 0.06),
)
LEVER_DYNAMICS = JointDynamics(damping=0.5, frictionloss=0.1)


def _build_lever(body, name):
    add_plate(body, name, (0.5, 0.5, 0.5, 1), -0.03, 0.03, 0.05)
    add_handle(body, name, LEVER)
    return add_joint(body, name, LEVER, LEVER_DYNAMICS)


LEVER_KIND = Kind(
    template=LEVER,
    dynamics=LEVER_DYNAMICS,
    colour=(0.5, 0.5, 0.5, 1),
    build=_build_lever,
    glyph="0.5",
    sweep_effort=1.0,
)
"""A throwaway kind that exists only in these tests."""


@pytest.fixture
def with_lever(monkeypatch):
    """The process-wide registry extended by the lever, for this test only (restored afterwards)."""
    extended = registry._REGISTRY.copy()
    extended.register(LEVER_KIND)
    monkeypatch.setattr(registry, "_REGISTRY", extended)
    return extended


def one_component_spec(kind: str, pose=(0.031, -0.017, 0.6)) -> PuzzleSpec:
    return PuzzleSpec(
        name=f"one-{kind}",
        components=(Component(name=f"{kind}-0", kind=kind, pose=pose, marker=0),),
        locks=(),
        goal=Goal(f"{kind}-0", 1),
        box=Box(size=(0.4, 0.3, 0.1)),
    )


def test_the_builtin_kinds_are_registered_in_the_paper_order():
    assert registered_kinds() == ("door", "slide", "wheel")
    for name in registered_kinds():
        assert registered_kind(name).name == name and get_kind(name) is registered_kind(name).template


def test_an_unknown_kind_is_refused_listing_the_registered_ones():
    with pytest.raises(UnknownKindError) as err:
        registered_kind("drawer")
    assert err.value.kind == "drawer" and err.value.available == ("door", "slide", "wheel")
    assert "drawer" in str(err.value) and all(k in str(err.value) for k in ("door", "slide", "wheel"))
    with pytest.raises(UnknownKindError, match="door"):
        get_kind("drawer")


def test_an_unknown_kind_in_a_spec_is_refused_by_the_box_builder():
    spec = one_component_spec("door")
    spec = PuzzleSpec(
        name=spec.name,
        components=(Component(name="x", kind="drawer", pose=(0, 0, 0), marker=0),),
        locks=(),
        goal=Goal("x", 1),
        box=spec.box,
    )
    with pytest.raises(UnknownKindError, match="drawer"):
        build_puzzle_box(spec)


def test_a_kind_registered_twice_is_refused():
    fresh = KindRegistry(registry.BUILTIN_KINDS)
    with pytest.raises(DuplicateKindError, match="'door' is already registered") as err:
        fresh.register(registered_kind("door"))
    assert err.value.registered == ("door", "slide", "wheel")
    with pytest.raises(DuplicateKindError):
        registry.register(registered_kind("slide"))
    assert registered_kinds() == ("door", "slide", "wheel")  # the refused registration left no trace


def test_only_kinds_are_registered():
    with pytest.raises(TypeError, match="Kind"):
        KindRegistry().register(LEVER)  # a bare template has no MJCF parts


def test_a_new_kind_changes_neither_the_paper_family_nor_its_boxes(monkeypatch):
    before = [spec.to_json() for spec in paper_family("all")]
    family = (PAPER_FAMILY, KIND_NAMES, ALLOWED_NEIGHBOURS, [kind_code(k) for k in KIND_NAMES])
    extended = registry._REGISTRY.copy()
    extended.register(LEVER_KIND)
    monkeypatch.setattr(registry, "_REGISTRY", extended)
    assert "lever" in registered_kinds()  # the builders see it ...
    assert (PAPER_FAMILY, KIND_NAMES, ALLOWED_NEIGHBOURS, [kind_code(k) for k in KIND_NAMES]) == family
    assert KIND_NAMES == ("door", "slide", "wheel") and [kind_code(k) for k in KIND_NAMES] == [0, 1, 2]
    assert not any(may_neighbour("lever", k) for k in (*KIND_NAMES, "lever"))  # ... the paper does not
    with pytest.raises(UnknownKindError):
        kind_code("lever")
    assert [spec.to_json() for spec in paper_family("all")] == before


def test_a_newly_registered_kind_is_built(with_lever):
    model = mujoco.MjModel.from_xml_string(
        build_puzzle_box(one_component_spec("lever"), with_markers=False).to_xml_string()
    )
    assert model.joint("lever-0:joint").type == mujoco.mjtJoint.mjJNT_SLIDE


def test_the_registry_is_restored_after_a_test():
    assert "lever" not in registered_kinds()


@pytest.mark.parametrize("name", [*registered_kinds(), "lever"])
def test_template_mjcf_and_handle_agree(name, with_lever):
    kind = with_lever.get(name)
    pose = (0.031, -0.017, 0.6)
    root = build_puzzle_box(one_component_spec(name, pose))
    root.compiler.angle = "radian"  # as the scene compiles the box (models.scene); MJCF's default is degrees
    model = mujoco.MjModel.from_xml_string(root.to_xml_string(), assets=root.get_assets())
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)  # qpos0: every component closed (state 0)
    # the box model's world frame is the lid frame
    expected_xy = transform_points(pose, np.array([kind.template.handle_xy]))[0]
    handle = data.geom(f"{name}-0:handle").xpos
    assert np.allclose(handle[:2], expected_xy, rtol=0, atol=1e-9)
    assert math.isclose(handle[2], PLATE_THICKNESS + HANDLE_HEIGHT / 2, abs_tol=1e-9)
    site = data.site(f"{name}-0:handle_site").xpos
    assert np.allclose(site, [*expected_xy, PLATE_THICKNESS + HANDLE_HEIGHT], rtol=0, atol=1e-9)
    joint = model.joint(f"{name}-0:joint")
    t = kind.template
    assert joint.type == {"hinge": mujoco.mjtJoint.mjJNT_HINGE, "slide": mujoco.mjtJoint.mjJNT_SLIDE}[t.joint]
    assert np.allclose(joint.range, [0.0, t.travel], atol=1e-12)
    assert math.isclose(model.dof_damping[joint.dofadr[0]], kind.dynamics.damping)
    assert math.isclose(model.dof_frictionloss[joint.dofadr[0]], kind.dynamics.frictionloss)
    # joint axis and anchor: the template's, in the component frame turned by the pose
    R = np.array([[math.cos(pose[2]), -math.sin(pose[2])], [math.sin(pose[2]), math.cos(pose[2])]])
    assert np.allclose(data.xaxis[joint.id][:2], R @ np.array(t.joint_axis[:2]), atol=1e-9)
    assert math.isclose(data.xaxis[joint.id][2], t.joint_axis[2], abs_tol=1e-9)
    anchor = transform_points(pose, np.array([t.joint_origin[:2]]))[0]
    assert np.allclose(data.xanchor[joint.id][:2], anchor, atol=1e-9)
