"""The kind registry: unknown and duplicate kinds are refused clearly, a new kind leaves the paper's family
and boxes untouched, and every registered kind's template agrees with the MJCF its module builds."""

import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from puzzlebox.models import Box, Component, Goal, PuzzleSpec, UnknownKindError
from puzzlebox.models.generator import paper_family
from puzzlebox.models.geometry import rectangle, transform_points
from puzzlebox.models.kinds import (
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
from puzzlebox.models.kinds.parts import PLATE_THICKNESS, add_handle, add_joint, add_plate
from puzzlebox.models.kinds.template import HANDLE_HEIGHT
from puzzlebox.models.puzzle_box import build_puzzle_box

LEVER = replace(  # a slide along y with its own travel, handle and footprint
    SLIDE,
    name="spinner",
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
"""A throwaway kind (named ``spinner``) that exists only in these tests."""
THROWAWAY = LEVER.name


@pytest.fixture
def with_lever(monkeypatch):
    """The process-wide registry extended by the throwaway kind, for this test only (restored afterwards)."""
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


def test_the_builtin_kinds_are_registered_paper_first_then_by_module_name():
    names = registered_kinds()
    assert names[:3] == ("door", "slide", "wheel") and list(names[3:]) == sorted(names[3:])
    assert names == tuple(k.name for k in registry.BUILTIN_KINDS)
    for name in registered_kinds():
        assert registered_kind(name).name == name and get_kind(name) is registered_kind(name).template


def test_an_unknown_kind_is_refused_listing_the_registered_ones():
    with pytest.raises(UnknownKindError) as err:
        registered_kind("trapdoor")
    assert err.value.kind == "trapdoor" and err.value.available == tuple(sorted(registered_kinds()))
    assert "trapdoor" in str(err.value) and all(k in str(err.value) for k in registered_kinds())
    with pytest.raises(UnknownKindError, match="door"):
        get_kind("trapdoor")


def test_an_unknown_kind_in_a_spec_is_refused_by_the_box_builder():
    spec = one_component_spec("door")
    spec = PuzzleSpec(
        name=spec.name,
        components=(Component(name="x", kind="trapdoor", pose=(0, 0, 0), marker=0),),
        locks=(),
        goal=Goal("x", 1),
        box=spec.box,
    )
    with pytest.raises(UnknownKindError, match="trapdoor"):
        build_puzzle_box(spec)


def test_a_kind_registered_twice_is_refused():
    fresh = KindRegistry(registry.BUILTIN_KINDS)
    with pytest.raises(DuplicateKindError, match="'door' is already registered") as err:
        fresh.register(registered_kind("door"))
    assert err.value.registered == tuple(sorted(registered_kinds()))
    before = registered_kinds()
    with pytest.raises(DuplicateKindError):
        registry.register(registered_kind("slide"))
    assert registered_kinds() == before  # the refused registration left no trace


def test_only_kinds_are_registered():
    with pytest.raises(TypeError, match="Kind"):
        KindRegistry().register(LEVER)  # a bare template has no MJCF parts


def test_a_new_kind_changes_neither_the_paper_family_nor_its_boxes(monkeypatch):
    before = [spec.to_json() for spec in paper_family("all")]
    family = (PAPER_FAMILY, KIND_NAMES, ALLOWED_NEIGHBOURS, [kind_code(k) for k in KIND_NAMES])
    extended = registry._REGISTRY.copy()
    extended.register(LEVER_KIND)
    monkeypatch.setattr(registry, "_REGISTRY", extended)
    assert THROWAWAY in registered_kinds()  # the builders see it ...
    assert (PAPER_FAMILY, KIND_NAMES, ALLOWED_NEIGHBOURS, [kind_code(k) for k in KIND_NAMES]) == family
    assert KIND_NAMES == ("door", "slide", "wheel") and [kind_code(k) for k in KIND_NAMES] == [0, 1, 2]
    assert not any(may_neighbour(THROWAWAY, k) for k in (*KIND_NAMES, THROWAWAY))  # ... the paper does not
    with pytest.raises(UnknownKindError, match="registered but not one of"):
        kind_code(THROWAWAY)
    assert [spec.to_json() for spec in paper_family("all")] == before


def test_a_newly_registered_kind_is_built(with_lever):
    model = mujoco.MjModel.from_xml_string(
        build_puzzle_box(one_component_spec(THROWAWAY), with_markers=False).to_xml_string()
    )
    assert model.joint(f"{THROWAWAY}-0:joint").type == mujoco.mjtJoint.mjJNT_SLIDE


def test_a_copy_of_the_registry_is_extended_without_touching_the_original():
    """What ``with_lever`` (and anyone extending the kinds for a while) relies on: the copy holds the same kinds and
    takes a new one; the process-wide registry neither gains it nor can be asked for it."""
    before = registered_kinds()
    extended = registry._REGISTRY.copy()
    assert extended.names() == before and all(extended.get(n) is registered_kind(n) for n in before)
    assert extended.register(LEVER_KIND) is LEVER_KIND
    assert extended.names() == (*before, THROWAWAY) and extended.get(THROWAWAY) is LEVER_KIND
    assert registered_kinds() == before and THROWAWAY not in registry._REGISTRY
    with pytest.raises(UnknownKindError, match=THROWAWAY):
        registered_kind(THROWAWAY)


@pytest.mark.parametrize("name", [*registered_kinds(), THROWAWAY])
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
    lift = kind.template.lift  # a raised part (a lever on its bracket) stands that much higher
    assert math.isclose(handle[2], lift + PLATE_THICKNESS + HANDLE_HEIGHT / 2, abs_tol=1e-9)
    site = data.site(f"{name}-0:handle_site").xpos
    assert np.allclose(site, [*expected_xy, lift + PLATE_THICKNESS + HANDLE_HEIGHT], rtol=0, atol=1e-9)
    marker = data.geom(f"{name}-0:marker")  # the marker frame is the component frame, on the plate's top
    assert np.allclose(marker.xpos[:2], pose[:2], atol=1e-9) and marker.xpos[2] > lift + PLATE_THICKNESS
    assert math.isclose(data.site(f"{name}-0:frame").xpos[2], lift + PLATE_THICKNESS, abs_tol=1e-9)
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
    assert math.isclose(data.xanchor[joint.id][2], lift + PLATE_THICKNESS / 2, abs_tol=1e-9)
    # the handle the primitives grasp is where the MJCF put it: the skills' joint model from the marker pose
    from puzzlebox.skills.joint_model import GRASP_DEPTH, joint_model

    T = np.eye(4)
    T[:3, :3] = data.geom(f"{name}-0:marker").xmat.reshape(3, 3)
    T[:3, 3] = [*pose[:2], marker.xpos[2] - lift]  # perception's upright pose: the marker in the lid's plane
    jm = joint_model(name, T)
    assert np.allclose(jm.grasp_point, handle + [0, 0, HANDLE_HEIGHT / 2 - GRASP_DEPTH], atol=1e-3)
    assert np.allclose(jm.axis, data.xaxis[joint.id], atol=1e-9)


def test_a_kind_outside_the_paper_family_is_coded_in_its_box_s_family_and_refused_in_the_paper_s_saying_so():
    # (kind_code("lever") said "Available kinds: ['door', 'slide', 'wheel']" while the environments code five)
    from puzzlebox.models.disassembly_kinds import family_kind_names

    five = family_kind_names(("door", "lever"))
    assert kind_code("lever", five) == five.index("lever") and kind_code("door", five) == kind_code("door") == 0
    with pytest.raises(UnknownKindError, match=r"'lever' is registered but not one of \['door', 'slide', 'wheel'\]"):
        kind_code("lever")
    with pytest.raises(UnknownKindError, match="unknown component kind 'hinge'.*'lever'"):
        kind_code("hinge")
