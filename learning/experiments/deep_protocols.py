"""The deep baselines through the paper's protocols, as resumable training jobs run in parallel.

One *job* trains one deep agent (``dqn``, ``model-based``, ``mt-dqn``, ``mt-model-based``) with one
training seed on the first ``k`` training variants, and evaluates it on the unseen variants at fixed
episode counts. The protocols share jobs:

- ``episodes``: the k = 9 job, evaluated at every ``DeepSchedule.checkpoints`` count;
- ``variants``: k = 0 is the k = 9 job at 0 episodes (the untrained network), k = 9 the k = 9 job at
  ``converged_episodes``, other k their own jobs (trained ``converged_episodes``);
- ``noise``: the k = 9 job at ``converged_episodes``, evaluated under every scene error.

Training and test layouts, world seeds and the success rule are the memory agent's
(``protocol.py``): every agent meets the same boxes. Here a job is defined (:func:`job_settings`), run
(:func:`run_job_task`) and its records merged into the protocols' points; the composition layer runs the jobs on
the task runner (``puzzlebox.lab.deep_protocols_run``): a finished job is written to
``OUT/jobs/<agent>-v<k>-s<seed>.json`` (with the network as ``.pt`` beside it, loadable by
``trial.py --checkpoint``) the moment it ends, so an interrupted run resumes where it stopped; a job
file made with other settings is recomputed, never mixed in.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.learning.agent_names import DEEP_AGENT_NAMES
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.experiments.protocol import (
    ProtocolConfig,
    Score,
    evaluate,
    summarise_scores,
    training_layout,
)
from puzzlebox.learning.experiments.symbolic_protocols import CONDITIONS
from puzzlebox.learning.symbolic_world import SymbolicWorld
from puzzlebox.learning.trial import run_episode
from puzzlebox.models.generator import TRAIN_INDICES

DEEP_AGENTS = DEEP_AGENT_NAMES
NONE = "none"


@dataclass(frozen=True)
class DeepSchedule:
    """How long the deep agents train, and where they are evaluated."""

    checkpoints: tuple[int, ...] = (0, 10, 25, 50, 75, 100, 150, 200, 300, 400, 500, 650)
    """Training episodes (over the 9 training variants) at which the episodes protocol evaluates."""
    converged_episodes: int = 650
    """Episodes of training "until convergence" (variants and noise protocols): the paper's deep agents
    solved every unseen variant after ~300 (model-based) and ~650 (model-free) episodes."""
    variant_counts: tuple[int, ...] = (0, 1, 3, 9)
    """Training-variant counts of the variants protocol (each extra count is a full training job)."""
    variant_agents: tuple[str, ...] = ("dqn", "model-based")
    """Deep agents of the variants protocol (the paper's Fig. 3 left has no MT-OPT agents)."""

    def __post_init__(self) -> None:
        if self.converged_episodes not in self.checkpoints:
            raise ConfigError(f"converged_episodes {self.converged_episodes} must be one of {self.checkpoints}")
        if list(self.checkpoints) != sorted(set(self.checkpoints)) or self.checkpoints[0] < 0:
            raise ConfigError(f"checkpoints must be increasing and >= 0, got {self.checkpoints}")
        if not set(self.variant_counts) <= set(range(len(TRAIN_INDICES) + 1)):
            raise ConfigError(f"variant counts must be within 0..{len(TRAIN_INDICES)}, got {self.variant_counts}")

    def quick(self) -> DeepSchedule:
        """A CI-sized schedule: a few dozen episodes (measures plumbing, not learning)."""
        return DeepSchedule(checkpoints=(0, 5, 10), converged_episodes=10, variant_counts=(0, 1, 9))


@dataclass(frozen=True)
class TrainingJob:
    """Train ``agent`` (seed ``seed``) on the first ``variants`` training variants; evaluate the clean
    scene at ``evaluate_at`` episode counts and every scene condition at ``conditions_at`` (if set)."""

    agent: str
    variants: int
    seed: int
    evaluate_at: tuple[int, ...]
    conditions_at: int | None = None
    poses: str = "relative"
    """The graph network's pose encoding (``GraphNetworkConfig.poses``); ``absolute`` is an ablation."""

    @property
    def key(self) -> str:
        return job_key(self.agent, self.variants, self.seed, self.poses)

    @property
    def episodes(self) -> int:
        return max(self.evaluate_at)


def job_key(agent: str, variants: int, seed: int, poses: str = "relative") -> str:
    """File stem of a job in ``OUT/jobs/``, e.g. ``dqn-v9-s0`` (``dqn-v9-s0-absolute`` for the ablation)."""
    suffix = "" if poses == "relative" else f"-{poses}"
    return f"{agent}-v{variants}-s{seed}{suffix}"


def jobs_for(
    protocol: str, agents: Sequence[str], config: ProtocolConfig, schedule: DeepSchedule, poses: str = "relative"
) -> list[TrainingJob]:
    """The jobs a protocol needs (the k = 9 job is the same for all three: it is computed once)."""
    full = len(TRAIN_INDICES)
    jobs = []
    for agent in agents:
        for seed in range(config.training_seeds):
            jobs.append(TrainingJob(agent, full, seed, schedule.checkpoints, schedule.converged_episodes, poses))
            if protocol == "variants" and agent in schedule.variant_agents:
                jobs += [
                    TrainingJob(agent, k, seed, (schedule.converged_episodes,), poses=poses)
                    for k in schedule.variant_counts
                    if 0 < k < full
                ]
    return jobs


def job_settings(job: TrainingJob, config: ProtocolConfig) -> dict[str, Any]:
    """Everything a job's numbers depend on (a cached job must match it exactly to be reused). The
    default pose encoding is left out, as in the files written before the option existed."""
    job_fields = asdict(job)
    if job.poses == "relative":
        del job_fields["poses"]
    return {
        "job": job_fields,
        "runs_per_variant": config.runs_per_variant,
        "success_actions": config.success_actions,
        "max_actions": config.max_actions,
    }


def _train(agent: Any, job: TrainingJob, episodes: range, config: ProtocolConfig) -> list[bool]:
    """Training episodes on the memory agent's boxes (``protocol.training_layout``)."""
    solved = []
    for e in episodes:
        spec, seed = training_layout(TRAIN_INDICES[: job.variants], e, job.seed)
        solved.append(run_episode(agent, SymbolicWorld(spec, seed), spec.name, seed, config.max_actions).solved)
    return solved


def _evaluate(agent: Any, config: ProtocolConfig, condition: str) -> dict[str, float]:
    agent.training = False
    score = evaluate(lambda spec: agent, config, **CONDITIONS[condition])
    agent.training = True
    return {"success_rate": score.success_rate, "mean_actions": score.mean_actions, "runs": score.runs}


def run_job(job: TrainingJob, config: ProtocolConfig, out_dir: str) -> dict[str, Any]:
    """Train and evaluate one job, write its network to ``OUT/jobs/<key>.pt`` atomically; its record."""
    import torch

    from puzzlebox.learning.baselines import GraphNetworkConfig, make_learner, save_checkpoint

    torch.set_num_threads(1)  # one job per core: the jobs are the parallelism
    start = time.perf_counter()
    agent = make_learner(job.agent, job.seed, GraphNetworkConfig(poses=job.poses))
    evaluations, training_solved = [], []
    done = 0
    for checkpoint in job.evaluate_at:
        training_solved += _train(agent, job, range(done, checkpoint), config)
        done = checkpoint
        conditions = CONDITIONS if checkpoint == job.conditions_at else (NONE,)
        for condition in conditions:
            evaluations.append({"episodes": checkpoint, "condition": condition, **_evaluate(agent, config, condition)})
    save_checkpoint(agent, Path(out_dir) / "jobs" / f"{job.key}.pt")
    return {
        "settings": job_settings(job, config),
        "evaluations": evaluations,
        "training_solved": int(np.sum(training_solved)),
        "training_episodes": len(training_solved),
        "wall_time_s": time.perf_counter() - start,
        "checkpoint": f"{job.key}.pt",
    }


def run_job_task(settings: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """:func:`run_job` as a runner task: ``settings`` is :func:`job_settings`'s (as JSON), ``context`` the
    output directory."""
    fields = dict(settings["job"])
    fields["evaluate_at"] = tuple(fields["evaluate_at"])
    job = TrainingJob(**fields)
    config = ProtocolConfig(runs_per_variant=settings["runs_per_variant"], success_actions=settings["success_actions"],
                            max_actions=settings["max_actions"])  # fmt: skip
    return json.loads(json.dumps(run_job(job, config, context["out_dir"])))  # tuples -> lists, as stored


def _score(records: Sequence[dict[str, Any]], episodes: int, condition: str) -> dict[str, Any] | None:
    """Mean and std over seeds of the evaluations at ``episodes`` under ``condition``."""
    picked = [e for r in records for e in r["evaluations"] if e["episodes"] == episodes and e["condition"] == condition]
    if not picked:
        return None
    return summarise_scores([Score(e["success_rate"], e["mean_actions"], e["runs"]) for e in picked])


def merge_deep_points(
    result: dict[str, Any],
    agents: Sequence[str],
    records: dict[str, dict[str, Any]],
    config: ProtocolConfig,
    schedule: DeepSchedule,
    poses: str = "relative",
) -> dict[str, Any]:
    """Add the deep agents' entries to a protocol result's points (new x values become new points)."""
    protocol, x_key = result["protocol"], result["x"]
    full = len(TRAIN_INDICES)
    by_x: dict[Any, dict[str, Any]] = {p[x_key]: p for p in result["points"]}
    fixed = {a: v for a, v in result["points"][0].items() if a not in (x_key, "memory")} if result["points"] else {}

    def put(x: Any, agent: str, entry: dict[str, Any] | None) -> None:
        if entry is not None:
            by_x.setdefault(x, {x_key: x, **fixed})[agent] = entry

    def seeds(agent: str, k: int) -> list[dict[str, Any]]:
        return [records[job_key(agent, k, t, poses)] for t in range(config.training_seeds)]

    for agent in agents:
        if protocol == "episodes":
            for x in schedule.checkpoints:
                put(x, agent, _score(seeds(agent, full), x, NONE))
        elif protocol == "noise":
            for condition in CONDITIONS:
                put(condition, agent, _score(seeds(agent, full), schedule.converged_episodes, condition))
        elif protocol == "variants" and agent in schedule.variant_agents:
            for k in schedule.variant_counts:
                source, episodes = (full, 0) if k == 0 else (k, schedule.converged_episodes)
                put(k, agent, _score(seeds(agent, source), episodes, NONE))
    points = [p for p in by_x.values() if len(p) > 1]  # drop x values no agent was evaluated at
    if protocol != "noise":
        points.sort(key=lambda p: p[x_key])
    return {**result, "points": points, "deep_schedule": asdict(schedule), "deep_poses": poses}
