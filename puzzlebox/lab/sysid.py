"""``experiment.py sysid``: the twin learns from the world — system identification of the box's per-kind joint
damping, joint friction and latch compliance from logged robot data of toggles.

For each cell (``cell_seeds``: one box hardware each, its per-kind factors drawn from the cell seed; the
``realistic`` profile), the cameras are calibrated from ChArUco images first (``lab.calibration_run``), as in the
other twin experiments. Then the oracle agent solves the paper training boxes (at random reachable placements:
``train_seeds``) and the unseen paper test boxes (``test_seeds``) end to end, every toggle logged as robot data
only (:class:`skills.toggle_recorder.ToggleRecorder`; ``DIR/logs/*.npz``); beside the logs, for evaluation only,
the world's true joint trajectory of each toggled part and the cell's true factors (never read by a fit). Each
kind's factors are fitted on the training toggles of its cell (:func:`twin.system_id.fit_kind`), and the
nominal twin's predictions of the held-out test toggles are scored with the nominal factors (1), the fitted ones
and — evaluation only, the floor a perfect identification would reach — the cell's true ones
(:func:`twin.toggle_scoring.toggle_errors`): the joint load [N] (the wrench's generalized force on the part's
joint, at the grasp point: what is fitted), the same less what a pose error explains, the whole force vector [N]
and the part's motion [mm].

The replay is given the robot's timing (command latency, the F/T sensor's rate and delay) and grip (the pads'
friction at the grip force set) from the datasheets (REALITY_NOTES.md Presets: the numbers the ``realistic``
profile uses too): properties of the robot, not of the box, and not identified here.

Everything is a task of ``puzzlebox.lab.runner`` (``--workers K``): calibrations, recorded trials, fits (one per cell
and kind) and evaluations (one per cell); each record is written atomically as it ends (``DIR/records/``), with
a progress bar per stage on a terminal, and the same command resumes, reusing them (Ctrl-C keeps what finished).
The summary is ``DIR/sysid.{json,md,png}``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.lab.cli import write_json
from puzzlebox.lab.reality_sweep import calibration_task
from puzzlebox.lab.runner import RecordStore, Task, make_executor, run_tasks
from puzzlebox.learning import make_agent, run_episode
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.generator import paper_family
from puzzlebox.models.kinds import KIND_NAMES
from puzzlebox.models.spec_loading import spec_from_dict
from puzzlebox.models.toggle_log import load_toggles, save_toggles
from puzzlebox.twin.pose_error import PoseErrorConfig
from puzzlebox.twin.reality import RealityProfile, load_profile
from puzzlebox.twin.system_id import FitConfig
from puzzlebox.twin.toggle_replay import KindScales, ReplayConfig
from puzzlebox.twin.toggle_scoring import pooled_rms, prepare, toggle_errors
from puzzlebox.twin.toggle_signals import SignalConfig

TARGET_RATIO = 0.5
"""The issue's target: the held-out joint-load error at most half the nominal twin's."""


@dataclass(frozen=True)
class SysIdConfig:
    """What ``experiment.py sysid`` runs."""

    profile: str = "realistic"
    cell_seeds: tuple[int, ...] = (0, 1, 2)
    """One box hardware (and camera set) per cell seed: the first three, none chosen."""
    train_boxes: tuple[int, ...] = tuple(range(9))
    """Indices of the paper training boxes solved for training data."""
    train_seeds: tuple[int, ...] = (1000,)
    """Trial seeds (placements) of each training box."""
    test_boxes: tuple[int, ...] = (0, 1, 2)
    """Indices of the paper test boxes solved for held-out data."""
    test_seeds: tuple[int, ...] = (2000, 2001)
    """Trial seeds (placements) of each test box."""
    agent: str = "oracle"
    """The agent that solves the boxes (the oracle needs no memory: five toggles per paper box)."""
    max_actions: int = 12
    command_latency: float = 0.005
    """The robot's command latency [s] (REALITY_NOTES Presets "command latency" 5 ms, §2 U11)."""
    ft_rate_hz: float = 100.0
    """The F/T sensor's rate [Hz] (Presets "F/T rate, delay" 100 Hz, §1 U3)."""
    ft_delay: float = 0.010
    """The F/T sensor's delay [s] (Presets "F/T rate, delay" 10 ms, §1)."""
    handle_friction: float = 0.4 * 0.5
    """The gripper's pads on a handle [-]: mu 0.4 (Presets "grip force, pad μ", §5 P1) at the 15 N grip set of the
    gripper's 30 N (§5 U14), applied as the twin applies a grip (``twin.physics_draws``)."""
    fit: FitConfig = field(default_factory=FitConfig)
    signals: SignalConfig = field(default_factory=SignalConfig)
    pose: PoseErrorConfig = field(default_factory=PoseErrorConfig)
    examples: int = 3
    """Held-out toggles whose predicted and logged joint loads are drawn (one per kind, from the first cell)."""

    def quick(self) -> SysIdConfig:
        """CI size: one cell, three training boxes (every kind), one placement of each test box, short fits."""
        return dataclasses.replace(
            self, cell_seeds=(1,), train_boxes=(0, 5, 6), test_seeds=(2000,),
            fit=dataclasses.replace(self.fit, max_nfev=8),
        )  # fmt: skip

    def replay(self) -> ReplayConfig:
        return ReplayConfig(
            command_latency=self.command_latency, ft_rate_hz=self.ft_rate_hz, ft_delay=self.ft_delay,
            handle_friction=self.handle_friction,
        )  # fmt: skip


# -- recorded trials ------------------------------------------------------------------------------


class TruthTrace:
    """Evaluation only: the world's true joint position of every component at every wrench reading (the
    pipeline's ticks), by robot time. Sits under the recorder, so its readings are the recorder's instants."""

    def __init__(self, robot: Any, session: Any) -> None:
        self._robot, self._session = robot, session
        self.times: dict[float, int] = {}
        self.positions: list[np.ndarray] = []

    def __getattr__(self, name: str) -> Any:
        return getattr(self._robot, name)

    def wrench(self) -> np.ndarray:
        w = self._robot.wrench()
        self.times.setdefault(self._robot.time, len(self.positions))
        self.positions.append(self._session.component_positions())
        return w

    def joint_of(self, index: int, times: np.ndarray) -> list[float]:
        return [float(self.positions[self.times[float(t)]][index]) for t in times]


def record_task(settings: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """Solve one box in the twin with every toggle logged (a runner task); the log goes to ``context["log"]``."""
    from puzzlebox.lab.twin_trial import evaluation_world  # MuJoCo and rendering only in the task
    from puzzlebox.learning.belief import CELL_BELIEF
    from puzzlebox.skills import SkillError
    from puzzlebox.skills.toggle_recorder import ToggleRecorder
    from puzzlebox.twin.errors import SimulationDiverged
    from puzzlebox.twin.session import TwinSession

    start = time.perf_counter()
    spec, seed = spec_from_dict(settings["spec"]), settings["seed"]
    profile = RealityProfile.from_dict(settings["profile"])
    calibration = CellCalibration.from_dict(settings["calibration"])
    with TwinSession(spec, seed=seed, reality=profile) as session:
        trace = TruthTrace(session.robot, session)
        # a Robot: TruthTrace forwards every call but wrench() to session.robot (__getattr__, unseen by pyright)
        recorder = ToggleRecorder(trace, {"spec": spec.name, "seed": seed, "cell_seed": profile.cell_seed})  # pyright: ignore[reportArgumentType]
        world = evaluation_world(session, recorder, calibration, seed)
        recorder.attach(world)
        agent = make_agent(settings["agent"], session.spec, None, None, belief=CELL_BELIEF)
        try:
            result = run_episode(agent, world, spec.name, seed, settings["max_actions"])
            solved, actions, ended = result.solved, result.num_actions, result.ended
        except (SkillError, SimulationDiverged) as err:  # the toggles logged so far are kept
            solved, actions, ended = False, len(world.log), f"{type(err).__name__}: {err}"
        kinds = session.cell.kinds.to_dict()
        index = {c.name: i for i, c in enumerate(session.spec.components)}
    for log in recorder.toggles:  # evaluation only: the truth beside the robot data, never fitted on
        log.truth = {"joint": trace.joint_of(index[log.component], log.time), "kind_factors": kinds}
    save_toggles(context["log"], recorder.toggles, {"spec": spec.name, "seed": seed, "cell_seed": profile.cell_seed})
    outcomes: dict[str, int] = {}
    for log in recorder.toggles:
        outcomes[log.outcome] = outcomes.get(log.outcome, 0) + 1
    return {
        "spec": spec.name, "seed": seed, "cell_seed": profile.cell_seed, "solved": solved,
        "num_actions": actions, "ended": ended, "toggles": len(recorder.toggles), "outcomes": outcomes,
        "true_kind_factors": kinds, "wall_time_s": time.perf_counter() - start,
    }  # fmt: skip


# -- fits and evaluations -------------------------------------------------------------------------


def _logs(directory: str, names: list[str]) -> list[Any]:
    logs = []
    for name in names:
        path = Path(directory) / "logs" / f"{name}.npz"
        if not path.is_file():
            raise FileNotFoundError(f"{path}: the log of a finished trial is missing; delete DIR/records to redo")
        logs += load_toggles(path)[0]
    return logs


def _configs(settings: dict[str, Any]) -> tuple[ReplayConfig, SignalConfig, PoseErrorConfig, FitConfig]:
    pose = PoseErrorConfig(**{**settings["pose"], "sigma": tuple(settings["pose"]["sigma"])})
    return ReplayConfig(**settings["replay"]), SignalConfig(**settings["signals"]), pose, FitConfig(**settings["fit"])


def fit_task(settings: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """Fit one kind of one cell on its training logs (a runner task)."""
    from puzzlebox.twin.system_id import fit_kind

    replay, signals, pose, fit = _configs(settings)
    ready, skipped = prepare(_logs(context["dir"], settings["logs"]), replay, signals, pose)
    kind = settings["kind"]
    if not any(t.log.kind == kind for t in ready):
        return {"kind": kind, "toggles": 0, "skipped": skipped}
    return {**fit_kind(kind, ready, fit).to_dict(), "skipped": [s for s in skipped if kind in s]}


def evaluate_task(settings: dict[str, Any], context: dict[str, Any]) -> dict[str, Any]:
    """Score the held-out logs of one cell with the nominal and the fitted factors (a runner task)."""
    replay, signals, pose, _ = _configs(settings)
    ready, skipped = prepare(_logs(context["dir"], settings["logs"]), replay, signals, pose)
    fitted = {k: KindScales(*v) for k, v in settings["factors"].items()}
    toggles, examples = [], []
    shown: set[str] = set()
    for t in ready:
        nominal = toggle_errors(t)
        scales = fitted.get(t.log.kind, KindScales())
        after = toggle_errors(t, scales)
        assert t.log.truth is not None  # record_task gives every logged toggle its truth
        true = t.log.truth["kind_factors"]  # evaluation only: how far a perfect identification would get
        kind = t.log.kind
        at_truth = toggle_errors(t, KindScales(true["joint_damping"][kind], true["joint_friction"][kind],
                                               true["latch_compliance"][kind]))  # fmt: skip
        toggles.append({"nominal": nominal.to_dict(), "fitted": after.to_dict(), "true": at_truth.to_dict()})
        if t.log.kind not in shown and len(examples) < settings["examples"]:
            shown.add(t.log.kind)
            examples.append(_series(t, scales))
    return {"toggles": toggles, "skipped": skipped, "examples": examples}


def _series(toggle: Any, scales: KindScales) -> dict[str, Any]:
    """The logged and predicted joint loads of a toggle over its compared ticks, for the plot."""
    nominal, fitted = toggle.predict()[0], toggle.predict(scales)[0]
    n = len(nominal)
    m = toggle.mask[:n]
    t = toggle.log.time[toggle.replay.window][:n][m]
    return {
        "component": toggle.log.component, "kind": toggle.log.kind, "context": toggle.log.context,
        "time_s": (t - t[0]).round(3).tolist(), "logged_n": toggle.logged_load[:n][m].round(4).tolist(),
        "nominal_n": nominal[m].round(4).tolist(), "fitted_n": fitted[m].round(4).tolist(),
    }  # fmt: skip


# -- the run --------------------------------------------------------------------------------------


def _trial_key(cell: int, split: str, name: str, seed: int) -> str:
    return f"cell{cell}-{split}-{name}-seed{seed}"


def run_sysid(out: Path, config: SysIdConfig, workers: int | None = None) -> dict[str, Any]:
    """Run (or resume) the experiment into ``out``; returns the summary also written to ``out/sysid.json``.

    Raises:
        LearningError: a task failed (every other one is kept for the resume) or the run was interrupted.
    """
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    base = load_profile(config.profile)
    profiles = {c: dataclasses.replace(base, cell_seed=c) for c in config.cell_seeds}
    train, test = paper_family("train", seed=0), paper_family("test", seed=0)
    records = out / "records"
    settings = {"replay": dataclasses.asdict(config.replay()), "signals": dataclasses.asdict(config.signals),
                "pose": dataclasses.asdict(config.pose), "fit": dataclasses.asdict(config.fit)}  # fmt: skip
    with make_executor(workers, None) as executor:
        calibrations = [
            Task(f"calibration-cell{c}", calibration_task, {"spec": test[0].to_dict(), "profile": p.to_dict()})
            for c, p in profiles.items()
        ]
        done = run_tasks(calibrations, RecordStore(records / "calibrations"), executor, desc="calibrations")
        done.raise_for_failures()
        trials, keys = [], {c: {"train": [], "test": []} for c in config.cell_seeds}
        for c, profile in profiles.items():
            calibration = done.records[f"calibration-cell{c}"]["calibration"]
            for split, boxes, seeds, family in (("train", config.train_boxes, config.train_seeds, train),
                                                ("test", config.test_boxes, config.test_seeds, test)):  # fmt: skip
                for i in boxes:
                    for seed in seeds:
                        key = _trial_key(c, split, family[i].name, seed)
                        keys[c][split].append(key)
                        trials.append(Task(key, record_task, {
                            "spec": family[i].to_dict(), "seed": seed, "profile": profile.to_dict(),
                            "calibration": calibration, "agent": config.agent, "max_actions": config.max_actions,
                        }, context={"log": str(out / "logs" / f"{key}.npz")}))  # fmt: skip
        report = run_tasks(trials, RecordStore(records / "trials"), executor, desc="recorded trials",
                           postfix=lambda r: f"toggles {sum(x['toggles'] for x in r.values())}")  # fmt: skip
        report.raise_for_failures()
        trial_records = report.records
        fits = [
            Task(f"fit-cell{c}-{kind}", fit_task, {**settings, "kind": kind, "logs": keys[c]["train"]},
                 context={"dir": str(out)})
            for c in config.cell_seeds for kind in KIND_NAMES
        ]  # fmt: skip
        fitted = run_tasks(fits, RecordStore(records / "fits"), executor, desc="fits")
        fitted.raise_for_failures()
        factors = {
            c: {k: list(fitted.records[f"fit-cell{c}-{k}"]["factors"].values())
                for k in KIND_NAMES if fitted.records[f"fit-cell{c}-{k}"].get("toggles")}
            for c in config.cell_seeds
        }  # fmt: skip
        evaluations = [
            Task(f"evaluate-cell{c}", evaluate_task,
                 {**settings, "logs": keys[c]["test"], "factors": factors[c],
                  "examples": config.examples if c == config.cell_seeds[0] else 0},
                 context={"dir": str(out)})
            for c in config.cell_seeds
        ]  # fmt: skip
        evaluated = run_tasks(evaluations, RecordStore(records / "evaluations"), executor, desc="evaluations")
        evaluated.raise_for_failures()
    reports = (done, report, fitted, evaluated)
    tasks = {
        "planned": sum(r.planned for r in reports), "reused": sum(len(r.reused) for r in reports),
        "task_time_s": sum(x.get("wall_time_s", 0.0) for r in (report, fitted) for x in r.records.values()),
    }  # fmt: skip
    summary = summarise(config, trial_records, fitted.records, evaluated.records, time.perf_counter() - start, tasks)
    write_report(summary, out)
    return summary


# -- the summary ----------------------------------------------------------------------------------


@dataclass
class _Errors:
    """Held-out errors of a group of toggles, nominal and fitted."""

    rows: list[dict[str, Any]]

    def figures(self) -> dict[str, Any]:
        from puzzlebox.twin.toggle_scoring import ToggleErrors

        def pooled(which: str, attribute: str) -> float | None:
            return pooled_rms([ToggleErrors(**r[which]) for r in self.rows], attribute)

        out: dict[str, Any] = {"toggles": len(self.rows), "ticks": sum(r["nominal"]["ticks"] for r in self.rows)}
        for attribute, name in (("load_rms", "load_rms_n"), ("pose_load_rms", "pose_load_rms_n"),
                                ("force_rms", "force_rms_n"), ("motion_rms", "motion_rms_m")):  # fmt: skip
            before, after, true = pooled("nominal", attribute), pooled("fitted", attribute), pooled("true", attribute)
            out[name] = {"nominal": before, "fitted": after, "true_factors": true,
                         "ratio": after / before if before and after is not None else None,
                         "true_ratio": true / before if before and true is not None else None}  # fmt: skip
        per_toggle = [r["fitted"]["load_rms"] / r["nominal"]["load_rms"] for r in self.rows if r["nominal"]["load_rms"]]
        out["toggles_improved"] = sum(v < 1 for v in per_toggle)
        return out


def summarise(
    config: SysIdConfig,
    trials: dict[str, dict[str, Any]],
    fits: dict[str, dict[str, Any]],
    evaluations: dict[str, dict[str, Any]],
    wall_time_s: float,
    tasks: dict[str, Any],
) -> dict[str, Any]:
    cells, all_rows = [], []
    for c in config.cell_seeds:
        rows = evaluations[f"evaluate-cell{c}"]["toggles"]
        all_rows += rows
        truth = next(r["true_kind_factors"] for r in trials.values() if r["cell_seed"] == c)
        kinds = {}
        for kind in KIND_NAMES:
            fit = fits[f"fit-cell{c}-{kind}"]
            mine = [r for r in rows if r["nominal"]["kind"] == kind]
            kinds[kind] = {
                "true_factors": {"damping": truth["joint_damping"][kind], "friction": truth["joint_friction"][kind],
                                 "latch": truth["latch_compliance"][kind]},
                "fit": fit, "held_out": _Errors(mine).figures(),
            }  # fmt: skip
        cells.append({"cell_seed": c, "kinds": kinds, "held_out": _Errors(rows).figures(),
                      "skipped_held_out": evaluations[f"evaluate-cell{c}"]["skipped"]})  # fmt: skip
    overall = _Errors(all_rows).figures()
    per_kind = {k: _Errors([r for r in all_rows if r["nominal"]["kind"] == k]).figures() for k in KIND_NAMES}
    ratio = overall["load_rms_n"]["ratio"]
    return {
        "config": dataclasses.asdict(config), "cells": cells, "held_out": overall, "held_out_per_kind": per_kind,
        "target_ratio": TARGET_RATIO, "target_met": ratio is not None and ratio <= TARGET_RATIO,
        "trials": {"count": len(trials), "solved": sum(r["solved"] for r in trials.values()),
                   "toggles": sum(r["toggles"] for r in trials.values())},
        "examples": [e for ev in evaluations.values() for e in ev["examples"]], "wall_time_s": wall_time_s,
        "tasks": tasks,
    }  # fmt: skip


def write_report(summary: dict[str, Any], out: Path) -> None:
    """``sysid.json``, ``sysid.md`` and ``sysid.png``, each written atomically."""
    from puzzlebox.models.atomic import write_atomically, write_text_atomically

    write_json(out / "sysid.json", summary)
    write_text_atomically(out / "sysid.md", markdown(summary))
    write_atomically(out / "sysid.png", lambda tmp: plot(summary, tmp))


def _fmt(value: float | None, scale: float = 1.0, digits: int = 3) -> str:
    return "-" if value is None or not math.isfinite(value) else f"{value * scale:.{digits}f}"


def _pair(figure: dict[str, Any], scale: float = 1.0) -> str:
    ratio = figure["ratio"]
    return f"{_fmt(figure['nominal'], scale)} → {_fmt(figure['fitted'], scale)} (×{_fmt(ratio, digits=2)})"


def _truth(figure: dict[str, Any]) -> str:
    return f"{_fmt(figure['true_factors'])} (×{_fmt(figure['true_ratio'], digits=2)})"


def markdown(summary: dict[str, Any]) -> str:
    overall, cfg = summary["held_out"], summary["config"]
    lines = [
        "# System identification: the twin learns the box from the world",
        "",
        f"Profile `{cfg['profile']}`, cells {cfg['cell_seeds']} (one box hardware each), the oracle agent on the paper "
        f"training boxes {list(cfg['train_boxes'])} (seeds {list(cfg['train_seeds'])}) for fitting and on the unseen "
        f"test boxes {list(cfg['test_boxes'])} (seeds {list(cfg['test_seeds'])}) held out; "
        f"{summary['trials']['count']} trials ({summary['trials']['solved']} solved), "
        f"{summary['trials']['toggles']} toggles logged.",
        "",
        "Held-out errors, nominal twin → fitted twin (× ratio), RMS over the compared ticks. Joint load: the "
        "wrench's generalized force on the part's joint, at the grasp point (what is fitted); less pose: less what "
        "an error of the part's perceived pose explains of it; force: the whole force vector; motion: the part's "
        "path against the world's (evaluation-only truth). At true factors: the joint-load error of the nominal twin "
        "given the cell's true factors (evaluation only): how far a perfect identification of them would get.",
        "",
        f"**Overall: joint load {_pair(overall['load_rms_n'])} N over {overall['toggles']} toggles — target ×"
        f"{summary['target_ratio']:.2f}: {'met' if summary['target_met'] else 'NOT met'}; at the true factors "
        f"{_truth(overall['load_rms_n'])} N.**",
        "",
        "| cell | kind | train / held-out toggles | true (damping, friction, latch) | fitted | joint load [N] "
        "| at true factors [N] | joint load less pose [N] | force [N] | motion [mm] |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for cell in summary["cells"]:
        for kind, k in cell["kinds"].items():
            fit, held = k["fit"], k["held_out"]
            true = ", ".join(f"{v:.2f}" for v in k["true_factors"].values())
            fitted = ", ".join(f"{v:.2f}" for v in fit["factors"].values()) if fit.get("toggles") else "-"
            lines.append(
                f"| {cell['cell_seed']} | {kind} | {fit.get('toggles', 0)} / {held['toggles']} | {true} | {fitted} "
                f"| {_pair(held['load_rms_n'])} | {_truth(held['load_rms_n'])} | {_pair(held['pose_load_rms_n'])} "
                f"| {_pair(held['force_rms_n'])} "
                f"| {_pair(held['motion_rms_m'], 1000)} |"
            )
    lines += ["", "| kind (all cells) | held-out toggles | joint load [N] | at true factors [N] "
              "| joint load less pose [N] | force [N] | motion [mm] |",
              "|---|---|---|---|---|---|---|"]  # fmt: skip
    for kind, held in [*summary["held_out_per_kind"].items(), ("**all**", overall)]:
        lines.append(
            f"| {kind} | {held['toggles']} | {_pair(held['load_rms_n'])} | {_truth(held['load_rms_n'])} "
            f"| {_pair(held['pose_load_rms_n'])} "
            f"| {_pair(held['force_rms_n'])} | {_pair(held['motion_rms_m'], 1000)} |"
        )
    lines += [
        "",
        f"Wall time of this run: {summary['wall_time_s']:.0f} s ({summary['tasks']['reused']} of "
        f"{summary['tasks']['planned']} tasks reused from an earlier run; their own time: "
        f"{summary['tasks']['task_time_s']:.0f} s of compute).",
        "",
    ]
    return "\n".join(lines)


def plot(summary: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    examples = summary["examples"]
    fig, axes = plt.subplots(1, len(examples) + 1, figsize=(4.6 * (len(examples) + 1), 3.8), squeeze=False)
    for ax, e in zip(axes[0], examples, strict=False):
        ax.plot(e["time_s"], e["logged_n"], color="k", lw=1.0, label="logged")
        ax.plot(e["time_s"], e["nominal_n"], color="tab:red", lw=1.0, label="nominal twin")
        ax.plot(e["time_s"], e["fitted_n"], color="tab:blue", lw=1.0, label="fitted twin")
        ax.set_title(f"{e['kind']}: {e['context'].get('spec', '')} {e['component']}", fontsize=9)
        ax.set_xlabel("time in the compared actuation [s]")
        ax.set_ylabel("joint load at the grasp point [N]")
        ax.grid(alpha=0.3)
    if examples:
        axes[0][0].legend(fontsize=7)
    ax = axes[0][-1]
    kinds = list(summary["held_out_per_kind"])
    x = np.arange(len(kinds) + 1)
    for offset, which, colour in ((-0.2, "nominal", "tab:red"), (0.2, "fitted", "tab:blue")):
        values, spreads = [], []
        for kind in [*kinds, "all"]:
            cells = summary["cells"]
            per_cell = [c["held_out"] if kind == "all" else c["kinds"][kind]["held_out"] for c in cells]
            rows = [f["load_rms_n"][which] for f in per_cell if f["load_rms_n"][which] is not None]
            values.append(summary["held_out"]["load_rms_n"][which] if kind == "all"
                          else summary["held_out_per_kind"][kind]["load_rms_n"][which] or 0.0)  # fmt: skip
            spreads.append(float(np.std(rows)) if len(rows) > 1 else 0.0)
        ax.bar(x + offset, values, 0.4, yerr=spreads, capsize=3, color=colour, label=f"{which} twin")
    ax.set_xticks(x, [*kinds, "all"])
    ax.set_ylabel("held-out joint-load RMS error [N]")
    ax.set_title("error per kind (whiskers: spread over cells)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=110, format="png")
    plt.close(fig)
