"""The resident-memory soak of ``bench.py --only soak`` (issue 37): many twin trials in one process, as a pool
worker runs them, with the resident memory after each.

The trials vary what the process caches hold: the paper boxes in turn, every third trial a generated random
box (a scene, a mechanism layout and render resources never seen before), each seed placing the box anew under
the profile (``realistic``: anywhere reachable). The verdict compares the resident memory after the last trial
with that after trial ``reference`` (20 by default: the caches are full by then): within ``bound_mb`` it holds.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass
from typing import Any

from puzzlebox.lab.process_memory import resident_mb
from puzzlebox.models import PuzzleSpec

__all__ = ["SoakConfig", "SoakPoint", "soak_boxes", "soak_points", "soak_verdict"]


@dataclass(frozen=True)
class SoakConfig:
    """One soak run.

    Attributes:
        trials: twin trials, one after the other in this process.
        reality: the twin's reality profile (a preset's name).
        agent: the registered agent that acts (``oracle``: every try an approach, few wasted).
        max_actions: the most tries per trial.
        reference: the trial whose resident memory the last one is compared with (1-based).
        bound_mb: the most the resident memory may grow from trial ``reference`` to the last [MB].
        random_every: every this many trials a generated random box instead of a paper one (0: paper only).
    """

    trials: int = 200
    reality: str = "realistic"
    agent: str = "oracle"
    max_actions: int = 12
    reference: int = 20
    bound_mb: float = 50.0
    random_every: int = 3


@dataclass(frozen=True)
class SoakPoint:
    """Trial ``trial`` (1-based) of the soak: its box and seed, its outcome, and the resident memory after it
    [MB] (``/proc/self/status`` VmRSS)."""

    trial: int
    spec: str
    seed: int
    solved: bool
    actions: int
    wall_s: float
    rss_mb: float


def soak_boxes(config: SoakConfig) -> Iterator[tuple[PuzzleSpec, int]]:
    """The soak's (box, seed) pairs, in order: the paper family in turn, every ``random_every``-th a random box of
    ``3 + k % 3`` components generated from seed k (5 components, a new box each time, with the default 3), trial k
    (from 0) seeded k."""
    from puzzlebox.models.generator import RandomGraphConfig, generate_random, paper_family

    paper = paper_family("all")
    for k in range(config.trials):
        if config.random_every and k % config.random_every == config.random_every - 1:
            spec = generate_random(RandomGraphConfig(num_components=3 + k % 3), seed=k)
        else:
            spec = paper[k % len(paper)]
        yield spec, k


def soak_points(config: SoakConfig, on_point: Callable[[SoakPoint], None] | None = None) -> list[SoakPoint]:
    """Run the soak: one :class:`SoakPoint` per trial (``on_point`` is called with each as it comes)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    from puzzlebox.lab.trial_config import TrialConfig
    from puzzlebox.lab.trials import run_trial

    points = []
    for k, (spec, seed) in enumerate(soak_boxes(config), start=1):
        trial = TrialConfig(agent=config.agent, seed=seed, max_actions=config.max_actions, reality=config.reality)
        record = run_trial(spec, trial)
        point = SoakPoint(k, spec.name, seed, record.solved, record.num_actions, record.wall_time_s, resident_mb())
        points.append(point)
        if on_point is not None:
            on_point(point)
    return points


def soak_verdict(points: list[SoakPoint], config: SoakConfig) -> dict[str, Any]:
    """The resident memory after trial ``reference`` and after the last, the growth between them [MB] and
    whether it is within ``bound_mb`` (None when fewer trials than ``reference`` ran), with every point."""
    last = points[-1] if points else None
    reference = points[config.reference - 1] if len(points) >= config.reference else None
    growth = None if last is None or reference is None else last.rss_mb - reference.rss_mb
    return {
        "config": asdict(config),
        "trials_run": len(points),
        "first_rss_mb": points[0].rss_mb if points else None,
        "reference_rss_mb": None if reference is None else reference.rss_mb,
        "last_rss_mb": None if last is None else last.rss_mb,
        "growth_mb": growth,
        "per_trial_mb": None if growth is None or last is reference else growth / (len(points) - config.reference),
        "holds": None if growth is None else growth <= config.bound_mb,
        "points": [asdict(p) for p in points],
    }
