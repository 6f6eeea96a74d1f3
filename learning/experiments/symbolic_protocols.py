"""The paper's three symbolic protocols (Fig. 3): success vs training variants, vs training episodes,
and under errors in the symbolic scene — for every symbolic agent, with the spread over training seeds.

Each protocol returns a JSON-ready dict: ``points`` (one row per x value, one entry per agent with
success rate and mean actions, mean and std over training seeds) plus the settings used.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict
from typing import Any

from tqdm import tqdm

from puzzlebox.learning.experiments.protocol import (
    ProtocolConfig,
    Score,
    agent_factory,
    evaluate,
    summarise_scores,
    train_memory,
)
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.learning.puzzle_env import FaultConfig
from puzzlebox.models.generator import TRAIN_INDICES

PAPER_UNIT = 0.015
"""One abstract unit of the authors' release in metres: their door-slide neighbour distance (6 units)
against ours (~0.09 m)."""
NOISE_CONDITIONS: dict[str, FaultConfig | None] = {
    "none": None,
    "wrong kind": FaultConfig(misreported_kinds=1),
    "pose noise": FaultConfig(position_noise_std=2 * PAPER_UNIT, yaw_noise_std=2 * math.pi / 12),
    "both": FaultConfig(misreported_kinds=1, position_noise_std=2 * PAPER_UNIT, yaw_noise_std=2 * math.pi / 12),
}
"""The release's noise: one kind replaced; Gaussian pose noise sigma = 2 units on x, y and
sigma * pi / 12 on the angle."""
MOVED_BOX_POSE = (0.32, -0.12, 2.0)
"""A box pose unlike the training boxes' (0.45, 0, 0): moved 18 cm and turned 115 degrees [m, m, rad]."""
CONDITIONS: dict[str, dict[str, Any]] = {
    **{name: {"faults": faults} for name, faults in NOISE_CONDITIONS.items()},
    "moved box": {"box_pose": MOVED_BOX_POSE},
}
"""The noise protocol's scene conditions, as keyword arguments of ``protocol.evaluate``."""
VARIANT_COUNTS = tuple(range(10))
EPISODE_CHECKPOINTS = (0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 12, 15, 20, 30, 45, 60)
TRAINING_EPISODES_FOR_CONVERGED = 18
"""Episodes of training "until convergence" (variants and noise protocols): two passes over 9 variants."""

Progress = Callable[[Sequence[Any], str], Any]


def _progress(items: Sequence[Any], desc: str) -> Any:
    return tqdm(items, desc=desc, unit="point", disable=None, leave=False)


def _trained_store(variants: Sequence[int], episodes: int, seed: int, config: ProtocolConfig) -> MemoryStore:
    store = MemoryStore(position_scale=config.memory.position_scale, rotation_weight=config.memory.rotation_weight)
    if variants and episodes:
        train_memory(store, variants, range(episodes), seed, config)
    return store


def _untrained_scores(
    agents: Sequence[str], config: ProtocolConfig, **kwargs: Any
) -> dict[str, dict[str, float | int | list[float]]]:
    """Agents that learn nothing across tasks score the same at every x: evaluate them once."""
    return {
        name: summarise_scores([evaluate(agent_factory(name, None, config), config, **kwargs)])
        for name in agents
        if name != "memory"
    }


def run_variants(agents: Sequence[str], config: ProtocolConfig, quick: bool = False) -> dict[str, Any]:
    """Success on the unseen variants vs the number of training variants available (Fig. 3, left)."""
    counts = (0, 1, 9) if quick else VARIANT_COUNTS
    fixed = _untrained_scores(agents, config)
    points = []
    for count in _progress(counts, "variants"):
        row: dict[str, Any] = {"training_variants": count, **fixed}
        if "memory" in agents:
            scores = [
                evaluate(
                    agent_factory(
                        "memory",
                        _trained_store(TRAIN_INDICES[:count], TRAINING_EPISODES_FOR_CONVERGED, t, config),
                        config,
                    ),
                    config,
                )
                for t in range(config.training_seeds)
            ]
            row["memory"] = summarise_scores(scores)
        points.append(row)
    return {"protocol": "variants", "x": "training_variants", "points": points, **_settings(config)}


def run_episodes(agents: Sequence[str], config: ProtocolConfig, quick: bool = False) -> dict[str, Any]:
    """Success on the unseen variants vs total training episodes over the 9 variants (Fig. 3, middle)."""
    checkpoints = (0, 1, 9) if quick else EPISODE_CHECKPOINTS
    fixed = _untrained_scores(agents, config)
    per_seed: dict[int, list[Score]] = {e: [] for e in checkpoints}
    if "memory" in agents:
        for t in range(config.training_seeds):
            store = MemoryStore(
                position_scale=config.memory.position_scale, rotation_weight=config.memory.rotation_weight
            )
            done = 0
            for e in _progress(checkpoints, f"episodes (seed {t})"):
                train_memory(store, TRAIN_INDICES, range(done, e), t, config)
                done = e
                per_seed[e].append(evaluate(agent_factory("memory", store, config), config))
    points = []
    for e in checkpoints:
        row: dict[str, Any] = {"training_episodes": e, **fixed}
        if per_seed[e]:
            row["memory"] = summarise_scores(per_seed[e])
        points.append(row)
    return {"protocol": "episodes", "x": "training_episodes", "points": points, **_settings(config)}


def run_noise(agents: Sequence[str], config: ProtocolConfig, quick: bool = False) -> dict[str, Any]:
    """Success under errors in the symbolic scene, after training to convergence (Fig. 3, right), plus
    the whole box moved and turned on the table (relative-pose memory keys)."""
    stores = [
        _trained_store(TRAIN_INDICES, TRAINING_EPISODES_FOR_CONVERGED, t, config) for t in range(config.training_seeds)
    ]
    points = []
    for name in _progress(list(CONDITIONS), "noise"):
        kwargs = CONDITIONS[name]
        row: dict[str, Any] = {"condition": name, **_untrained_scores(agents, config, **kwargs)}
        if "memory" in agents:
            row["memory"] = summarise_scores(
                [evaluate(agent_factory("memory", store, config), config, **kwargs) for store in stores]
            )
        points.append(row)
    levels = {
        "position_noise_std_m": 2 * PAPER_UNIT,
        "yaw_noise_std_rad": 2 * math.pi / 12,
        "moved_box_pose": MOVED_BOX_POSE,
    }
    return {"protocol": "noise", "x": "condition", "points": points, "levels": levels, **_settings(config)}


def _settings(config: ProtocolConfig) -> dict[str, Any]:
    return {"config": asdict(config)}


PROTOCOLS = {"variants": run_variants, "episodes": run_episodes, "noise": run_noise}
