"""Reality profiles at a level of one factor: 0 is ideal, 1 realistic, 2 harsh, one factor at a time."""

import dataclasses

import pytest

from puzzlebox.twin.errors import ProfileError
from puzzlebox.twin.reality import HARSH, IDEAL, REALISTIC, RealityProfile
from puzzlebox.twin.reality_levels import ALL, FACTORS, force_noise_profile, profile_at


def _without_name(profile: RealityProfile) -> RealityProfile:
    return dataclasses.replace(profile, name="x")


@pytest.mark.parametrize("preset, level", [(REALISTIC, 1.0), (HARSH, 2.0)])
def test_all_factors_at_the_preset_levels_are_the_presets(preset, level):
    assert _without_name(profile_at(ALL, level)) == _without_name(preset)


@pytest.mark.parametrize("factor", [*FACTORS, ALL])
def test_level_zero_is_the_ideal_cell_with_a_placed_box(factor):
    profile = profile_at(factor, 0.0)
    assert profile.placement is not None
    assert _without_name(dataclasses.replace(profile, placement=None)) == _without_name(IDEAL)


@pytest.mark.parametrize("factor", list(FACTORS))
def test_a_factor_sets_its_own_fields_and_nothing_else(factor):
    profile = profile_at(factor, 1.0)
    owned = set(FACTORS[factor])
    changed = set()
    for section in ("camera", "force_torque", "arm", "physics"):
        for f in dataclasses.fields(getattr(IDEAL, section)):
            value = getattr(getattr(profile, section), f.name)
            if value != getattr(getattr(IDEAL, section), f.name):
                changed.add((section, f.name))
                assert value == getattr(getattr(REALISTIC, section), f.name)
    assert changed and changed <= owned


def test_half_a_level_lies_between_ideal_and_realistic():
    ft = profile_at("force-torque", 0.5).force_torque
    assert ft.force_noise == pytest.approx(REALISTIC.force_torque.force_noise / 2)
    physics = profile_at("physics", 0.5).physics
    assert 1.0 > physics.pad_friction > REALISTIC.physics.pad_friction  # None means the model's 1.0
    assert REALISTIC.physics.friction_scale.low < physics.friction_scale.low < 1.0


def test_beyond_harsh_stays_a_valid_profile():
    profile = profile_at(ALL, 3.0)
    assert profile.physics.jam_probability <= 1.0 and profile.physics.pad_friction > 0
    assert RealityProfile.from_dict(profile.to_dict()) == profile


def test_unknown_factor_and_bad_level_are_clear_errors():
    with pytest.raises(ProfileError, match="known:.*force-torque"):
        profile_at("gremlins", 1.0)
    with pytest.raises(ProfileError, match="level"):
        profile_at("arm", -0.5)
    with pytest.raises(ProfileError, match="force noise"):
        force_noise_profile(-1.0)


def test_force_noise_profile_is_ideal_but_for_the_wrench_noise():
    profile = force_noise_profile(7.0)
    assert profile.force_torque.force_noise == 7.0 and profile.force_torque.torque_noise == pytest.approx(0.21)
    assert profile.camera == IDEAL.camera and profile.physics == IDEAL.physics and profile.arm == IDEAL.arm
