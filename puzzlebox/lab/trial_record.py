"""The record of one trial: what ``trial.py`` writes per run (``DIR/runs/<key>.json``, ``results.json``'s
``runs[]``), typed."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from puzzlebox.learning import ActionRecord, RunResult

__all__ = ["TrialRecord"]

_OPTIONAL = (
    "sim_time_s", "perceived_position_error_m", "box_pose", "reality", "peak_true_wrist_force_n",
    "peak_true_wrist_force_during", "sensed_sha256", "told_kinds", "found_kinds", "timeline", "robot_time_s", "stopped",
    "perceived_closed_poses",
)  # fmt: skip


@dataclass(frozen=True)
class TrialRecord:
    """One trial's outcome; the twin's fields are None for a symbolic trial.

    Attributes:
        spec, seed: the spec's name and the trial's seed.
        solved: the goal reached within the budget.
        num_actions: tries made.
        wall_time_s: the trial's wall time [s].
        actions: each try: the component (its spec name), whether it moved (as sensed), the outcome and why a
            failed try failed.
        ended: why an unsolved trial stopped early, else empty.
        sim_time_s: simulated time [s] (twin).
        perceived_position_error_m: per component, the perceived closed position's error in the lid plane [m].
        box_pose: where the box stood ``[x, y, yaw]`` in the robot base frame [m, m, rad].
        reality: the reality profile's name.
        peak_true_wrist_force_n: the largest true external wrist force [N] and
        peak_true_wrist_force_during: what the arm was doing then.
        sensed_sha256: SHA-256 over everything the pipeline sensed, in order (the trial's fingerprint).
        told_kinds: component -> the kind the pipeline was told, when one was told wrong.
        found_kinds: component -> the kind that moved it, where the world found a part's kind other than it was told
            (``skills.robot_world``; given with ``told_kinds``, and whenever one was found).
        timeline: per try, what was sensed (and in the twin the simulator's truth), the F/T peak, times.
        robot_time_s: the arm's own clock over the trial [s] (real cell).
        stopped: why the arm's safety limits stopped the trial, else empty (real cell).
        perceived_closed_poses: per component, its closed pose as the survey perceived it (real cell).
    """

    spec: str
    seed: int
    solved: bool
    num_actions: int
    wall_time_s: float
    actions: tuple[ActionRecord, ...] = ()
    ended: str = ""
    sim_time_s: float | None = None
    perceived_position_error_m: dict[str, float] | None = None
    box_pose: tuple[float, float, float] | None = None
    reality: str | None = None
    peak_true_wrist_force_n: float | None = None
    peak_true_wrist_force_during: str | None = None
    sensed_sha256: str | None = None
    told_kinds: dict[str, str] | None = None
    found_kinds: dict[str, str] | None = None
    timeline: tuple[dict[str, Any], ...] | None = field(default=None, repr=False)
    robot_time_s: float | None = None
    stopped: str | None = None
    perceived_closed_poses: dict[str, list[float]] | None = field(default=None, repr=False)

    @classmethod
    def of_run(cls, result: RunResult, **twin: Any) -> TrialRecord:
        """The record of a :class:`~puzzlebox.learning.RunResult`, with the twin's fields given (a twin trial's
        ``wall_time_s`` among them: the whole trial's, survey included)."""
        fields = {"wall_time_s": result.wall_time_s, **twin}
        return cls(result.spec, result.seed, result.solved, result.num_actions, actions=tuple(result.actions),
                   ended=result.ended, **fields)  # fmt: skip

    @classmethod
    def from_dict(cls, entry: dict[str, Any]) -> TrialRecord:
        """The record of a run entry (:meth:`to_dict`'s layout: a ``results.json`` ``runs[]`` entry or a
        ``DIR/runs/<key>.json`` record) of a symbolic, twin or real trial; ``from_dict(r.to_dict()) == r``."""
        actions = tuple(ActionRecord.from_dict(a) for a in entry.get("actions", ()))
        extra = {k: entry[k] for k in _OPTIONAL if k in entry}
        if "box_pose" in extra:
            extra["box_pose"] = tuple(extra["box_pose"])
        if "timeline" in extra:
            extra["timeline"] = tuple(dict(a) for a in extra["timeline"])
        return cls(entry["spec"], entry["seed"], entry["solved"], entry["num_actions"], entry["wall_time_s"],
                   actions=actions, ended=entry.get("ended", ""), **extra)  # fmt: skip

    @property
    def outcome_agreement(self) -> float | None:
        """Fraction of tries whose sensed outcome (moved or not) agrees with the simulator's truth (twin only)."""
        if self.timeline is None or self.robot_time_s is not None:  # a real cell has no truth to agree with
            return None
        return sum(a["moved"] == a["true_moved"] for a in self.timeline) / max(len(self.timeline), 1)

    def to_dict(self) -> dict[str, Any]:
        """The run entry of ``results.json`` (the command line's contract; twin fields only for a twin trial)."""
        out: dict[str, Any] = {
            "spec": self.spec, "seed": self.seed, "solved": self.solved, "num_actions": self.num_actions,
            "wall_time_s": self.wall_time_s,
            "actions": [a.to_dict() for a in self.actions],
            "ended": self.ended,
        }  # fmt: skip
        if self.robot_time_s is not None:  # a real cell: what was sensed, no simulator
            return out | {
                "robot_time_s": self.robot_time_s,
                "stopped": self.stopped,
                "perceived_closed_poses": dict(self.perceived_closed_poses or {}),
                "timeline": [dict(a) for a in self.timeline or ()],
            }
        if self.sim_time_s is None:
            return out
        out |= {
            "sim_time_s": self.sim_time_s,
            "perceived_position_error_m": dict(self.perceived_position_error_m or {}),
            "box_pose": list(self.box_pose or ()),
            "reality": self.reality,
            "peak_true_wrist_force_n": self.peak_true_wrist_force_n,
            "peak_true_wrist_force_during": self.peak_true_wrist_force_during,
            "sensed_sha256": self.sensed_sha256,
        }
        if self.told_kinds is not None:
            out["told_kinds"] = dict(self.told_kinds)
        if self.found_kinds is not None:
            out["found_kinds"] = dict(self.found_kinds)
        out["timeline"] = [dict(a) for a in self.timeline or ()]
        return out
