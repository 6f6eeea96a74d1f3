"""What a set of twin runs says beyond success and actions: outcome agreement with the simulator's truth,
perception error, speed and peak wrist force."""

from __future__ import annotations

from puzzlebox.models.try_outcome import Cause

__all__ = ["twin_figures"]


def twin_figures(runs: list) -> dict:
    """Outcome agreement with ground truth, perception error and speed over all twin runs."""
    actions = [a for r in runs for a in r["timeline"]]
    reasons: dict[str, int] = {}
    for a in actions:
        if a["outcome"] == "failed":
            cause = a.get("cause") or Cause.from_legacy(a["reason"])  # (a record from before causes were kept)
            key = Cause(cause).prefix if cause else "unknown"
            reasons[key] = reasons.get(key, 0) + 1
    errors = [e for r in runs for e in r["perceived_position_error_m"].values()]
    sim, wall = sum(r["sim_time_s"] for r in runs), sum(r["wall_time_s"] for r in runs)
    return {
        "outcome_agreement": float(sum(a["moved"] == a["true_moved"] for a in actions) / max(len(actions), 1)),
        "actions_total": len(actions),
        "perceived_position_error_max_m": max(errors, default=0.0),
        "perceived_position_error_mean_m": sum(errors) / max(len(errors), 1),
        "wall_time_per_trial_s_max": max((r["wall_time_s"] for r in runs), default=0.0),
        "wall_time_per_trial_s_mean": wall / max(len(runs), 1),
        "sim_over_wall": sim / wall if wall else 0.0,
        "failed_tries_by_reason": reasons,
        "unsolved_reasons": [
            f"{r['spec']} seed {r['seed']}: {r.get('ended') or 'out of actions'}" for r in runs if not r["solved"]
        ],  # fmt: skip
        "peak_true_wrist_force_n": max((r["peak_true_wrist_force_n"] for r in runs), default=0.0),
    }
