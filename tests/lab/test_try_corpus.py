"""The corpus of recorded tries (puzzlebox/lab/try_corpus.py) and the pinch's judgement on real traces: a sample
recorded by ``experiment.py tries`` is committed under tests/, so the judgement is tested without simulating."""

import subprocess
import sys
from pathlib import Path

import pytest

from puzzlebox.lab.try_corpus import (
    CAUSES_JUDGED,
    RecordedTry,
    judge_corpus,
    judge_recorded,
    load_tries,
    sample,
    save_tries,
)
from puzzlebox.skills.judgement import PinchLimits, PinchTrace, Reading
from puzzlebox.skills.settings import PrimitiveConfig

ROOT = Path(__file__).resolve().parents[2]
SAMPLE = ROOT / "tests/skills/data/tries_sample.npz"
"""Pinches of each cause from ``python scripts/experiment.py tries --out DIR`` (``DIR/sample.npz``)."""
LIMITS = PinchLimits(press_limit=float("inf"), window=5, head_start=0.0, slip_ticks=26, grasp_closure=0.7)


def made_up(outcome: str, cause: str | None, moved: bool, opposing: float, key: str = "t0") -> RecordedTry:
    """A pinch with a made-up trace: carried to its end (light load), or held at once (``opposing`` N)."""
    if opposing < 20:
        trace = PinchTrace(LIMITS, tuple(Reading(p / 10 + 0.02, opposing, opposing, p / 10, 0.7) for p in range(11)),
                           (), 1.0)  # fmt: skip
    else:
        trace = PinchTrace(LIMITS, (Reading(0.02, opposing, opposing, 0.0, 0.7),))
    context = {"key": key, "profile": "realistic", "split": "held-out", "component": "slide-1"}
    truth = {"state_before": 0, "state_after": int(moved), "fraction_before": 0.0, "fraction_after": float(moved)}
    return RecordedTry(context, outcome, cause, truth, trace)


def test_tries_round_trip_through_their_file(tmp_path):
    empty = RecordedTry({"key": "t1"}, "failed", "grasp_empty", made_up("moved", None, True, 2.0).truth, None)
    tries = [made_up("moved", None, True, 2.0), made_up("blocked", "locked_no_progress", False, 25.0), empty]
    path = save_tries(tmp_path / "t.npz", tries)
    assert load_tries(path) == tries
    (tmp_path / "bad.npz").write_bytes(b"not a file of tries")
    with pytest.raises(ValueError):
        load_tries(tmp_path / "bad.npz")


def test_the_judgement_is_tallied_against_the_truth_with_a_confusion_matrix():
    tries = [
        made_up("moved", None, True, 2.0),  # right
        made_up("blocked", "locked_no_progress", False, 25.0),  # right
        made_up("blocked", "locked_no_progress", True, 25.0),  # held, yet the state changed: wrong
        made_up("blocked", "held_part_way", False, 25.0),  # live said otherwise than the judgement does now
        RecordedTry({"key": "t1"}, "failed", "grasp_empty", {"state_before": 0, "state_after": 0}, None),
    ]
    summary = judge_corpus(tries, PrimitiveConfig())
    overall = summary["all"]["all"]
    assert (overall["pinches"], overall["same_as_live"], overall["evidence"]) == (4, 3, 4)
    assert overall["agreement"] == pytest.approx(3 / 4)
    assert overall["confusion"]["blocked"] == {"moved": 1, "not moved": 2}
    assert summary["unjudged"] == {"grasp_empty": 1}
    assert summary["cause"]["locked_no_progress"]["pinches"] == 2


def test_the_sample_takes_a_few_pinches_of_each_cause_from_different_trials():
    tries = [made_up("moved", None, True, 2.0, key=f"t{k % 3}") for k in range(9)]
    tries += [made_up("blocked", "locked_no_progress", False, 25.0, key="t0") for _ in range(3)]
    chosen = sample(tries, per_cause=2)
    assert [t.cause for t in chosen] == [None, None, "locked_no_progress"]
    assert len({t.context["key"] for t in chosen if t.cause is None}) == 2


def test_every_recorded_pinch_of_the_sample_is_judged_as_the_hand_judged_it_live():
    tries = load_tries(SAMPLE)
    assert SAMPLE.stat().st_size <= 5_000_000
    causes = {t.cause for t in tries}
    assert {None, "locked_no_progress", "held_part_way"} <= causes  # moved, and the two ways a lock is felt
    assert causes <= {c.value if c else None for c in CAUSES_JUDGED}
    for t in tries:
        judgement = judge_recorded(t, PrimitiveConfig())
        assert (judgement.outcome, judgement.cause.value if judgement.cause else None) == (t.outcome, t.cause), (
            t.context
        )


def test_the_sample_agrees_with_the_truth_where_it_is_evidence():
    for t in load_tries(SAMPLE):
        if t.outcome == "moved":
            assert t.truly_moved, t.context
        elif t.outcome == "blocked":
            assert not t.truly_moved, t.context


def test_the_tries_command_takes_only_its_flags(tmp_path):
    command = [sys.executable, str(ROOT / "scripts/experiment.py"), "tries", "--out", str(tmp_path / "out")]
    result = subprocess.run([*command, "--runs", "3"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 2 and "--runs" in result.stderr, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr
    assert not (tmp_path / "out").exists()


def test_a_recorded_trial_is_judged_offline_as_it_was_live_and_agrees_with_the_truth(tmp_path):
    """One oracle trial of a paper box under ``ideal`` recorded as ``experiment.py tries`` records it: every pinch and
    swing judged again from its file gives what the hand concluded live, and moved / blocked match the truth."""
    from puzzlebox.lab.tries_experiment import record_task
    from puzzlebox.models.generator import paper_family
    from puzzlebox.twin.reality import load_profile

    spec = paper_family("test", seed=0)[0]
    settings = {"key": "ideal-paper-test-0-s7000", "spec": spec.to_dict(), "seed": 7000,
                "profile": load_profile("ideal").to_dict(), "profile_name": "ideal", "calibration": None,
                "misreported": False, "split": "development", "agent": "dual", "max_actions": 6}  # fmt: skip
    summary = record_task(settings, {"file": str(tmp_path / "t.npz")})
    tries = load_tries(tmp_path / "t.npz")
    assert summary["tries"] == len(tries) >= 5 and summary["judged"] >= 4
    judged = judge_corpus(tries)["all"]["all"]
    assert judged["same_as_live"] == judged["pinches"] == summary["judged"]
    assert judged["agreement"] == 1.0 and judged["confusion"]["moved"]["moved"] >= 1
