"""Spec v1 with 6-DOF poses: disassembly scenes (issue 14, part 1) beside the unchanged puzzle boxes."""

from __future__ import annotations

import copy
import json
import random
from pathlib import Path
from typing import Any

import pytest
from conftest import SCENE_EXAMPLE, SPEC_EXAMPLE

from puzzlebox.models import LockTable, SpecError, load_spec, spec_from_dict, validate_data
from puzzlebox.models.disassembly_kinds import (
    ALLOWED_LOCKS,
    DISASSEMBLY_KIND_NAMES,
    DISASSEMBLY_KINDS,
    family_kind_names,
    kind_family,
    may_lock,
)
from puzzlebox.models.kinds import KIND_NAMES

DATA = Path(__file__).resolve().parents[3] / "shared" / "data" / "disassembly"
LAB_COMPUTERS = ("lab-computer-a.json", "lab-computer-b.json")

needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"{DATA} (the shared disassembly data) is absent")


def _scene() -> dict[str, Any]:
    """A small disassembly scene: two screws hold the panel, the panel holds the RAM, which holds the board."""
    return copy.deepcopy(SCENE_EXAMPLE)


def _problems(data: Any) -> list[str]:
    return [str(p) for p in validate_data(data)]


@needs_data
@pytest.mark.parametrize("file", LAB_COMPUTERS)
def test_both_lab_computers_load_and_validate(file):
    data = json.loads((DATA / file).read_text())
    assert validate_data(data) == []
    spec = load_spec(DATA / file)
    assert spec.family == "disassembly" and spec.box is None
    assert all(len(c.pose) == 6 for c in spec.components)
    assert len(LockTable.from_spec(spec).shortest_solution()) == 8  # every part out, once each
    assert spec.poses_in_world().shape == (len(spec.components), 6)


@needs_data
def test_the_families_relations_cover_both_lab_computers():
    for file in LAB_COMPUTERS:
        spec = load_spec(DATA / file)
        kind = dict(zip(spec.component_names, spec.kinds, strict=True))
        assert set(spec.kinds) <= set(DISASSEMBLY_KINDS)
        for rule in spec.locks:
            assert may_lock(kind[rule.locker], kind[rule.locked]), rule


def test_the_kind_families_are_separate():
    assert KIND_NAMES == ("door", "slide", "wheel")  # the puzzle-box codes are unchanged
    assert not set(KIND_NAMES) & set(DISASSEMBLY_KIND_NAMES)
    assert {kind_family(k) for k in KIND_NAMES} == {"puzzle-box"}
    assert {kind_family(k) for k in DISASSEMBLY_KIND_NAMES} == {"disassembly"}
    assert all(a in DISASSEMBLY_KINDS and b in DISASSEMBLY_KINDS for a, b in ALLOWED_LOCKS)
    assert may_lock("screw", "panel") and not may_lock("panel", "screw")
    assert family_kind_names(["ram", "screw"]) == DISASSEMBLY_KIND_NAMES
    assert family_kind_names(["door"]) == KIND_NAMES
    with pytest.raises(ValueError, match="mix"):
        family_kind_names(["door", "ram"])


def _lock_graph(spec) -> set[tuple[str, int, str, int]]:
    """The lock rules with names replaced by kind + position (the puzzle up to renaming and order)."""
    label = {c.name: (c.kind, tuple(round(v, 6) for v in c.pose)) for c in spec.components}
    return {(label[r.locker], r.locker_state, label[r.locked], r.locked_state) for r in spec.locks}


@pytest.mark.parametrize("seed", range(5))
def test_shuffled_and_renamed_scene_is_the_same_puzzle(seed):
    data = _scene()
    rng = random.Random(seed)
    other = copy.deepcopy(data)
    rename = {c["name"]: f"part-{rng.randrange(10**6)}-{k}" for k, c in enumerate(other["components"])}
    for c in other["components"]:
        c["name"] = rename[c["name"]]
    for r in other["locks"]:
        r["locker"], r["locked"] = rename[r["locker"]], rename[r["locked"]]
    other["goal"]["component"] = rename[other["goal"]["component"]]
    rng.shuffle(other["components"])
    rng.shuffle(other["locks"])
    a, b = spec_from_dict(data), spec_from_dict(other)
    assert _lock_graph(a) == _lock_graph(b)
    assert len(LockTable.from_spec(a).shortest_solution()) == len(LockTable.from_spec(b).shortest_solution()) == 5


def test_a_component_with_several_lockers_moves_only_when_none_holds_it():
    spec = spec_from_dict(_scene())
    table = LockTable.from_spec(spec)
    panel = spec.index_of("panel")
    one_screw_out = 1 << spec.index_of("s1")
    assert not table.can_move(one_screw_out, panel)
    assert table.can_move(one_screw_out | 1 << spec.index_of("s2"), panel)


def test_unreachable_goal_in_a_scene_is_rejected():
    data = _scene()
    data["locks"].append({"locker": "board", "locker_state": 0, "locked": "s1", "locked_state": 0})
    data["locks"].append({"locker": "board", "locker_state": 0, "locked": "s2", "locked_state": 0})
    assert any(p.startswith("goal: unreachable") for p in _problems(data))


def test_generic_rules_still_apply_to_scenes():
    data = _scene()
    data["components"][1]["name"] = "s1"
    data["locks"].append({"locker": "panel", "locker_state": 2, "locked": "panel", "locked_state": 0})
    data["goal"]["component"] = "nothing"
    problems = _problems(data)
    assert any(p.startswith("component 's1'") and "duplicate name" in p for p in problems)
    assert any(p.startswith("locks[4].locker_state") for p in problems)
    assert any(p.startswith("locks[4]:") and "locks itself" in p for p in problems)
    assert any(p.startswith("goal.component") for p in problems)


@pytest.mark.parametrize("pose", [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0], [0, 0, 0, 0, 0, 0, 0], "here"])
def test_a_scene_pose_of_the_wrong_length_names_the_component(pose):
    data = _scene()
    data["components"][3]["pose"] = pose
    problems = _problems(data)
    assert len(problems) == 1
    assert problems[0].startswith("component 'ram'.pose") and "6-DOF" in problems[0]


def test_a_6dof_pose_on_a_door_is_rejected(spec_dict):
    spec_dict["components"][0]["pose"] = [-0.12, 0.05, 0.0, 0.0, 0.0, 0.0]
    problems = _problems(spec_dict)
    assert len(problems) == 1
    assert problems[0].startswith("component 'door-1'.pose") and "6-DOF pose on puzzle-box kind 'door'" in problems[0]


def test_a_disassembly_kind_in_a_box_spec_is_rejected(spec_dict):
    spec_dict["components"].append({"name": "ram-1", "kind": "ram", "pose": [0.1, -0.1, 0.0, 0, 0, 0]})
    problems = _problems(spec_dict)
    assert len(problems) == 1
    assert (
        problems[0].startswith("component 'ram-1'.kind")
        and "disassembly kind 'ram' in a puzzle-box spec" in problems[0]
    )


def test_a_scene_mixing_families_names_the_component():
    data = _scene()
    data["components"].append({"name": "door-1", "kind": "door", "pose": [0.0, 0.0, 0.0]})
    problems = _problems(data)
    assert len(problems) == 1  # no "box missing": the spec is a disassembly scene
    assert (
        problems[0].startswith("component 'door-1'.kind")
        and "puzzle-box kind 'door' in a disassembly scene" in (problems[0])
    )


def test_an_unknown_kind_lists_both_families():
    data = _scene()
    data["components"][0]["kind"] = "fan"
    (problem,) = _problems(data)
    assert problem.startswith("component 's1'.kind") and "'screw'" in problem and "'door'" in problem


def test_every_problem_is_listed_at_once():
    data = _scene()
    data["components"][0]["pose"] = [0.0]
    data["components"].append({"name": "d", "kind": "door", "pose": [0, 0, 0]})
    data["locks"].append({"locker": "ghost", "locker_state": 0, "locked": "ram", "locked_state": 0})
    with pytest.raises(SpecError) as err:
        spec_from_dict(data)
    wheres = {p.where for p in err.value.problems}
    assert wheres == {"component 's1'.pose", "component 'd'.kind", "locks[4].locker"}


def test_a_scene_round_trips_through_its_json():
    spec = spec_from_dict(_scene())
    from puzzlebox.models import spec_from_json

    again = spec_from_json(spec.to_json())
    assert again == spec and again.family == "disassembly"


def test_the_spec_example_is_still_a_puzzle_box():
    spec = spec_from_dict(copy.deepcopy(SPEC_EXAMPLE))
    assert spec.family == "puzzle-box"
