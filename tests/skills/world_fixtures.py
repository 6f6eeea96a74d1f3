"""A ``TwinWorld`` over a twin session exactly as the trial script wires it (``puzzlebox/lab/twin_trial.py``:
nominal calibration, the spec's goal, ground truth for scoring only), shared by the skills tests."""

from __future__ import annotations

from puzzlebox.lab.twin_trial import TrueForceWatch, evaluation_world  # noqa: E402  (scripts/ is not a package)
from puzzlebox.skills.twin_world import TwinWorld  # noqa: E402
from puzzlebox.twin.session import TwinSession  # noqa: E402

__all__ = ["TrueForceWatch", "twin_world"]


def twin_world(session: TwinSession, seed: int = 0) -> TwinWorld:
    return evaluation_world(session, seed=seed)
