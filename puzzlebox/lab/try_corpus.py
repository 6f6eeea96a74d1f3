"""A corpus of recorded tries, and the pinch's judgement measured on it offline (``experiment.py tries``).

Every toggle the hand makes in a set of twin trials is recorded with the readings its judgement read
(:class:`skills.judgement.PinchTrace`: per control tick the command, the load against the motion and its magnitude,
the fingers' progress and the gripper's closure), what the hand concluded (outcome and cause) and, for evaluation
only, the simulator's truth: the part's true state and joint position before and after the toggle. The trials: the
paper's test boxes under ``ideal``, ``realistic`` and ``harsh`` (each with its calibration), runs with one kind
misreported, and boxes of the hard sets, solved by the dual agent from an empty memory (it explores: many tries
meet a lock). One file per trial, ``DIR/tries/<key>.npz`` (:func:`save_tries`), written as each trial finishes.

The judgement (:func:`skills.judgement.judge_pinch`) is then run on every recorded pinch, with no simulator behind it:
that it gives what the hand concluded live is checked try by try, and its agreement with the truth is counted per
profile and per cause, with a confusion matrix (``moved`` against the part's state changed, ``blocked`` against it
unchanged; ``failed`` is no evidence). Results: ``DIR/tries.{json,md}``.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.models.npz_file import load_header, save_npz
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
from puzzlebox.skills.judgement import Judgement, PinchLimits, PinchTrace, Reading, judge_pinch
from puzzlebox.skills.settings import PrimitiveConfig

FORMAT = "puzzlebox-tries/1"
READING_COLUMNS = ("commanded", "opposing", "magnitude", "progress", "closure")
"""The columns of a pinch's ``actuation`` array, one row per :class:`Reading`."""
SWING_COLUMNS = ("progress", "face", "normal", "opposing", "magnitude")
"""The columns of a door swing's ``actuation`` array, one row per :class:`SwingReading`."""
CLOSING_COLUMNS = ("progress", "opposing", "magnitude")
"""The columns of a door's closing push's ``actuation`` array, one row per :class:`ClosingReading`."""


@dataclass(frozen=True)
class RecordedTry:
    """One toggle as recorded: the context, what the hand concluded, the truth (evaluation only), the readings."""

    context: dict[str, Any]
    """Trial key, profile, box, seed, action number, component, the kind in use, opening or closing."""
    outcome: str
    """What the hand concluded: ``moved``, ``blocked`` or ``failed``."""
    cause: str | None
    """Its cause (a :class:`models.try_outcome.Cause` value), None for moved."""
    truth: dict[str, Any]
    """Evaluation only: ``state_before``, ``state_after`` (0/1), ``fraction_before``, ``fraction_after`` [-]."""
    trace: PinchTrace | SwingTrace | ClosingTrace | None
    """The readings its judgement read, a pinch's or a door's opening swing's, or None: the toggle's result came from
    no recorded judgement (a closing push, a top-up, a failed grasp)."""

    @property
    def truly_moved(self) -> bool:
        return self.truth["state_after"] != self.truth["state_before"]


def save_tries(path: str | Path, tries: Iterable[RecordedTry]) -> Path:
    """Write ``tries`` to ``path`` (``.npz``: a JSON header and each pinch's arrays) atomically."""
    header: list[dict[str, Any]] = []
    arrays: dict[str, np.ndarray] = {}
    for i, t in enumerate(tries):
        h = {"context": t.context, "outcome": t.outcome, "cause": t.cause, "truth": t.truth, "trace": None}
        if isinstance(t.trace, PinchTrace):
            h["trace"] = {"kind": "pinch", "limits": dataclasses.asdict(t.trace.limits), "reached": t.trace.reached}
            rows = [[getattr(r, c) for c in READING_COLUMNS] for r in t.trace.actuation]
            arrays[f"{i}.actuation"] = np.array(rows, dtype=np.float64).reshape(-1, len(READING_COLUMNS))
            arrays[f"{i}.settling"] = np.array(t.trace.settling, dtype=np.float64).reshape(-1, 2)
        elif isinstance(t.trace, SwingTrace):
            h["trace"] = {"kind": "swing", "limits": dataclasses.asdict(t.trace.limits), "ended_at": t.trace.ended_at}
            rows = [[getattr(r, c) for c in SWING_COLUMNS] for r in t.trace.readings]
            arrays[f"{i}.actuation"] = np.array(rows, dtype=np.float64).reshape(-1, len(SWING_COLUMNS))
        elif isinstance(t.trace, ClosingTrace):
            h["trace"] = {"kind": "closing", "limits": dataclasses.asdict(t.trace.limits)}
            rows = [[getattr(r, c) for c in CLOSING_COLUMNS] for r in t.trace.readings]
            arrays[f"{i}.actuation"] = np.array(rows, dtype=np.float64).reshape(-1, len(CLOSING_COLUMNS))
        header.append(h)
    return save_npz(path, {"format": FORMAT, "tries": header}, arrays)


def load_tries(path: str | Path) -> list[RecordedTry]:
    """The tries of a file :func:`save_tries` wrote.

    Raises:
        ValueError: not such a file (its format is named).
    """
    with np.load(path) as data:
        header = load_header(data, path, FORMAT, "a file of tries")
        tries = []
        for i, h in enumerate(header["tries"]):
            trace: PinchTrace | SwingTrace | ClosingTrace | None = None
            if h["trace"] is not None and h["trace"]["kind"] == "pinch":
                readings = tuple(Reading(*map(float, row)) for row in data[f"{i}.actuation"])
                settling = tuple((float(p), float(c)) for p, c in data[f"{i}.settling"])
                limits = PinchLimits(**h["trace"]["limits"])
                trace = PinchTrace(limits, readings, settling, h["trace"]["reached"])
            elif h["trace"] is not None and h["trace"]["kind"] == "swing":
                swings = tuple(SwingReading(*map(float, row)) for row in data[f"{i}.actuation"])
                trace = SwingTrace(SwingLimits(**h["trace"]["limits"]), swings, h["trace"]["ended_at"])
            elif h["trace"] is not None:
                closing = tuple(ClosingReading(*map(float, row)) for row in data[f"{i}.actuation"])
                trace = ClosingTrace(ClosingLimits(**h["trace"]["limits"]), closing)
            tries.append(RecordedTry(h["context"], h["outcome"], h["cause"], h["truth"], trace))
    return tries


# -- the judgement on the corpus ----------------------------------------------------------------------


@dataclass
class Tally:
    """The judgement against the truth over a group of pinches."""

    pinches: int = 0
    same_as_live: int = 0
    """Pinches the offline judgement judged as the hand did live (outcome and cause)."""
    confusion: dict[str, dict[str, int]] = dataclasses.field(
        default_factory=lambda: {o: {"moved": 0, "not moved": 0} for o in ("moved", "blocked", "failed")}
    )
    """Judged outcome -> the truth (the part's state changed or not) -> count."""

    def add(self, judged: str, truly_moved: bool, same: bool) -> None:
        self.pinches += 1
        self.same_as_live += same
        self.confusion[judged]["moved" if truly_moved else "not moved"] += 1

    @property
    def evidence(self) -> int:
        """Pinches judged ``moved`` or ``blocked`` (evidence for the agent)."""
        c = self.confusion
        return sum(c["moved"].values()) + sum(c["blocked"].values())

    @property
    def agreement(self) -> float | None:
        """Share of the evidence that agrees with the truth: moved where the state changed, blocked where not."""
        c = self.confusion
        return (c["moved"]["moved"] + c["blocked"]["not moved"]) / self.evidence if self.evidence else None

    def to_dict(self) -> dict[str, Any]:
        return {"pinches": self.pinches, "same_as_live": self.same_as_live, "evidence": self.evidence,
                "agreement": self.agreement, "confusion": self.confusion}  # fmt: skip


def judge_corpus(tries: Iterable[RecordedTry], config: PrimitiveConfig | None = None) -> dict[str, Any]:
    """The judgement on every recorded pinch and swing of ``tries``, offline (the settings of ``config``, default
    the hand's): tallies overall, per profile, per split, per live cause, per motion; the tries no recorded
    judgement concluded (closing pushes, top-ups, failed grasps) counted apart; the time a judgement takes [ms]."""
    config = config or PrimitiveConfig()
    groups: dict[str, dict[str, Tally]] = {"all": {}, "profile": {}, "split": {}, "cause": {}, "motion": {}}
    unjudged: dict[str, int] = {}
    seconds, count = 0.0, 0
    for t in tries:
        if t.trace is None:
            unjudged[t.cause or t.outcome] = unjudged.get(t.cause or t.outcome, 0) + 1
            continue
        start = time.perf_counter()
        judgement = judge_recorded(t, config)
        seconds += time.perf_counter() - start
        count += 1
        same = judgement.outcome == t.outcome and (judgement.cause.value if judgement.cause else None) == t.cause
        motion = {PinchTrace: "pinch", SwingTrace: "swing", ClosingTrace: "closing"}[type(t.trace)]
        keys = {"all": "all", "profile": t.context["profile"], "split": t.context["split"],
                "cause": t.cause or "moved", "motion": motion}  # fmt: skip
        for group, key in keys.items():
            groups[group].setdefault(key, Tally()).add(judgement.outcome, t.truly_moved, same)
    return {
        **{g: {k: v.to_dict() for k, v in sorted(tallies.items())} for g, tallies in groups.items()},
        "unjudged": unjudged,
        "ms_per_judgement": 1000 * seconds / count if count else None,
    }


CAUSES_JUDGED = (
    None, Cause.LOCKED_NO_PROGRESS, Cause.HELD_PART_WAY, Cause.LOCKED_PULLED, Cause.LOCKED_SLIPPED_OFF,
    Cause.LOCKED_PUSHED, Cause.LOCKED_PAD_SLID, Cause.INCOMPLETE_TRAVEL, Cause.SLIPPED, Cause.JAMMED,
)  # fmt: skip
"""What a pinch's or a swing's judgement can conclude (None: moved)."""


def judge_recorded(t: RecordedTry, config: PrimitiveConfig) -> Judgement:
    """The judgement of a recorded pinch or swing, offline.

    Raises:
        ValueError: ``t`` has no readings (no recorded judgement concluded it)."""
    if isinstance(t.trace, PinchTrace):
        return judge_pinch(t.trace, config.judgement)
    if isinstance(t.trace, SwingTrace):
        return judge_swing(t.trace, config.judgement, config.push.judgement)
    if isinstance(t.trace, ClosingTrace):
        return judge_closing(t.trace, config.judgement, config.push.judgement)
    raise ValueError(f"try {t.context} has no readings to judge")


def sample(tries: list[RecordedTry], per_cause: int = 4) -> list[RecordedTry]:
    """Up to ``per_cause`` recorded pinches and as many swings of each live cause (moved included), each from a
    different trial where there are enough: the sample committed under ``tests/`` for the judgement's tests."""
    chosen: list[RecordedTry] = []
    for motion in (PinchTrace, SwingTrace, ClosingTrace):
        for cause in CAUSES_JUDGED:
            value = cause.value if cause is not None else None
            pool = [t for t in tries if isinstance(t.trace, motion) and t.cause == value]
            seen: set[str] = set()
            for t in pool:
                if len(seen) >= per_cause:
                    break
                if t.context["key"] not in seen:
                    seen.add(t.context["key"])
                    chosen.append(t)
    return chosen


__all__ = [
    "CAUSES_JUDGED",
    "FORMAT",
    "RecordedTry",
    "Tally",
    "judge_corpus",
    "judge_recorded",
    "load_tries",
    "sample",
    "save_tries",
]
