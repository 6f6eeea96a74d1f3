"""One test per validation rule of SPEC.md, plus 'every problem at once' and 'never raises'."""

import json

import pytest
from conftest import SPEC_EXAMPLE
from hypothesis import given, settings
from hypothesis import strategies as st

from puzzlebox.models import SpecError, spec_from_dict, spec_from_json, validate_data


def problems_of(data):
    return [str(p) for p in validate_data(data)]


def only_problem(data, *fragments):
    found = problems_of(data)
    assert len(found) == 1, found
    for fragment in fragments:
        assert fragment in found[0], found
    return found[0]


def test_the_spec_example_is_valid(spec_dict):
    assert validate_data(spec_dict) == []


def test_non_json_input_is_one_problem_naming_the_position():
    with pytest.raises(SpecError) as info:
        spec_from_json("{not json")
    (problem,) = info.value.problems
    assert problem.where == "file" and "line 1" in problem.message


def test_top_level_must_be_an_object():
    only_problem([1, 2], "file", "object")


def test_wrong_format_is_rejected(spec_dict):
    spec_dict["format"] = "puzzlebox-spec/2"
    only_problem(spec_dict, "format", "puzzlebox-spec/2")


def test_missing_format_is_rejected(spec_dict):
    del spec_dict["format"]
    only_problem(spec_dict, "format", "missing")


def test_unknown_kind_names_the_component_and_lists_known_kinds(spec_dict):
    spec_dict["components"][0]["kind"] = "trapdoor"
    only_problem(spec_dict, "'door-1'", "trapdoor", "door", "slide", "wheel", "lever", "drawer")


def test_duplicate_names_are_rejected(spec_dict):
    spec_dict["components"][1]["name"] = "door-1"
    spec_dict["components"][1]["pose"] = [0.08, 0.05, 0.0]
    found = problems_of(spec_dict)
    assert any("duplicate name 'door-1'" in p for p in found), found


def test_lock_to_an_unknown_component_is_rejected(spec_dict):
    spec_dict["locks"][0]["locked"] = "wheel-9"
    only_problem(spec_dict, "locks[0].locked", "wheel-9", "door-1")


@pytest.mark.parametrize("bad", [2, -1, "1", True, None, 0.5])
def test_lock_state_must_be_zero_or_one(spec_dict, bad):
    spec_dict["locks"][1]["locker_state"] = bad
    only_problem(spec_dict, "locks[1].locker_state")


def test_goal_state_must_be_zero_or_one(spec_dict):
    spec_dict["goal"]["state"] = 3
    only_problem(spec_dict, "goal.state")


def test_self_lock_is_rejected(spec_dict):
    spec_dict["locks"][0]["locked"] = "door-1"
    only_problem(spec_dict, "locks[0]", "locks itself")


def test_missing_goal_is_rejected(spec_dict):
    del spec_dict["goal"]
    only_problem(spec_dict, "goal", "missing")


def test_goal_naming_an_unknown_component_is_rejected(spec_dict):
    spec_dict["goal"]["component"] = "nowhere"
    only_problem(spec_dict, "goal.component", "nowhere")


def test_overlapping_components_are_rejected(spec_dict):
    spec_dict["components"][1]["pose"] = [-0.10, 0.05, 0.0]  # 2 cm from the door's centre
    only_problem(spec_dict, "overlaps", "door-1", "slide-1")


def test_touching_components_do_not_overlap(spec_dict):
    # door spans x in [-0.155, -0.074]; a slide at yaw 0 spans [x-0.041, x+0.075]: touching at x=-0.033
    spec_dict["components"][1]["pose"] = [-0.033, 0.05, 0.0]
    assert validate_data(spec_dict) == []


def test_component_outside_the_lid_is_rejected(spec_dict):
    spec_dict["components"][0]["pose"] = [-0.19, 0.05, 0.0]  # half-length 0.2, door half-side 0.035
    only_problem(spec_dict, "'door-1'", "beyond the lid")


def test_puzzle_box_needs_a_box(spec_dict):
    del spec_dict["box"]
    only_problem(spec_dict, "box", "missing")


def test_box_size_must_be_positive(spec_dict):
    spec_dict["box"]["size"] = [0.4, 0.0, 0.08]
    only_problem(spec_dict, "box.size")


def test_unreachable_goal_is_rejected(spec_dict):
    # slide-1 closed keeps door-1 closed and door-1 closed keeps slide-1 closed: a deadlock
    spec_dict["locks"][1] = {"locker": "slide-1", "locker_state": 0, "locked": "door-1", "locked_state": 0}
    only_problem(spec_dict, "goal", "unreachable")


def test_bad_pose_is_rejected(spec_dict):
    spec_dict["components"][0]["pose"] = [0.0, float("nan"), 0.0]
    only_problem(spec_dict, "'door-1'.pose")
    spec_dict["components"][0]["pose"] = [0.0, 0.0]
    only_problem(spec_dict, "'door-1'.pose")


def test_duplicate_marker_ids_are_rejected(spec_dict):
    spec_dict["components"][1]["marker"] = 0
    only_problem(spec_dict, "marker", "already used", "door-1")


def test_a_marker_id_outside_the_dictionary_is_rejected(spec_dict):
    spec_dict["components"][1]["marker"] = 250  # DICT_4X4_250 has ids 0..249: the twin cannot render it
    only_problem(spec_dict, "marker", "250", "0..249")
    spec_dict["components"][1]["marker"] = 249
    assert validate_data(spec_dict) == []


def test_a_duplicate_lock_is_rejected(spec_dict):
    spec_dict["locks"].append(dict(spec_dict["locks"][0]))
    only_problem(spec_dict, f"locks[{len(spec_dict['locks']) - 1}]", "duplicates locks[0]")


def test_a_duplicate_json_key_is_rejected(spec_dict):
    text = json.dumps(spec_dict)
    doubled = text.replace('"goal": {', '"goal": {"component": "slide-1", ', 1)  # two "component" keys
    assert doubled != text
    with pytest.raises(SpecError) as info:
        spec_from_json(doubled)
    (problem,) = info.value.problems
    assert problem.where == "file" and "duplicate key 'component'" in problem.message
    spec_from_json(text)  # the same spec without the duplicate loads


def test_every_problem_is_listed_at_once(spec_dict):
    spec_dict["format"] = "other"
    spec_dict["components"][0]["kind"] = "trapdoor"
    spec_dict["locks"][0]["locked_state"] = 7
    spec_dict["goal"]["component"] = "ghost"
    with pytest.raises(SpecError) as info:
        spec_from_dict(spec_dict)
    where = [p.where for p in info.value.problems]
    assert len(where) == 4, where
    assert "format" in where and "goal.component" in where
    assert all(f"  - {p}" in str(info.value) for p in info.value.problems)


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=10), children, max_size=5),
    max_leaves=20,
)


@settings(max_examples=300, deadline=None)
@given(json_values)
def test_validation_never_raises_on_arbitrary_json(value):
    assert isinstance(validate_data(value), list)


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_validation_never_raises_on_mutated_specs(data):
    # Replace one field anywhere in a valid spec by an arbitrary JSON value.
    mutated = json.loads(json.dumps(SPEC_EXAMPLE))
    target = mutated
    path = data.draw(
        st.sampled_from(
            [
                ("format",),
                ("box", "size"),
                ("components", 0, "pose"),
                ("locks", 1),
                ("goal", "component"),
                ("components", 1),
                ("box",),
                ("name",),
            ]
        )
    )
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = data.draw(json_values)
    assert isinstance(validate_data(mutated), list)
