"""The twin's hard test sets (issue 36): eight-part boxes of every kind, deterministic, valid, reachable, held out
from training, with their optimum; one of them solved end to end in the twin at a placement of its own."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.lab import TrialConfig, run_trial
from puzzlebox.lab.hard_sets import (
    FAMILY_NAMES,
    HardSetConfig,
    family_of,
    hard_box,
    hard_test_set,
    hard_training_set,
    optimum,
)
from puzzlebox.lab.learning_boxes import LearningBox
from puzzlebox.lab.learning_optimum import family_table, with_optimum
from puzzlebox.models import LockTable
from puzzlebox.models.kinds import registered_kinds
from puzzlebox.models.placement import placed, sample_reachable_pose
from puzzlebox.models.reach import unreachable_handles
from puzzlebox.models.validation import validate_data


@pytest.fixture(scope="module")
def first_test_boxes():
    """Test box 0 of every hard family (generating one takes seconds: the mechanism design search)."""
    return {name: hard_test_set(name, 1)[0] for name in FAMILY_NAMES}


def test_every_hard_box_has_eight_valid_parts_in_reach_and_its_familys_locks(first_test_boxes):
    for name, spec in first_test_boxes.items():
        assert len(spec.components) == 8 and spec.name == f"hard-{name}-s36000"
        assert validate_data(spec.to_dict()) == []
        assert spec.box is not None and spec.box.pose is not None
        assert unreachable_handles(spec, spec.box.pose) == []  # where it was generated, and where the twin puts it:
        pose = sample_reachable_pose(spec, np.random.default_rng(0))
        assert unreachable_handles(spec, pose) == []
        assert {c.kind for c in spec.components} <= set(registered_kinds())
        assert family_of(spec).name == name
    lockers = {}
    for rule in first_test_boxes["multi8"].locks:
        if rule.locked_state == 0:
            lockers.setdefault(rule.locked, set()).add(rule.locker)
    assert max(len(held) for held in lockers.values()) == 2  # some part is held by two lockers
    chain = first_test_boxes["chain8"]
    assert optimum(chain) == 8 == len(LockTable.from_spec(chain).shortest_solution() or [])


def test_a_hard_box_is_a_pure_function_of_its_family_and_seed(first_test_boxes):
    assert hard_box("chain8", 36_000).to_json() == first_test_boxes["chain8"].to_json()


def test_the_test_boxes_are_held_out_from_training():
    with pytest.raises(ValueError, match="held out"):
        HardSetConfig(test_seed=10, train_seed=0)
    config = HardSetConfig(test_seed=0, train_seed=5000, max_boxes=2)
    with pytest.raises(ValueError, match="0..2 boxes"):
        hard_training_set("random8", 3, config)
    with pytest.raises(ValueError, match="families"):
        hard_box("random9", 0)


def test_each_point_of_the_curve_carries_its_optimum_and_each_familys_figures(first_test_boxes):
    tests = [LearningBox(s, name, 2 if name == "multi8" else 1, optimum(s)) for name, s in first_test_boxes.items()]
    trials = {
        f"a-{box.family}": {"spec": box.spec.name, "solved": True, "num_actions": box.optimum + 1,
                            "peak_true_wrist_force_n": 30.0 + i}
        for i, box in enumerate(tests)
    }  # fmt: skip
    trials["a-chain8"]["solved"] = False  # an unsolved trial counts the budget
    where = {k: ("symbolic", 0, 0.0) for k in trials}
    summary = with_optimum({"points": [{"start": "symbolic", "hours": 0.0, "mean_actions": 10.0}]}, trials, where,
                           tests, max_actions=40)  # fmt: skip
    point = summary["points"][0]
    assert point["optimum"] == pytest.approx(np.mean([b.optimum for b in tests]))
    assert point["ratio_to_optimum"] == pytest.approx(10.0 / point["optimum"])
    assert point["peak_true_wrist_force_n"] == 32.0
    assert point["sets"]["chain8"] == {"trials": 1, "success_rate": 0.0, "mean_actions": 40.0, "optimum": 8.0}
    assert [b["max_lockers"] for b in summary["test_boxes"]] == [1, 2, 1]
    assert "| symbolic | 0 | " in "\n".join(family_table(summary))


def test_a_hard_box_is_solved_end_to_end_in_the_twin_at_a_placement_of_its_own():
    spec = hard_box("random8", 5004)  # a validation box (neither a test nor a training box): doors, slides, a lever
    pose = sample_reachable_pose(spec, np.random.default_rng(3636))
    record = run_trial(placed(spec, pose), TrialConfig(agent="oracle", seed=3636, max_actions=optimum(spec)))
    assert record.solved and record.num_actions == optimum(spec) == 5, record.ended
    assert record.box_pose == pytest.approx(pose)
    assert all(a.moved for a in record.actions)
    assert record.peak_true_wrist_force_n is not None and record.peak_true_wrist_force_n <= 45.0
