"""Parts that strike each other as they move break a spec by geometry: the check finds them, and the generators
draw boxes without them."""

from __future__ import annotations

import pytest

from puzzlebox.models.box_export import compile_box
from puzzlebox.models.generator import RandomGraphConfig, generate_random, paper_family
from puzzlebox.models.kinds import family_named
from puzzlebox.models.lock_check import check_locks
from puzzlebox.models.part_clearance import meeting_parts
from puzzlebox.models.spec_loading import spec_from_dict

# random-n8-s49 as generate.py random --components 8 --kinds all drew it before parts were checked: an open door-0's
# handle stands in door-7's sweep (only the parts that matter kept; the box, poses and locks as drawn)
STRIKING = {
    "format": "puzzlebox-spec/1",
    "name": "door-handle-in-a-sweep",
    "box": {"size": [0.32, 0.272, 0.08], "pose": [0.45, 0.0, 0.0]},
    "components": [
        {"name": "door-0", "kind": "door", "pose": [0.014, 0.0, 0.0], "marker": 0},
        {"name": "drawer-2", "kind": "drawer", "pose": [0.114, 0.0, 0.0], "marker": 2},
        {"name": "door-7", "kind": "door", "pose": [-0.076, 0.005, -1.570796], "marker": 7},
    ],
    "locks": [],
    "goal": {"component": "door-7", "state": 1},
}


def test_an_open_doors_handle_in_a_neighbours_sweep_is_found_and_stops_the_neighbour():
    spec = spec_from_dict(STRIKING)
    assert meeting_parts(spec) == [("door-0", "door-7")]
    model, joints = compile_box(spec, "latch")  # no lock at all: only the parts' own geometry
    stopped = [t for t in check_locks(spec, model, joints).transitions if t.component == "door-7" and t.moved < 0.75]
    assert stopped and all(t.state & 1 for t in stopped)  # door-7 stops only with door-0 open


def test_the_same_doors_apart_clear():
    data = {**STRIKING, "components": [{**c, "pose": [-0.1, 0.005, -1.570796]} if c["name"] == "door-7" else c
                                       for c in STRIKING["components"]]}  # fmt: skip
    assert meeting_parts(spec_from_dict(data)) == []


@pytest.mark.parametrize("split", ["train", "test"])
def test_the_paper_boxes_parts_clear(split):
    for spec in paper_family(split):
        assert meeting_parts(spec) == [], spec.name


def test_the_generator_draws_boxes_whose_parts_clear():
    spec = generate_random(RandomGraphConfig(8, family=family_named("all")), seed=49)
    assert meeting_parts(spec) == []
