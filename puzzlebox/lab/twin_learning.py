"""``experiment.py twin-learning``: the paper's robot learning curve, closed in simulation.

The memory agent learns on the 9 paper training boxes, each episode at a random reachable placement, end
to end in the twin under a reality profile (``realistic``), and is measured on the unseen paper test boxes
(also placed at random) after 0, 0.25, 0.5, 1 and 2 hours of simulated robot experience, from three
starts:

- ``empty``: an empty memory (the paper's robot, which had no prior experience);
- ``symbolic``: a memory trained in the symbolic simulator only (``symbolic_episodes`` episodes), no robot
  time: what simulation is worth before a robot touches a box;
- ``symbolic+twin``: that symbolic memory, then experience in the twin.

With ``--test-set hard`` (:attr:`TwinLearningConfig.test_set`) the test boxes are the hard sets of
:mod:`puzzlebox.lab.hard_sets` (eight parts of every kind: random, multi-locker and chains, ``test_boxes`` of each
family), and training runs on generated boxes of the same families with other seeds
(:mod:`puzzlebox.lab.learning_boxes`); the multi-locker boxes are tried with a belief over sets of up to two lockers.
Every figure carries the test boxes' optimum beside it.

Each start is run for every training seed (the spread in the plot). Beside them, the deep agents
(``dqn``, ``model-based``: ``deep_agents``) trained to convergence in the symbolic simulator (the paper
protocols' 650 episodes on the 9 training variants, one network per training seed) run the same test trials:
the paper's robot figures for them are 5.4 and 21.2 actions. The cell is calibrated from ChArUco
images first (``lab.calibration_run``); training stores only what the robot sensed (``lab.twin_training``).

Everything is a task of ``puzzlebox.lab.runner`` (``--workers K``, or Ray): one training chain per start and
seed (its memory file grows episode by episode in ``DIR/memories/``, and a copy of it is taken at each
checkpoint, atomically: a chain killed part-way resumes from its file and its copies), then one trial per
start, seed, checkpoint, test box and placement (``DIR/trials/``), run once where memories hold the same (every
seed's empty memory, a seed's symbolic and symbolic+twin memories at 0 h: ``same_trial_as`` in the summary names
the trial that stands for another). The same command resumes. The summary
is ``DIR/twin-learning.{json,md,png}``: mean actions and success against robot hours, mean and spread over
seeds, with the paper's real-robot figures beside them.
"""

from __future__ import annotations

import dataclasses
import os
import sqlite3
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

from puzzlebox.lab.cli import write_json
from puzzlebox.lab.deep_protocols_run import job_task
from puzzlebox.lab.learning_boxes import LearningBox, test_boxes, training_boxes
from puzzlebox.lab.learning_optimum import family_table, with_optimum
from puzzlebox.lab.reality_sweep import calibrated_cell
from puzzlebox.lab.runner import RecordStore, Task, make_executor, run_tasks
from puzzlebox.lab.trial_task import trial_task
from puzzlebox.lab.twin_training import TwinTraining
from puzzlebox.learning import MemoryAgent, SymbolicWorld, run_episode, summarise
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.experiments.deep_protocols import TrainingJob, job_key
from puzzlebox.learning.experiments.protocol import ProtocolConfig
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.learning.memory.store import content_sha256
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.atomic import apply_umask
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.generator import TRAIN_INDICES, paper_family
from puzzlebox.models.spec_loading import spec_from_dict
from puzzlebox.twin.reality import RealityProfile, load_profile

HARD_TEST_BOXES = 2
"""Test boxes of each hard family in ``--test-set hard`` (x 3 families x ``placements``, at every checkpoint)."""
HARD_TRAIN_BOXES = 40
"""Training boxes of each hard family, chosen on validation boxes (seeds 5000-5009, never the test boxes), symbolic,
3 seeds each: 20 of each took 1.20 / 1.29 / 1.14 x the optimum on random / multi-locker / chain boxes, 40 of each
1.09 / 1.19 / 1.08."""
STARTS = ("empty", "symbolic", "symbolic+twin")
"""Where a learning curve starts (see the module docstring)."""
PAPER_ROBOT = {0.0: 26.0, 0.5: 10.0, 1.0: 8.8}
"""The paper's real robot: mean actions on an unseen box after that many hours of robot experience."""
PAPER_FINAL = 6.6
"""... and in its final trials (~30 training episodes)."""
PAPER_DEEP = {"dqn": 5.4, "model-based": 21.2}
"""The paper's deep agents on the real robot (model-free after 700 episodes; model-based, 3 of 5 timed out)."""


@dataclass(frozen=True)
class TwinLearningConfig:
    """What ``experiment.py twin-learning`` runs."""

    profile: str = "realistic"
    hours: tuple[float, ...] = (0.0, 0.25, 0.5, 1.0, 2.0)
    """Simulated robot experience at which the test boxes are measured [h]."""
    seeds: tuple[int, ...] = (0, 1)
    """Training seeds (each start is run once per seed)."""
    placements: int = 2
    """Random reachable placements of each test box, per checkpoint."""
    test_set: str = "paper"
    """``paper`` (the paper's test boxes, training on its 9 training boxes) or ``hard`` (the hard sets, training on
    generated boxes of their families: :mod:`puzzlebox.lab.learning_boxes`)."""
    test_boxes: int = 3
    """How many of the paper test boxes are measured (all three but in CI); with ``hard``, boxes of each family."""
    train_boxes: int = 9
    """With ``hard``: training boxes of each family (the paper's are its 9)."""
    symbolic_episodes: int = 9
    """Episodes of symbolic training of the ``symbolic`` starts (one per training box)."""
    max_actions: int = 30
    """Action budget of a test trial and of a training episode (the paper's robot timeout)."""
    train_seed: int = 70000
    """World seed of training episode e of seed s: ``train_seed + 1000 s + e``."""
    eval_seed: int = 60000
    """Placement seeds of the test trials: ``eval_seed + placement`` (the same at every checkpoint)."""
    cell_seed: int = 0
    calibrated: bool = True
    """Perceive through a calibration made in the cell from ChArUco images first (the paper's robot was calibrated);
    False: without a calibration file (the nominal cell), in training and in the test trials."""
    deep_agents: tuple[str, ...] = ("dqn", "model-based")
    """Deep agents measured beside the memory (trained in the symbolic simulator only; empty: none)."""
    deep_episodes: int = 650
    """Their symbolic training episodes over the 9 training variants (the paper protocols' converged count)."""
    deep_eval_runs: int = 10
    """Runs per unseen variant of their symbolic evaluation at the end of training (reported, not used)."""

    def quick(self) -> TwinLearningConfig:
        """CI size: checkpoints at 0 and 0.02 h, one seed, one placement of one test box, 6 actions; DQN
        trained 10 episodes. With ``hard``: one box of each family, 16 actions, 2 training boxes of each family,
        no deep agent."""
        if self.test_set == "hard":
            return dataclasses.replace(self, hours=(0.0, 0.02), seeds=(0,), placements=1, max_actions=16,
                                       test_boxes=1, train_boxes=2, symbolic_episodes=6)  # fmt: skip
        return dataclasses.replace(self, hours=(0.0, 0.02), seeds=(0,), placements=1, max_actions=6, test_boxes=1,
                                   deep_agents=("dqn",), deep_episodes=10, deep_eval_runs=1)  # fmt: skip

    def hard(self) -> TwinLearningConfig:
        """The hard test sets (module docstring): HARD_TEST_BOXES boxes of each family, HARD_TRAIN_BOXES training
        boxes of each, each once symbolically, a 40-action budget (a chain of 8 takes 8 at best), checkpoints at 0,
        0.5 and 1 h (the paper's robot's), no deep agent (theirs are trained on the paper's boxes)."""
        return dataclasses.replace(self, test_set="hard", test_boxes=HARD_TEST_BOXES, train_boxes=HARD_TRAIN_BOXES,
                                   symbolic_episodes=3 * HARD_TRAIN_BOXES, max_actions=40, hours=(0.0, 0.5, 1.0),
                                   deep_agents=())  # fmt: skip

    def starts(self) -> tuple[str, ...]:
        return STARTS

    def with_seed(self, seed: int) -> TwinLearningConfig:
        """Fresh placements and training episodes: test placements' world seeds from ``seed``, training episodes'
        from ``seed + 10000`` (``seed + 10000 + 1000 s + e``)."""
        if seed < 0:
            raise ValueError(f"a seed is >= 0, got {seed}")
        return dataclasses.replace(self, eval_seed=seed, train_seed=seed + 10000)


def snapshot_memory(store_path: Path, target: Path) -> None:
    """A consistent copy of the SQLite memory at ``store_path``, written to ``target`` atomically."""
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    os.close(fd)
    try:
        with sqlite3.connect(store_path) as source, sqlite3.connect(name) as copy:
            source.backup(copy)
        apply_umask(name)  # mkstemp made it private; the snapshot is not
        os.replace(name, target)
    finally:
        if os.path.exists(name):
            os.unlink(name)


def symbolic_training(
    store: MemoryStore, seed: int, episodes: int, max_actions: int, train: list[PuzzleSpec], lockers: list[int]
) -> None:
    """The ``symbolic`` starts' memory: ``episodes`` symbolic episodes on the training boxes ``train`` (box ``i``
    with a belief over up to ``lockers[i]`` lockers a part), seeded by ``seed``."""
    for e in range(episodes):
        spec, k = train[e % len(train)], lockers[e % len(train)]
        agent = MemoryAgent(store, learn=True, config=DualControllerConfig(max_lockers=k) if k != 1 else None)
        agent.episode_label, agent.episode_seed = spec.name, 1000 * seed + e
        run_episode(agent, SymbolicWorld(spec, 1000 * seed + e), spec.name, 1000 * seed + e, max_actions)


def _provenance(store: MemoryStore) -> dict[str, Any]:
    """``store.provenance()`` as the JSON-like object it is (per source a dict: episodes, robot hours...)."""
    return cast("dict[str, Any]", store.provenance())


def checkpoint_entry(copy: Path, hours: float) -> dict[str, Any]:
    """The record of the checkpoint at ``hours`` [h] whose memory is ``copy``: what that copy holds (a chain resumed
    after its copy was taken has a store that has grown since)."""
    store = MemoryStore.open_existing(copy)
    try:
        provenance = _provenance(store)
    finally:
        store.close()
    return {"hours": hours, "robot_hours": provenance["twin"]["robot_hours"], "memory": copy.name,
            "twin_episodes": provenance["twin"]["episodes"], "episodes": provenance["episodes"]}  # fmt: skip


def training_chain(settings: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """One start's learning in the twin (a runner task): its memory grows in ``context['dir']`` and is copied
    at each checkpoint of ``settings['hours']``; a chain killed part-way goes on from its file."""
    start, seed = settings["start"], settings["seed"]
    folder = Path(context["dir"])
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{start}-s{seed}.sqlite"
    store = MemoryStore(path)
    # the paper's training boxes unless the chain was given its own (--test-set hard; its settings then name them)
    train = [spec_from_dict(d) for d in settings["train"]] if "train" in settings else paper_family("train", seed=0)
    lockers = settings.get("train_max_lockers", [1] * len(train))
    try:
        if start != "empty" and store.num_episodes == 0:
            symbolic_training(store, seed, settings["symbolic_episodes"], settings["max_actions"], train, lockers)
        calibration = settings["calibration"]
        twin = TwinTraining(RealityProfile.from_dict(settings["reality"]),
                            CellCalibration.from_dict(calibration) if calibration is not None else None)  # fmt: skip
        hours = [0.0] if start == "symbolic" else sorted(settings["hours"])
        checkpoints, skipped, runs = [], [], []
        for h in hours:
            while _provenance(store)["twin"]["robot_hours"] < h:
                # (resumed: the episodes stored are not run again; one the cell could not run stores nothing)
                e = _provenance(store)["twin"]["episodes"] + len(skipped)
                spec, k = train[e % len(train)], lockers[e % len(train)]
                controller = twin.controller if k == 1 else dataclasses.replace(twin.controller, max_lockers=k)
                agent = MemoryAgent(store, learn=True, config=controller)
                episode_seed = settings["train_seed"] + 1000 * seed + e
                agent.episode_label, agent.episode_seed = spec.name, episode_seed
                before = store.num_episodes
                result = twin.episode(agent, spec, episode_seed, settings["max_actions"])
                runs.append({"episode": e, "spec": spec.name, "seed": agent.episode_seed, "solved": result.solved,
                             "num_actions": result.num_actions, "ended": result.ended})  # fmt: skip
                if store.num_episodes == before:
                    skipped.append({"episode": e, "spec": spec.name, "ended": result.ended})
            target = folder / f"{start}-s{seed}@{h:g}h.sqlite"
            if not target.exists():
                snapshot_memory(path, target)
            checkpoints.append(checkpoint_entry(target, h))
        log = store.training_log()  # each run's "episodes": a list
    finally:
        store.close()
    return {"start": start, "seed": seed, "checkpoints": checkpoints, "skipped": skipped, "runs": runs,
            "episodes": [e for run in log for e in cast(list, run["episodes"])]}  # fmt: skip


def run_twin_learning(
    out: Path, config: TwinLearningConfig, workers: int | None = None, ray: str | None = None
) -> dict[str, Any]:
    """Run (or resume) the experiment into ``out``; returns the summary written to ``out/twin-learning.json``.

    Raises:
        LearningError: a task failed (every other one is kept for the resume).
    """
    out.mkdir(parents=True, exist_ok=True)
    reality = load_profile(config.profile)
    tests = test_boxes(config.test_set, config.test_boxes, out / "specs")
    train: list[LearningBox] = []
    if config.test_set != "paper":  # (the paper's chains keep the settings they had: their records resume)
        train = training_boxes(config.test_set, config.train_boxes, out / "specs")
    begin = time.perf_counter()
    phases: dict[str, float] = {}
    deep_records: dict[str, Any] = {}
    with make_executor(workers, ray) as executor:
        calibration = calibrated_cell(reality, out / "calibrations", executor) if config.calibrated else None
        memories = out / "memories"
        chains = [
            Task(f"{start}-s{seed}", training_chain, {
                "start": start, "seed": seed, "hours": list(config.hours), "reality": reality.to_dict(),
                "calibration": calibration, "symbolic_episodes": config.symbolic_episodes,
                "max_actions": config.max_actions, "train_seed": config.train_seed,
                **({"train": [b.spec.to_dict() for b in train],
                    "train_max_lockers": [b.max_lockers for b in train]} if train else {}),
            }, context={"dir": str(memories)})
            for start in STARTS for seed in config.seeds
        ]  # fmt: skip
        phases["calibration_s"] = time.perf_counter() - begin
        deep_jobs = _deep_jobs(config, out / "deep")
        if deep_jobs:
            deep = run_tasks(deep_jobs, RecordStore(out / "deep" / "jobs"), executor, desc="deep agents (symbolic)")
            deep.raise_for_failures()
            deep_records = deep.records
        phases["deep_training_s"] = time.perf_counter() - begin - sum(phases.values())
        trained = run_tasks(chains, RecordStore(out / "chains"), executor, desc="training in the twin")
        trained.raise_for_failures()
        phases["twin_training_s"] = time.perf_counter() - begin - sum(phases.values())
        trials, where = [], {}
        same_trial_as: dict[str, str] = {}  # a checkpoint's trial -> the same trial of an identical memory
        first_of: dict[tuple[str, str, int], str] = {}
        for chain in chains:
            record = trained.records[chain.key]
            for checkpoint in record["checkpoints"]:
                # a seed's symbolic and symbolic+twin memories at 0 h are one memory, every seed's empty one another:
                # their trials are run once (a trial is a function of the memory's content, the box and its placement)
                content = content_sha256(memories / checkpoint["memory"])
                for box in tests:
                    for placement in range(config.placements):
                        key = f"{chain.key}@{checkpoint['hours']:g}h-{box.spec.name}-p{placement}"
                        where[key] = (record["start"], record["seed"], checkpoint["hours"])
                        first = first_of.setdefault((content, box.spec.name, placement), key)
                        if first != key:
                            same_trial_as[key] = first
                            continue
                        trials.append(trial_task(
                            key, box.spec, config.eval_seed + placement, sim="twin", agent="memory",
                            max_actions=config.max_actions, memory=str(memories / checkpoint["memory"]),
                            reality=reality.to_dict(), calibration=calibration, max_lockers=box.max_lockers,
                        ))  # fmt: skip
        for job in deep_jobs:
            record = deep_records[job.key]
            agent, seed = job.settings["job"]["agent"], job.settings["job"]["seed"]
            for box in tests:
                for placement in range(config.placements):
                    key = f"{job.key}-{box.spec.name}-p{placement}"
                    trials.append(trial_task(
                        key, box.spec, config.eval_seed + placement, sim="twin", agent=agent,
                        max_actions=config.max_actions, checkpoint=str(out / "deep" / "jobs" / record["checkpoint"]),
                        reality=reality.to_dict(), calibration=calibration,
                    ))  # fmt: skip
                    where[key] = (agent, seed, 0.0)
        measured = run_tasks(trials, RecordStore(out / "trials"), executor, desc="test trials",
                             postfix=lambda r: f"solved {sum(x['solved'] for x in r.values())}/{len(r)}")  # fmt: skip
        measured.raise_for_failures()
        phases["test_trials_s"] = time.perf_counter() - begin - sum(phases.values())
    records = {**measured.records, **{key: measured.records[first] for key, first in same_trial_as.items()}}
    summary = _summary(config, reality.name, trained.records, records, where, deep_records)
    summary = with_optimum(summary, records, where, tests, config.max_actions)
    summary["same_trial_as"] = same_trial_as
    summary["wall_time_s"] = time.perf_counter() - begin
    summary["wall_time_by_phase_s"] = phases
    write_json(out / "twin-learning.json", summary)
    (out / "twin-learning.md").write_text(markdown(summary))
    plot(summary, out / "twin-learning.png")
    return summary


def _deep_jobs(config: TwinLearningConfig, folder: Path) -> list[Task]:
    """One runner task per deep agent and training seed: the paper protocols' k = 9 training job, trained
    ``deep_episodes`` episodes, its network written to ``folder/jobs/<agent>-v9-s<seed>.pt``."""
    protocol = ProtocolConfig(runs_per_variant=config.deep_eval_runs)
    return [
        job_task(TrainingJob(agent, len(TRAIN_INDICES), seed, (config.deep_episodes,)), protocol, folder)
        for agent in config.deep_agents for seed in config.seeds
    ]  # fmt: skip


def _summary(config, profile, chains, trials, where, deep=None) -> dict[str, Any]:
    points = []
    for start in STARTS:
        for hours in [0.0] if start == "symbolic" else sorted(config.hours):
            per_seed = []
            for seed in config.seeds:
                runs = [trials[k] for k, w in where.items() if w == (start, seed, hours)]
                figures = summarise(runs, config.max_actions)
                chain = chains[f"{start}-s{seed}"]
                robot = next(c["robot_hours"] for c in chain["checkpoints"] if c["hours"] == hours)
                per_seed.append({"seed": seed, "trials": len(runs), "success_rate": figures["success_rate"],
                                 "mean_actions": figures["mean_actions"], "robot_hours": robot})  # fmt: skip
            points.append({"start": start, "hours": hours, **_over_seeds(per_seed), "seeds": per_seed})
    for agent in config.deep_agents:
        per_seed = []
        for seed in config.seeds:
            runs = [trials[k] for k, w in where.items() if w == (agent, seed, 0.0)]
            figures = summarise(runs, config.max_actions)
            job = (deep or {}).get(job_key(agent, len(TRAIN_INDICES), seed), {})
            symbolic = next(iter(job.get("evaluations", [])), {})
            per_seed.append({"seed": seed, "trials": len(runs), "success_rate": figures["success_rate"],
                             "mean_actions": figures["mean_actions"], "robot_hours": 0.0,
                             "symbolic_success_rate": symbolic.get("success_rate"),
                             "symbolic_mean_actions": symbolic.get("mean_actions")})  # fmt: skip
        points.append({"start": agent, "deep": True, "hours": 0.0, "training_episodes": config.deep_episodes,
                       **_over_seeds(per_seed), "seeds": per_seed, "paper_robot": PAPER_DEEP.get(agent)})  # fmt: skip
    return {"config": dataclasses.asdict(config), "profile": profile, "points": points,
            "training": _training_outcomes(chains), "paper_robot": {str(h): a for h, a in PAPER_ROBOT.items()},
            "paper_final": PAPER_FINAL, "paper_deep": PAPER_DEEP}  # fmt: skip


def _over_seeds(per_seed: list[dict[str, Any]]) -> dict[str, float]:
    """Mean and spread (population std) over training seeds of the mean actions and the success rate."""
    out = {}
    for key in ("mean_actions", "success_rate"):
        values = [s[key] for s in per_seed]
        out[key], out[f"{key}_std"] = statistics.fmean(values), statistics.pstdev(values)
    return out


def _training_outcomes(chains: dict[str, Any]) -> dict[str, Any]:
    """Per start, over seeds: the twin training episodes run, solved, and why the others ended (box, part, error;
    "out of actions" when the budget ran out). Episodes of an execution that was resumed are counted from the
    part that ran last."""
    out: dict[str, Any] = {}
    for chain in chains.values():
        entry = out.setdefault(chain["start"], {"episodes": 0, "solved": 0, "ended": {}})
        for run in chain.get("runs", []):
            entry["episodes"] += 1
            entry["solved"] += run["solved"]
            if not run["solved"]:
                parts = run["ended"].split(": ")
                why = f"{run['spec']} {': '.join(parts[:2])}" if run["ended"] else f"{run['spec']} out of actions"
                entry["ended"][why] = entry["ended"].get(why, 0) + 1
    return {k: v for k, v in out.items() if v["episodes"]}


def markdown(summary: dict[str, Any]) -> str:
    config = summary["config"]
    paper_set = config.get("test_set", "paper") == "paper"
    boxes = (
        "on the paper training boxes at random placements, measured on the unseen test boxes"
        if paper_set
        else f"on generated eight-part boxes ({config['train_boxes']} of each hard family) at random placements, "
        f"measured on the held-out hard sets ({config['test_boxes']} boxes of each family)"
    )
    lines = [
        "# Learning in the twin: the paper's robot learning curve, closed in simulation",
        "",
        f"The memory agent trained end to end in the twin (`{summary['profile']}` profile, "
        f"{'calibrated first' if config.get('calibrated', True) else 'without a calibration file'}) {boxes} "
        f"({config['placements']} random placements each, from world seed {config['eval_seed']}; "
        f"{config['max_actions']} actions per trial), mean and "
        f"spread over {len(config['seeds'])} training seed(s).",
        "",
        "| start | robot hours | solved | mean actions | optimum | ratio | peak force [N] | paper (real robot) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for p in summary["points"]:
        paper = (PAPER_ROBOT.get(p["hours"]) if p["start"] == "empty" else p.get("paper_robot")) if paper_set else None
        start = f"{p['start']} ({p['training_episodes']} symbolic episodes)" if p.get("deep") else p["start"]
        optimum = f"{p['optimum']:.2f} | {p['ratio_to_optimum']:.2f}" if "optimum" in p else "- | -"
        force = f"{p['peak_true_wrist_force_n']:.1f}" if p.get("peak_true_wrist_force_n") is not None else "-"
        lines.append(
            f"| {start} | {p['hours']:g} | {p['success_rate']:.1%} ± {p['success_rate_std']:.1%} "
            f"| {p['mean_actions']:.2f} ± {p['mean_actions_std']:.2f} | {optimum} | {force} "
            f"| {'-' if paper is None else paper} |"
        )
    lines += ["", *family_table(summary)]
    if paper_set:
        lines += [f"The paper's robot in its final trials: {PAPER_FINAL} actions.", ""]
    for start, t in summary.get("training", {}).items():
        reasons = "; ".join(f"{why} x{n}" for why, n in sorted(t["ended"].items(), key=lambda kv: -kv[1]))
        lines += [f"Training in the twin, `{start}`: {t['solved']} of {t['episodes']} episodes solved"
                  + (f"; the others ended: {reasons}." if reasons else "."), ""]  # fmt: skip
    if "wall_time_s" in summary:
        phases = ", ".join(f"{k.removesuffix('_s').replace('_', ' ')} {v / 60:.1f}"
                           for k, v in summary.get("wall_time_by_phase_s", {}).items())  # fmt: skip
        lines += [f"Wall time: {summary['wall_time_s'] / 60:.1f} min ({phases} min).", ""]
    return "\n".join(lines)


def plot(summary: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
    hours = sorted(summary["config"]["hours"])
    for start in STARTS:
        pts = [p for p in summary["points"] if p["start"] == start]
        if start == "symbolic":  # no robot time: a flat line across the curve
            pts = [dict(pts[0], hours=h) for h in hours]
        for ax, key in zip(axes, ("mean_actions", "success_rate"), strict=True):
            ax.errorbar([p["hours"] for p in pts], [p[key] for p in pts], yerr=[p[f"{key}_std"] for p in pts],
                        marker="o", capsize=3, label=start, linestyle="--" if start == "symbolic" else "-")  # fmt: skip
    deep = [p for p in summary["points"] if p.get("deep")]
    for i, p in enumerate(deep):  # no robot time: a flat line, its seeds' spread shaded
        for ax, key in zip(axes, ("mean_actions", "success_rate"), strict=True):
            color = f"C{3 + i}"
            ax.axhline(p[key], linestyle=":", color=color, label=f"{p['start']} (symbolic only)")
            ax.axhspan(p[key] - p[f"{key}_std"], p[key] + p[f"{key}_std"], color=color, alpha=0.07)
        if p.get("paper_robot") is not None:
            axes[0].plot([hours[-1]], [p["paper_robot"]], "kx", markersize=8)
            axes[0].annotate(f"paper {p['start']}", (hours[-1], p["paper_robot"]), fontsize=7,
                             textcoords="offset points", xytext=(-40, 4))  # fmt: skip
    optimum = [p["optimum"] for p in summary["points"] if "optimum" in p]
    if optimum:
        axes[0].axhline(optimum[0], color="C2", linestyle="-.", linewidth=1, label="optimum (test boxes' mean)")
    if summary["config"].get("test_set", "paper") == "paper":  # the paper's robot met the paper's boxes only
        axes[0].plot(list(PAPER_ROBOT), list(PAPER_ROBOT.values()), "k*", markersize=10, label="paper, real robot")
        axes[0].axhline(PAPER_FINAL, color="k", linestyle=":", linewidth=1, label="paper, final trials")
    axes[0].set_ylabel("mean actions (unsolved count the budget)")
    axes[1].set_ylabel("solved [-]")
    for ax in axes:
        ax.set_xlabel("simulated robot experience [h]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    test_set = summary["config"].get("test_set", "paper")
    fig.suptitle(f"learning in the twin ({summary['profile']}, {test_set} test set)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
