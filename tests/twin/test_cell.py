"""The cell's fixed imperfections: the box hardware's per-kind physics factors are drawn once per cell (the same
in every trial of it, another cell draws others), change nothing at the identity, leave the cell's older draws
bit-identical, and multiply each component's per-trial factors in the compiled model."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from puzzlebox.models.generator import paper_family
from puzzlebox.models.kinds import KIND_NAMES, registered_kinds
from puzzlebox.twin.cell import draw_cell
from puzzlebox.twin.reality import IDENTITY, PRESETS, PhysicsReality, RealityProfile, ScaleRange
from puzzlebox.twin.session import TwinSession

SPEC = paper_family("test")[0]  # a door, two slides and two wheels
CAMERAS = ("overview", "xarm7/gripper/wrist_camera")


def with_physics(base: RealityProfile, **fields) -> RealityProfile:
    return dataclasses.replace(base, physics=dataclasses.replace(base.physics, **fields))


def test_kind_factors_are_one_per_kind_and_drawn_from_the_cell_seed_only():
    realistic = PRESETS["realistic"]
    with TwinSession(SPEC, seed=1, reality=realistic) as a, TwinSession(SPEC, seed=2, reality=realistic) as b:
        assert a.cell.kinds == b.cell.kinds  # every trial of one cell meets the same hardware
        assert not np.array_equal(a.physics_draw.joint_damping, b.physics_draw.joint_damping)  # trial jitter differs
    kinds = draw_cell(realistic, CAMERAS).kinds
    other = draw_cell(dataclasses.replace(realistic, cell_seed=7), CAMERAS).kinds
    for table, scale in ((kinds.joint_damping, realistic.physics.kind_joint_damping_scale),
                         (kinds.joint_friction, realistic.physics.kind_joint_friction_scale),
                         (kinds.latch_compliance, realistic.physics.kind_latch_compliance_scale)):  # fmt: skip
        assert list(table) == list(registered_kinds())  # the paper's first, drawn as before; then each new kind
        assert all(scale.low <= f <= scale.high for f in table.values())
    assert kinds != other


def test_kind_factors_leave_the_cameras_and_tcp_bias_of_a_cell_bit_identical():
    realistic = PRESETS["realistic"]
    plain = with_physics(
        realistic,
        kind_joint_damping_scale=IDENTITY,
        kind_joint_friction_scale=IDENTITY,
        kind_latch_compliance_scale=IDENTITY,
    )
    a, b = draw_cell(realistic, CAMERAS), draw_cell(plain, CAMERAS)
    assert np.array_equal(a.tcp_bias, b.tcp_bias)
    for name in CAMERAS:
        for f in dataclasses.fields(a.cameras[name]):
            assert np.array_equal(getattr(a.cameras[name], f.name), getattr(b.cameras[name], f.name)), f.name
    assert set(b.kinds.joint_damping.values()) == {1.0} and set(a.kinds.joint_damping.values()) != {1.0}


def model_factors(s: TwinSession) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each component's damping, frictionloss and latch solref[0] over the nominal model's, in spec order."""
    m, nominal, names = s.model, s.nominal_model, s.scene.names
    out = []
    for c in s.spec.components:
        dof = m.joint(names.components[c.name].joint).dofadr[0]
        latch = m.equality(names.components[c.name].latch).id
        out.append((
            m.dof_damping[dof] / nominal.dof_damping[dof],
            m.dof_frictionloss[dof] / nominal.dof_frictionloss[dof],
            m.eq_solref[latch, 0] / nominal.eq_solref[latch, 0],
        ))  # fmt: skip
    return tuple(np.array(column) for column in zip(*out, strict=True))


def test_identity_kind_ranges_change_nothing():
    trial_only = dataclasses.replace(
        PRESETS["ideal"],
        physics=PhysicsReality(joint_damping_scale=ScaleRange(0.5, 2.0), joint_friction_scale=ScaleRange(0.5, 2.0),
                               latch_compliance_scale=ScaleRange(1.0, 3.0)),
    )  # fmt: skip
    with TwinSession(SPEC, seed=3, reality=trial_only) as s:
        m, nominal, trial = s.model, s.nominal_model, s.physics_draw
        assert set(s.cell.kinds.joint_damping.values()) == {1.0}
        for i, c in enumerate(s.spec.components):  # exactly the per-trial factor, bit for bit
            dof = m.joint(s.scene.names.components[c.name].joint).dofadr[0]
            latch = m.equality(s.scene.names.components[c.name].latch).id
            assert m.dof_damping[dof] == nominal.dof_damping[dof] * trial.joint_damping[i]
            assert m.dof_frictionloss[dof] == nominal.dof_frictionloss[dof] * trial.joint_friction[i]
            assert m.eq_solref[latch, 0] == nominal.eq_solref[latch, 0] * trial.latch_compliance[i]
    with TwinSession(SPEC, seed=3, reality="ideal") as s:
        assert all(np.array_equal(f, np.ones(len(SPEC.components))) for f in model_factors(s))


def test_a_component_has_its_nominal_physics_times_its_kind_factor_times_its_trial_factor():
    profile = with_physics(
        PRESETS["realistic"],
        kind_joint_damping_scale=ScaleRange(0.3, 3.0, log=True),
        kind_joint_friction_scale=ScaleRange(0.3, 3.0),
        kind_latch_compliance_scale=ScaleRange(1.0, 4.0),
    )
    with TwinSession(SPEC, seed=4, reality=profile) as s:
        damping, friction, latch = model_factors(s)
        kinds, trial = s.cell.kinds, s.physics_draw
        for i, c in enumerate(s.spec.components):
            assert damping[i] == pytest.approx(kinds.joint_damping[c.kind] * trial.joint_damping[i], rel=1e-12)
            assert friction[i] == pytest.approx(kinds.joint_friction[c.kind] * trial.joint_friction[i], rel=1e-12)
            assert latch[i] == pytest.approx(kinds.latch_compliance[c.kind] * trial.latch_compliance[i], rel=1e-12)
        slides = [i for i, c in enumerate(s.spec.components) if c.kind == "slide"]
        # two slides share their kind's factor: what differs between them is the trial's small jitter
        assert damping[slides[0]] / trial.joint_damping[slides[0]] == pytest.approx(
            damping[slides[1]] / trial.joint_damping[slides[1]], rel=1e-12
        )


def test_realistic_draws_the_box_hardware_per_cell_and_only_jitter_per_trial():
    physics = PRESETS["realistic"].physics
    assert (physics.kind_joint_damping_scale.low, physics.kind_joint_damping_scale.high) == (0.7, 1.5)
    assert (physics.kind_joint_friction_scale.low, physics.kind_joint_friction_scale.high) == (0.7, 1.5)
    assert (physics.kind_latch_compliance_scale.low, physics.kind_latch_compliance_scale.high) == (1.0, 2.0)
    for jitter in (physics.joint_damping_scale, physics.joint_friction_scale, physics.latch_compliance_scale):
        assert jitter.high - jitter.low == pytest.approx(0.1)


def test_registering_a_kind_changes_no_paper_kinds_hardware(monkeypatch):
    """A kind beyond the paper's draws its factors from a stream of its own: the paper kinds' factors are the ones
    a registry of the paper's kinds alone draws, and each new kind's do not depend on which others exist."""
    import puzzlebox.twin.cell as cell

    realistic = PRESETS["realistic"]
    full = draw_cell(realistic, CAMERAS).kinds
    monkeypatch.setattr(cell, "registered_kinds", lambda: KIND_NAMES)
    paper_only = draw_cell(realistic, CAMERAS).kinds
    monkeypatch.setattr(cell, "registered_kinds", lambda: (*KIND_NAMES, "lever"))
    with_lever = draw_cell(realistic, CAMERAS).kinds
    for table in ("joint_damping", "joint_friction", "latch_compliance"):
        assert getattr(paper_only, table) == {k: getattr(full, table)[k] for k in KIND_NAMES}
        assert getattr(with_lever, table)["lever"] == getattr(full, table)["lever"]
