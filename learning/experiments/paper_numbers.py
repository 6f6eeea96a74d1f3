"""The paper's numbers (PAPER_NOTES.md) that our protocols are compared against."""

from __future__ import annotations

PAPER: dict[str, list[dict[str, object]]] = {
    "variants": [
        {"what": "1 training variant, success", "agent": "memory", "x": 1, "key": "success_rate", "paper": 0.987},
        {"what": "9 training variants, success", "agent": "memory", "x": 9, "key": "success_rate", "paper": 1.0},
        {"what": "1 training variant, success (deep model-free)", "agent": "dqn", "x": 1, "key": "success_rate",
         "paper": 0.427},
        {"what": "1 training variant, success (deep model-based)", "agent": "model-based", "x": 1,
         "key": "success_rate", "paper": 0.0},
    ],
    "episodes": [
        {"what": "9 episodes, success", "agent": "memory", "x": 9, "key": "success_rate", "paper": 1.0},
        {"what": "9 episodes, mean actions", "agent": "memory", "x": 9, "key": "mean_actions", "paper": 9.4},
        {"what": "30 episodes, mean actions", "agent": "memory", "x": 30, "key": "mean_actions", "paper": 7.5},
        {"what": "60 episodes, mean actions", "agent": "memory", "x": 60, "key": "mean_actions", "paper": 7.5},
    ],
    "noise": [
        {"what": "wrong kind, success", "agent": "memory", "x": "wrong kind", "key": "success_rate", "paper": 0.79},
        {"what": "pose noise, success", "agent": "memory", "x": "pose noise", "key": "success_rate", "paper": 0.75},
        {"what": "both, success", "agent": "memory", "x": "both", "key": "success_rate", "paper": 0.72},
    ],
}  # fmt: skip
"""Per protocol: the figure, the agent and x value it belongs to, and the paper's value. Mean actions
"7.2-7.7 later" in the release's arrays is entered as 7.5."""
