"""A door's pushes judged (skills/door_judgement.py) on readings made up tick by tick: no simulator behind them."""

import math

import pytest

from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.door_judgement import (
    ClosingLimits,
    ClosingReading,
    ClosingTrace,
    SwingLimits,
    SwingReading,
    SwingTrace,
    judge_closing,
    judge_swing,
)
from puzzlebox.skills.settings import DoorPushJudgement, JudgementConfig

JUDGEMENT, PUSH = JudgementConfig(), DoorPushJudgement()
TRAVEL = math.radians(85.0)


def limits(start: float = 0.0) -> SwingLimits:
    """A swing from ``start`` pressed from 3 N, held after 3 deg of sliding, slid after 7 deg, a 5-tick stall."""
    return SwingLimits(start, 3.0, math.radians(3.0) / TRAVEL, math.radians(7.0) / TRAVEL, 5)


def pressed(progress: list[float], faces: list[float], normal: float = 6.0, opposing: float = 4.0):
    return [SwingReading(p, f, normal, opposing, normal) for p, f in zip(progress, faces, strict=True)]


def swing(readings, start: float = 0.0, ended_at: float | None = None):
    return judge_swing(SwingTrace(limits(start), tuple(readings), ended_at), JUDGEMENT, PUSH)


def test_a_door_whose_face_turns_with_the_pad_to_its_stop_is_moved():
    steps = [k / 20 for k in range(23)]
    judgement = swing(pressed(steps, steps), ended_at=1.05)
    assert (judgement.outcome, judgement.cause) == ("moved", None)


def test_a_pad_sliding_along_a_face_that_does_not_turn_is_a_latch_or_a_jam():
    steps = [k / 100 for k in range(12)]  # the pad turns 11 % (9 deg) along a face standing still
    latched = swing(pressed(steps, [0.0] * 12))
    assert (latched.outcome, latched.cause) == ("blocked", Cause.LOCKED_PAD_SLID)
    jammed = swing(pressed([0.3 + p for p in steps], [0.3] * 12), start=0.3)
    assert (jammed.outcome, jammed.cause, jammed.held_at) == ("failed", Cause.JAMMED, 0.3)  # no evidence


def test_a_door_pushed_hard_before_a_tenth_of_its_travel_is_pushed_in_vain():
    judgement = swing(pressed([0.0, 0.01], [0.0, 0.01]) + [SwingReading(0.02, 0.02, 31.0, 20.0, 31.0)])
    assert (judgement.outcome, judgement.cause) == ("blocked", Cause.LOCKED_PUSHED)


def test_a_face_that_stops_part_way_while_the_pad_goes_on_is_held_part_way_where_the_face_stands():
    steps = [k / 50 for k in range(16)]  # the face turns with the pad to 30 %
    on = [0.30 + k / 200 for k in range(1, 12)]  # the pad slides on 5.5 % (4.7 deg), the face stays
    judgement = swing(pressed(steps + on, steps + [0.30] * 11))
    assert (judgement.outcome, judgement.cause, judgement.held_at) == ("blocked", Cause.HELD_PART_WAY, 0.30)
    # the face read with the perception's offset (3 % of the travel, ~1 mm): where it stands is its turn since the
    # pad first pressed on it, not the offset reading
    offset = swing(pressed(steps + on, [f - 0.03 for f in steps + [0.30] * 11]))
    assert offset.cause is Cause.HELD_PART_WAY and offset.held_at == pytest.approx(0.30)


def test_a_pad_that_lost_the_face_early_is_judged_by_how_far_the_face_turned_while_pressed():
    readings = pressed([0.0, 0.02, 0.04], [0.0, 0.02, 0.04], opposing=6.0)
    readings += [SwingReading(p, p, 0.0, 0.0, 1.0) for p in (0.3, 0.6, 1.0)]  # then over the post, in the air
    judgement = swing(readings, ended_at=1.0)
    assert (judgement.outcome, judgement.cause, judgement.progress) == ("blocked", Cause.LOCKED_PUSHED, 0.04)
    with pytest.raises(ValueError, match="cut short"):
        swing(readings)


def test_a_closing_push_ends_on_the_lid_and_a_plate_that_does_not_give_is_a_latch():
    closing = ClosingLimits(start=0.0, contact=3.0)
    down = tuple(ClosingReading(k / 10, 4.0, 4.0) for k in range(10)) + (ClosingReading(0.98, 25.0, 25.0),)
    assert judge_closing(ClosingTrace(closing, down), JUDGEMENT, PUSH).outcome == "moved"
    held = (ClosingReading(0.0, 4.0, 4.0), ClosingReading(0.02, 21.0, 21.0))
    judgement = judge_closing(ClosingTrace(closing, held), JUDGEMENT, PUSH)
    assert (judgement.outcome, judgement.cause) == ("blocked", Cause.LOCKED_PUSHED)


def test_a_door_that_stood_part_way_and_will_not_go_on_under_a_hard_push_is_stuck():
    """Pushed on from 27 %, a door that does not turn further under 31 N on its face is stuck there (no evidence):
    the push stops, rather than pressing on until the pad slips off the handle (48-55 N without a calibration
    file)."""
    judgement = swing([SwingReading(0.28, 0.27, 6.0, 4.0, 6.0), SwingReading(0.29, 0.27, 31.0, 20.0, 31.0)], start=0.27)
    assert (judgement.outcome, judgement.cause, judgement.held_at) == ("failed", Cause.JAMMED, 0.27)
    # a door held there stands still as the pad meets it: read at ``jam_force`` (20 N), under ``blocked_force``
    light = swing([SwingReading(0.28, 0.27, 6.0, 4.0, 6.0), SwingReading(0.28, 0.27, 21.0, 8.0, 21.0)], start=0.27)
    assert (light.outcome, light.cause) == ("failed", Cause.JAMMED)
    closed = [SwingReading(0.02, 0.01, 6.0, 4.0, 6.0), SwingReading(0.02, 0.01, 21.0, 8.0, 21.0)]
    with pytest.raises(ValueError, match="cut short"):  # from its start, 20 N ends nothing: the swing goes on
        swing(closed, start=0.0)
    free = swing(pressed([0.27 + k / 20 for k in range(16)], [0.27 + k / 20 for k in range(16)]), 0.27, 1.02)
    assert free.outcome == "moved"  # a light push that turns the door carries it on
