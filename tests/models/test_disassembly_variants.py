"""Variants of a measured computer (issue 14 part 4): counts within their ranges, the locks of what is added or
removed, jittered poses, one seed one variant, and every variant a valid scene."""

from __future__ import annotations

from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from puzzlebox.models import LockTable, load_spec
from puzzlebox.models.disassembly_variants import VariantConfig, disassembly_variant

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "disassembly"
pytestmark = pytest.mark.skipif(not DATA.is_dir(), reason=f"{DATA} (the shared disassembly data) is absent")
STILL = VariantConfig(position_sigma=0.0, angle_sigma=0.0)


@pytest.fixture(scope="module")
def lab_b():
    return load_spec(DATA / "lab-computer-b.json")


def locks_of(spec, name):
    return {(rule.locker, rule.locked) for rule in spec.locks if name in (rule.locker, rule.locked)}


@pytest.mark.parametrize("seed", range(12))
def test_a_variant_is_a_valid_scene_with_counts_in_range_and_the_motherboard_still_the_goal(lab_b, seed):
    variant = disassembly_variant(lab_b, seed)
    counts = Counter(variant.kinds)
    assert 1 <= counts["ram"] <= 3 and 0 <= counts["gpu_cable"] <= 2
    assert counts["screw"] == 2 and counts["panel"] == counts["cpu"] == counts["gpu"] == counts["motherboard"] == 1
    assert variant.goal.component == "motherboard" and variant.goal.state == 1
    optimum = len(LockTable.from_spec(variant).shortest_solution())
    assert optimum == len(variant.components)  # everything must come out before the motherboard, once each
    assert variant == disassembly_variant(lab_b, seed)  # one seed, one variant


def test_an_added_stick_sits_one_slot_along_with_the_locks_of_its_neighbour(lab_b):
    three = disassembly_variant(lab_b, 0, replace(STILL, ram_sticks=(3, 3), gpu_cables=(0, 0)))
    pose = dict(zip(three.component_names, three.poses_in_world(), strict=True))
    np.testing.assert_allclose(pose["ram-3"], pose["ram-2"] - [0.01, 0, 0, 0, 0, 0], atol=1e-12)
    assert locks_of(three, "ram-3") == {("side-panel", "ram-3"), ("ram-3", "motherboard")}
    one = disassembly_variant(lab_b, 0, replace(STILL, ram_sticks=(1, 1), gpu_cables=(0, 0)))
    assert "ram-2" not in one.component_names and not locks_of(one, "ram-2")


def test_an_added_cable_plugs_into_the_gpu_behind_the_panel_as_on_lab_computer_a(lab_b):
    variant = disassembly_variant(lab_b, 0, replace(STILL, ram_sticks=(2, 2), gpu_cables=(2, 2)))
    for cable in ("gpu-cable-1", "gpu-cable-2"):
        assert locks_of(variant, cable) == {("side-panel", cable), (cable, "gpu")}
    lab_a = load_spec(DATA / "lab-computer-a.json")
    pose_a = dict(zip(lab_a.component_names, lab_a.poses_in_world(), strict=True))
    pose = dict(zip(variant.component_names, variant.poses_in_world(), strict=True))
    np.testing.assert_allclose(pose["gpu-cable-1"] - pose["gpu"], pose_a["gpu-cable"] - pose_a["gpu"], atol=1e-6)


def test_without_jitter_and_with_the_same_counts_the_variant_is_the_computer(lab_b):
    same = disassembly_variant(lab_b, 3, replace(STILL, ram_sticks=(2, 2), gpu_cables=(0, 0)))
    assert [(c.name, c.kind) for c in same.components] == [(c.name, c.kind) for c in lab_b.components]
    assert same.locks == lab_b.locks
    np.testing.assert_allclose(same.poses_in_world(), lab_b.poses_in_world(), atol=1e-6)  # the file's precision


def test_every_pose_is_jittered_by_about_its_sigma(lab_b):
    config = replace(VariantConfig(), ram_sticks=(2, 2), gpu_cables=(0, 0))
    base = lab_b.poses_in_world()
    shifts, turns = [], []
    for seed in range(40):
        poses = disassembly_variant(lab_b, seed, config).poses_in_world()
        shifts.append(poses[:, :3] - base[:, :3])
        turns.append((Rotation.from_euler("xyz", base[:, 3:]).inv() * Rotation.from_euler("xyz", poses[:, 3:]))
                     .as_rotvec())  # fmt: skip
    assert np.std(shifts) == pytest.approx(config.position_sigma, rel=0.15)
    assert np.std(turns) == pytest.approx(config.angle_sigma, rel=0.15)


def test_bad_ranges_and_a_puzzle_box_are_refused(lab_b, spec_dict):
    from puzzlebox.models import spec_from_dict

    with pytest.raises(ValueError, match="at least one RAM stick"):
        VariantConfig(ram_sticks=(0, 2))
    with pytest.raises(ValueError, match="inclusive range"):
        VariantConfig(gpu_cables=(2, 1))
    with pytest.raises(ValueError, match="puzzle box"):
        disassembly_variant(spec_from_dict(spec_dict), 0)
