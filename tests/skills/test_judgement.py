"""The pinch's judgement (skills/judgement.py) on readings made up tick by tick: no simulator behind it."""

import math

import pytest

from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.judgement import Decision, PinchJudge, PinchLimits, PinchTrace, Reading, judge_pinch
from puzzlebox.skills.settings import JudgementConfig

CONFIG = JudgementConfig()
"""The defaults: moved from 75 %, held under 10 % at 20 N, a stall 1 % in 50 ms at 20 N, a slip 0.012 closure."""
LIMITS = PinchLimits(press_limit=math.inf, window=5, head_start=0.0, slip_ticks=26, grasp_closure=0.70)
"""A pull across its post (no press limit), a stall over 5 ticks, grasped at a closure of 0.70."""


def ramp(progress: list[float], opposing: float = 2.0, closure: float = 0.70, magnitude: float | None = None):
    """Readings of a handle carried through ``progress`` (one per tick), the command 2 % ahead."""
    load = opposing if magnitude is None else magnitude
    return [Reading(p + 0.02, opposing, load, p, closure) for p in progress]


def fold(readings, limits=LIMITS):
    judge = PinchJudge(CONFIG, limits)
    for r in readings:
        decision = judge.read(r)
        if decision is not Decision.GO_ON:
            return judge, decision
    return judge, Decision.GO_ON


def test_a_free_part_carried_to_its_end_is_moved():
    readings = ramp([k / 50 for k in range(51)])
    judge, decision = fold(readings)
    assert decision is Decision.GO_ON
    judgement = judge.verdict(1.0)
    assert (judgement.outcome, judgement.cause) == ("moved", None)
    assert judge_pinch(PinchTrace(LIMITS, tuple(readings), (), 1.0), CONFIG) == judgement


def test_force_rising_before_a_tenth_of_the_travel_is_a_lock():
    readings = ramp([0.0, 0.01, 0.02]) + ramp([0.03], opposing=21.0)
    _, decision = fold(readings)
    assert decision is Decision.HELD_EARLY
    judgement = judge_pinch(PinchTrace(LIMITS, tuple(readings)), CONFIG)
    assert (judgement.outcome, judgement.cause, judgement.peak_opposing_force) == (
        "blocked",
        Cause.LOCKED_NO_PROGRESS,
        21.0,
    )


def test_the_magnitude_alone_past_its_limit_is_a_lock_too():
    _, decision = fold(ramp([0.0, 0.02], opposing=5.0, magnitude=36.0))
    assert decision is Decision.HELD_EARLY


def test_a_handle_pressed_along_its_post_is_held_at_the_light_press_limit():
    pressed = PinchLimits(press_limit=10.0, window=5, head_start=0.0, slip_ticks=26, grasp_closure=0.70)
    assert fold(ramp([0.0, 0.02], opposing=12.0), pressed)[1] is Decision.HELD_EARLY
    assert fold(ramp([0.0, 0.02], opposing=12.0))[1] is Decision.GO_ON  # across the post 12 N is no lock


def test_a_stall_part_way_under_load_is_held_part_way_where_it_stopped():
    readings = ramp([k / 20 for k in range(7)]) + ramp([0.30] * 5, opposing=22.0)
    judge, decision = fold(readings)
    assert decision is Decision.HELD_PART_WAY
    judgement = judge.ended(decision)
    assert (judgement.outcome, judgement.cause, judgement.held_at) == ("blocked", Cause.HELD_PART_WAY, 0.30)


def test_a_stall_under_a_light_load_is_not_a_lock():
    readings = ramp([k / 20 for k in range(7)]) + ramp([0.30] * 10, opposing=15.0)
    assert fold(readings)[1] is Decision.GO_ON


def test_a_stall_where_the_head_start_puts_the_part_at_its_stop_ends_the_motion_there():
    started = PinchLimits(press_limit=math.inf, window=5, head_start=0.2, slip_ticks=26, grasp_closure=0.70)
    readings = ramp([k / 10 for k in range(6)]) + ramp([0.58] * 5, opposing=22.0)
    assert fold(readings, started)[1] is Decision.AT_STOP  # 58 % + 20 % >= 75 %
    assert fold(readings)[1] is Decision.HELD_PART_WAY


def test_pads_sliding_off_a_handle_that_held_are_a_lock_and_off_a_free_one_no_evidence():
    held = ramp([0.0, 0.01], opposing=8.0) + ramp([0.02], opposing=8.0, closure=0.72)  # closed 0.02 further
    judge, decision = fold(held)
    assert decision is Decision.SLIPPED_OFF_LOCKED
    assert judge.ended(decision).cause is Cause.LOCKED_SLIPPED_OFF
    free = ramp([0.2, 0.3], opposing=2.0) + ramp([0.4], closure=0.72)
    judge, decision = fold(free)
    assert decision is Decision.SLIPPED and judge.ended(decision).outcome == "failed"
    assert fold(ramp([0.3], closure=0.95))[1] is Decision.SLIPPED  # closed on nothing at once


def test_a_slip_after_the_end_stop_was_felt_is_moved():
    readings = [Reading(1.05, 5.0, 25.0, 0.97, 0.70), Reading(1.06, 5.0, 25.0, 0.97, 0.73)]
    judge, decision = fold(readings)
    assert decision is Decision.SLIPPED_AT_END_STOP
    assert judge.ended(decision).outcome == "moved" and judge.ended(decision).end_stop_felt


def test_the_verdict_of_a_motion_that_ran_its_course():
    judge, _ = fold(ramp([0.0, 0.02, 0.04], opposing=6.0))
    assert judge.verdict(0.05).cause is Cause.LOCKED_PULLED  # short of 10 % after 5 N
    assert judge.verdict(0.50).cause is Cause.INCOMPLETE_TRAVEL  # past 10 %, short of 75 %: no evidence
    assert judge.verdict(0.80).outcome == "moved"
    light, _ = fold(ramp([0.0, 0.02], opposing=3.0))
    assert light.verdict(0.05).cause is Cause.INCOMPLETE_TRAVEL  # under 5 N the pull proved nothing


def test_a_slip_while_settling_ends_the_settling_at_the_end_stop_or_the_try_elsewhere():
    readings = [Reading(1.05, 5.0, 25.0, 0.98, 0.70)]
    at_stop = PinchTrace(LIMITS, tuple(readings), ((0.98, 0.70), (0.98, 0.73), (0.99, 0.73)), 0.98)
    assert judge_pinch(at_stop, CONFIG).outcome == "moved"
    lost = PinchTrace(LIMITS, tuple(ramp([0.5])), ((0.5, 0.70), (0.5, 0.73)), 0.5)
    assert judge_pinch(lost, CONFIG).cause is Cause.SLIPPED


def test_a_trace_cut_short_cannot_be_judged():
    with pytest.raises(ValueError, match="cut short"):
        judge_pinch(PinchTrace(LIMITS, tuple(ramp([0.0, 0.1]))), CONFIG)
    with pytest.raises(ValueError, match="does not end a try"):
        PinchJudge(CONFIG, LIMITS).ended(Decision.GO_ON)
