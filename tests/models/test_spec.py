import json

import pytest

from puzzlebox.models import SPEC_FORMAT, SpecError, load_spec, save_spec, spec_from_dict, spec_from_json
from puzzlebox.models.generator import RandomGraphConfig, generate_random, paper_family


def test_spec_example_loads_with_its_fields(spec_dict):
    spec = spec_from_dict(spec_dict)
    assert spec.name == "paper-test-0"
    assert spec.box.size == (0.40, 0.30, 0.08) and spec.box.pose == (0.45, 0.0, 0.0)
    assert spec.component_names == ("door-1", "slide-1")
    assert spec.components[1].pose == (-0.02, 0.05, 1.5708)
    assert spec.goal.component == "slide-1" and spec.goal.state == 1
    assert spec.locks[1].locker == "slide-1" and spec.locks[1].locker_state == 1


def test_round_trip_through_json_gives_the_same_spec_and_bytes(tmp_path):
    for spec in [*paper_family("all"), generate_random(RandomGraphConfig(8, multi_locker=True), seed=4)]:
        path = save_spec(spec, tmp_path / f"{spec.name}.json")
        again = load_spec(path)
        assert again == spec
        assert again.to_json() == path.read_text()


def test_written_json_matches_the_contract_keys(spec_dict):
    data = json.loads(spec_from_dict(spec_dict).to_json())
    assert data["format"] == SPEC_FORMAT
    assert list(data) == ["format", "name", "box", "components", "locks", "goal"]
    assert set(data["components"][0]) == {"name", "kind", "pose", "marker"}
    assert set(data["locks"][0]) == {"locker", "locker_state", "locked", "locked_state"}


def test_missing_markers_are_assigned_unique_unused_ids(spec_dict):
    spec_dict["components"][0].pop("marker")
    spec_dict["components"][1]["marker"] = 0
    spec = spec_from_dict(spec_dict)
    assert sorted(c.marker for c in spec.components) == [0, 1]


def test_goal_state_defaults_to_open(spec_dict):
    del spec_dict["goal"]["state"]
    assert spec_from_dict(spec_dict).goal.state == 1


def test_unknown_extra_fields_are_tolerated(spec_dict):
    spec_dict["author"] = "someone"  # SPEC.md: new optional fields may be added
    spec_dict["components"][0]["colour"] = "red"
    assert spec_from_dict(spec_dict).name == "paper-test-0"


def test_shuffled_lists_and_renamed_components_describe_the_same_puzzle(spec_dict):
    from puzzlebox.models import LockTable

    renamed = json.loads(json.dumps(spec_dict).replace("door-1", "A").replace("slide-1", "B"))
    renamed["components"].reverse()
    renamed["locks"].reverse()
    a, b = LockTable.from_spec(spec_from_dict(spec_dict)), LockTable.from_spec(spec_from_dict(renamed))
    assert len(a.shortest_solution()) == len(b.shortest_solution()) == 2


def test_save_is_atomic_and_leaves_no_temporary_file(tmp_path, spec_dict):
    path = save_spec(spec_from_dict(spec_dict), tmp_path / "deep" / "dir" / "x.json")
    assert path.exists() and not list(path.parent.glob("*.tmp"))


def test_unreadable_file_is_a_spec_error_not_a_traceback(tmp_path):
    with pytest.raises(SpecError, match="cannot read"):
        load_spec(tmp_path / "missing.json")
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe\x00garbage")
    with pytest.raises(SpecError):
        load_spec(tmp_path / "bin.json")


def test_invalid_text_never_builds_a_spec():
    with pytest.raises(SpecError) as info:
        spec_from_json('{"format": "puzzlebox-spec/1"}')
    fields = {p.where for p in info.value.problems}
    assert {"name", "components", "locks", "goal"} <= fields
