"""A try's outcome as a type: every cause is named by one text the hand writes, a cause fits its outcome, and a
record written before causes were kept loads with the cause its text names."""

from __future__ import annotations

import pytest

from puzzlebox.lab.trial_record import TrialRecord
from puzzlebox.models.try_outcome import Cause, TryResult

# one text of each cause, as the hand and the world write them (skills/primitives.py, door_push.py, robot_world.py)
WRITTEN = {
    "ForceLimitExceeded: force limit: 72 N > 60 N while descending, motion stopped": Cause.FORCE_LIMIT,
    "IKFailure: TCP target [0.7, 0.1, 0.2] not reached: out of reach": Cause.UNREACHABLE,
    "GraspFailure: the gripper closed on nothing at [0.4, 0.0, 0.1] (3 attempts)": Cause.GRASP_EMPTY,
    "SlipDetected: the handle slipped out of the grasp after 40% of the travel": Cause.SLIPPED,
    "SlipDetected: the part was not seen": Cause.MARKER_LOST,
    "SlipDetected: the handle moved but the part is not back at its closed pose": Cause.NOT_BACK_CLOSED,
    "SlipDetected: the handle moved but the marker did not": Cause.MARKER_STILL,
    "SlipDetected: the door stayed shut (2% of its travel)": Cause.DOOR_STAYED_SHUT,
    "SlipDetected: the part stands at 55% of its travel": Cause.STANDS_PART_WAY,
    "IncompleteTravel: only 61% of the travel covered; pushed on under its plate: x": Cause.INCOMPLETE_TRAVEL,
    "Jammed: the door held at 40% of its travel": Cause.JAMMED,
    "latched: held part-way (33% of the travel)": Cause.HELD_PART_WAY,
    "latched: force rose without progress": Cause.LOCKED_NO_PROGRESS,
    "latched: pulled without progress (also tried as door, wheel)": Cause.LOCKED_PULLED,
    "latched: held until the grasp slipped": Cause.LOCKED_SLIPPED_OFF,
    "latched: pushed without progress": Cause.LOCKED_PUSHED,
    "latched: the pad slid along its handle": Cause.LOCKED_PAD_SLID,
    "latched: the door stayed shut under the pinch and the push": Cause.LOCKED_PINCH_AND_PUSH,
}


def test_every_cause_is_read_back_from_the_text_it_was_written_as():
    assert set(WRITTEN.values()) == set(Cause), "a cause without a text here"
    for text, cause in WRITTEN.items():
        assert Cause.from_legacy(text) is cause, text
        assert text.startswith(cause.prefix)
    assert Cause.from_legacy("") is None and Cause.from_legacy("could not try door-1") is None


def test_a_cause_must_fit_its_outcome():
    assert TryResult("blocked", cause=Cause.HELD_PART_WAY).cause.family == "locked"
    assert TryResult("failed", cause=Cause.GRASP_EMPTY).informative is False
    for outcome, cause in (("moved", Cause.GRASP_EMPTY), ("failed", Cause.LOCKED_PUSHED), ("blocked", Cause.JAMMED)):
        with pytest.raises(ValueError, match="cannot be caused by"):
            TryResult(outcome, cause=cause)
    assert TryResult("blocked").cause is None  # a symbolic world says no more than blocked


def _entry(**action):
    return {"spec": "paper-test-0", "seed": 3, "solved": False, "num_actions": 1, "wall_time_s": 1.0,
            "actions": [{"component": "door-1", "moved": False, "outcome": "blocked", **action}]}  # fmt: skip


def test_a_record_keeps_its_causes_and_an_old_one_loads_with_the_cause_its_text_names():
    new = TrialRecord.from_dict(_entry(reason="latched: pushed without progress", cause="locked_pushed"))
    assert new.actions[0].cause is Cause.LOCKED_PUSHED
    assert TrialRecord.from_dict(new.to_dict()) == new and new.to_dict()["actions"][0]["cause"] == "locked_pushed"
    old = TrialRecord.from_dict(_entry(reason="latched: held part-way (33% of the travel)"))
    assert old.actions[0].cause is Cause.HELD_PART_WAY and old.actions[0].reason.endswith("(33% of the travel)")
    symbolic = TrialRecord.from_dict(_entry(reason="", cause=None))
    assert symbolic.actions[0].cause is None
    with pytest.raises(ValueError):
        TrialRecord.from_dict(_entry(reason="", cause="on_fire"))


def test_the_worlds_result_is_carried_to_the_record_as_it_was_returned():
    # the result changes type once between the world and the record's dict: the run's action holds the very object
    from puzzlebox.learning import DualAgent, SymbolicWorld, run_episode
    from puzzlebox.models.generator import paper_family

    spec = paper_family("test")[0]
    returned: list[TryResult] = []

    class Recording(SymbolicWorld):
        def try_toggle(self, index: int) -> TryResult:
            returned.append(super().try_toggle(index))
            return returned[-1]

    run = run_episode(DualAgent(), Recording(spec, 0), spec.name, 0, max_actions=30)
    assert run.solved and [a.result for a in run.actions] == returned
    assert all(a.result is r for a, r in zip(run.actions, returned, strict=True))


@pytest.mark.parametrize("cause", list(Cause))
def test_every_result_round_trips_through_the_record(cause):
    result = TryResult("blocked" if cause.family == "locked" else "failed", f"text of {cause.value}", cause=cause)
    record = TrialRecord.from_dict(_entry(reason=result.reason, cause=cause.value, outcome=result.outcome))
    assert record.actions[0].result == result
    assert TrialRecord.from_dict(record.to_dict()) == record


def test_an_old_record_without_outcomes_loads_as_it_moved_and_a_cause_that_does_not_fit_is_dropped():
    old = _entry(reason="latched: force rose without progress")
    del old["actions"][0]["outcome"]  # (moved: False)
    assert TrialRecord.from_dict(old).actions[0].outcome == "blocked"
    failed = _entry(reason="latched: held part-way (33% of the travel)", outcome="failed")
    assert TrialRecord.from_dict(failed).actions[0].cause is None  # (a lock's text on a failed try: no cause)
