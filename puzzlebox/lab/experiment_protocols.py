"""Every protocol of ``experiment.py`` from its settings (:class:`ExperimentFlags`): the paper's symbolic ones
(``puzzlebox.lab.paper_protocols``) and the twin's — ``reality`` (``reality_sweep``), ``twin-learning``, ``hard-sets``
(``hard_grid``),
``kinds`` (``kinds_experiment``), ``manipulation`` (``manipulation_experiment``), ``sysid``, ``tries``
(``tries_experiment``), ``disassembly``
(``disassembly_run``) and ``faults``. Each checks the flags it takes, writes ``DIR/<name>.config.json``, runs
(resuming what a previous run of the same command finished) and hands its report (``DIR/<name>.md``) and wall time
to ``echo``. A mistake in the settings is an :class:`ExperimentSettingsError`; the learning layer's refusal an
:class:`ExperimentFailed`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

from puzzlebox.lab.cli import write_json
from puzzlebox.lab.errors import ExperimentFailed, ExperimentSettingsError, ExperimentStepFailed
from puzzlebox.lab.experiment_flags import (
    DISASSEMBLY,
    FAULTS,
    HARD_SETS,
    KINDS,
    MANIPULATION,
    REALITY,
    REGRESSION,
    SYSID,
    TRIES,
    TWIN_LEARNING,
    ExperimentFlags,
    release_outputs,
)
from puzzlebox.lab.paper_protocols import run_paper_protocols
from puzzlebox.learning.errors import LearningError
from puzzlebox.learning.experiments.deep_protocols import DEEP_AGENTS

Echo = Callable[[str], object]


def run_experiment(flags: ExperimentFlags, echo: Echo = print) -> None:
    """Check ``flags`` and run its protocol."""
    flags.check()
    runs = {REALITY: run_reality, FAULTS: run_faults, TWIN_LEARNING: run_twin_learning, HARD_SETS: run_hard_sets,
            REGRESSION: run_regression, SYSID: run_sysid, TRIES: run_tries,
            DISASSEMBLY: run_disassembly, KINDS: run_kinds, MANIPULATION: run_manipulation}  # fmt: skip
    try:
        runs.get(flags.protocol, run_paper_protocols)(flags, echo)
    finally:
        release_outputs()  # the --out each protocol holds from its config on


def run_reality(flags: ExperimentFlags, echo: Echo = print) -> None:
    """The reality-gap sweep: the memory agent end to end in the twin, each factor of the gap at each level."""
    from puzzlebox.lab.reality_sweep import SweepConfig, run_sweep

    if flags.agents not in (None, "memory"):
        raise ExperimentSettingsError(f"the reality protocol runs the memory agent only, got --agents {flags.agents}")
    if flags.seeds is not None:
        raise ExperimentSettingsError("--seeds is for the symbolic protocols")
    flags.check_workers()
    config = flags.with_runs(SweepConfig().quick() if flags.quick else SweepConfig(), "placements", 1)
    memory = _memory_file(flags.memory)
    out = flags.out_dir()
    flags.write_config(out, REALITY, sweep=asdict(config))
    try:
        summary = run_sweep(out, config, memory, flags.workers, flags.ray)
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    report(out, REALITY, summary, echo)


def run_twin_learning(flags: ExperimentFlags, echo: Echo = print) -> None:
    """Learning in the twin: the memory agent from each start (and the deep agents asked for beside it)."""
    from puzzlebox.lab.twin_learning import TwinLearningConfig, run_twin_learning

    if flags.memory is not None:
        raise ExperimentSettingsError(
            "the twin-learning protocol runs the memory agent from its own memories (no --memory)"
        )
    flags.check_workers()
    config = TwinLearningConfig().hard() if flags.test_set == "hard" else TwinLearningConfig()
    config = config.quick() if flags.quick else config
    if flags.agents is not None:  # the memory's curve always; the deep agents asked for beside it
        agents = [a.strip() for a in flags.agents.split(",") if a.strip()]
        unknown = [a for a in agents if a not in ("memory", *DEEP_AGENTS)]
        if unknown or "memory" not in agents:
            raise ExperimentSettingsError(
                f"twin-learning --agents: memory and any of {list(DEEP_AGENTS)}, got {agents}"
            )
        config = replace(config, deep_agents=tuple(a for a in agents if a != "memory"))
        if config.deep_agents and config.test_set != "paper":
            raise ExperimentSettingsError("twin-learning --test-set hard runs the memory agent only (the deep agents "
                                          "are trained on the paper's boxes): --agents memory")  # fmt: skip
    config = flags.with_seeds(flags.with_runs(config, "placements", 1), "seeds", as_range=True)
    if flags.seed is not None:
        try:
            config = config.with_seed(flags.seed)
        except ValueError as err:
            raise ExperimentSettingsError(f"--seed {flags.seed}: {err}") from err
    if flags.calibration == "both":
        raise ExperimentSettingsError(
            "twin-learning --calibration: with or without (a memory learns through one cell: run each into its own DIR)"
        )
    if flags.calibration is not None:
        config = replace(config, calibrated=flags.calibration == "with")
    out = flags.out_dir()
    flags.write_config(out, TWIN_LEARNING, twin_learning=asdict(config))
    try:
        summary = run_twin_learning(out, config, flags.workers, flags.ray)
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    report(out, TWIN_LEARNING, summary, echo)


def run_hard_sets(flags: ExperimentFlags, echo: Echo = print) -> None:
    """The hard test sets in the twin: eight-part boxes of every kind, the symbolic memory agent, one profile."""
    from puzzlebox.lab.hard_grid import CALIBRATIONS, HardGridConfig, run_hard_grid
    from puzzlebox.twin.errors import ProfileError
    from puzzlebox.twin.reality import load_profile

    flags.only("--out, --profile, --boxes, --seed, --calibration, --runs, --memory, --workers, --ray and --quick",
               "agents", "seeds")  # fmt: skip
    flags.check_workers(show=True)
    config = HardGridConfig().quick() if flags.quick else HardGridConfig()
    if flags.seed is not None:
        try:
            config = config.with_seed(flags.seed)
        except ValueError as err:
            raise ExperimentSettingsError(f"--seed {flags.seed}: {err}") from err
    if flags.calibration is not None:
        cells = {"both": CALIBRATIONS, "with": ("calibrated",), "without": ("uncalibrated",)}
        config = replace(config, calibrations=cells[flags.calibration])
    if flags.profile is not None:
        try:
            load_profile(flags.profile)  # a preset's name or a profile file, checked before any work
        except ProfileError as err:
            raise ExperimentSettingsError(f"--profile: {err}") from err
        config = replace(config, profile=flags.profile)
    if flags.boxes is not None:
        config = replace(config, boxes=flags.boxes)
    config = flags.with_runs(config, "placements", 1)
    memory = _memory_file(flags.memory)
    out = flags.out_dir()
    flags.write_config(out, HARD_SETS, hard_sets=asdict(config))
    try:
        summary = run_hard_grid(out, config, memory, flags.workers, flags.ray)
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    report(out, HARD_SETS, summary, echo)


def run_regression(flags: ExperimentFlags, echo: Echo = print) -> None:
    """The regression grid: a fixed set of twin trials, fingerprinted; with ``--reference``, compared with an
    earlier run's (every difference one line on stdout, then exit 1)."""
    from puzzlebox.lab.regression_grid import RegressionGridConfig, compare, load_reference, run_regression_grid

    flags.only("--out, --reference, --workers, --ray and --quick", "agents", "seeds", "runs", "memory")
    flags.check_workers(show=True)
    reference = None
    if flags.reference is not None:
        try:
            reference = load_reference(Path(flags.reference))  # checked before any work
        except ValueError as err:
            raise ExperimentSettingsError(f"--reference: {err}") from err
    config = RegressionGridConfig().quick() if flags.quick else RegressionGridConfig()
    out = flags.out_dir()
    flags.write_config(out, REGRESSION, regression=asdict(config))
    try:
        summary = run_regression_grid(out, config, flags.workers, flags.ray)
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    trials = summary["trials"]
    lines = [f"# The regression grid: {len(trials)} twin trials, {sum(t['solved'] for t in trials.values())} solved",
             "", f"Fingerprints: `{out / 'regression.json'}`."]  # fmt: skip
    differences = compare(summary, reference) if reference is not None else []
    if reference is not None:
        verdict = f"{len(differences)} difference(s)" if differences else "identical (actions, outcomes, sensed_sha256)"
        lines += ["", f"Against `{flags.reference}`: {verdict}", *(f"- {d}" for d in differences)]
    (out / "regression.md").write_text("\n".join(lines) + "\n")
    report(out, REGRESSION, summary, echo)
    if differences:
        raise ExperimentStepFailed("the regression grid against its reference", 1)


def _memory_file(memory: str | None) -> Path | None:
    """``--memory`` as an existing file, or None."""
    if memory is None:
        return None
    path = Path(memory)
    if not path.is_file():
        raise ExperimentSettingsError(
            f"--memory {path}: no such file (train one with scripts/train.py, or leave it out)"
        )
    return path


def run_kinds(flags: ExperimentFlags, echo: Echo = print) -> None:
    """Boxes mixing every registered kind, symbolically and end to end in the twin."""
    from puzzlebox.lab.kinds_experiment import KindsConfig, run_kinds

    flags.only("--out, --runs, --workers and --quick", "agents", "seeds", "ray", "memory")
    flags.check_workers()
    config = flags.with_runs(KindsConfig().quick() if flags.quick else KindsConfig(), "runs", 1)
    out = flags.out_dir()
    flags.write_config(out, KINDS, kinds=asdict(config))
    report(out, KINDS, run_kinds(out, config, flags.workers), echo)


def run_sysid(flags: ExperimentFlags, echo: Echo = print) -> None:
    """System identification of the box's joints and latches from logged toggles, nominal against fitted."""
    from puzzlebox.lab.sysid import SysIdConfig, run_sysid

    flags.only("--out, --workers, --cells and --quick", "agents", "runs", "seeds", "ray", "memory")
    flags.check_workers(show=True)
    config = SysIdConfig().quick() if flags.quick else SysIdConfig()
    if flags.cells is not None:
        config = replace(config, cell_seeds=cell_seeds(flags.cells))
    out = flags.out_dir(directory_only=True)
    flags.write_config(out, SYSID, sysid=asdict(config))
    try:
        summary = run_sysid(out, config, flags.workers)
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    report(out, SYSID, summary, echo)


def run_tries(flags: ExperimentFlags, echo: Echo = print) -> None:
    """A corpus of recorded tries, and the pinch's judgement measured on it offline against the truth."""
    from puzzlebox.lab.tries_experiment import TriesConfig, run_tries

    flags.only("--out, --workers and --quick", "agents", "runs", "seeds", "ray", "memory")
    flags.check_workers(show=True)
    config = TriesConfig().quick() if flags.quick else TriesConfig()
    out = flags.out_dir(directory_only=True)
    flags.write_config(out, TRIES, tries=asdict(config))
    try:
        summary = run_tries(out, config, flags.workers)
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    report(out, TRIES, summary, echo)


def cell_seeds(cells: str) -> tuple[int, ...]:
    """``--cells``: distinct cell seeds >= 0, comma-separated."""
    try:
        seeds = tuple(int(c) for c in cells.split(","))
    except ValueError:
        raise ExperimentSettingsError(f"--cells takes comma-separated integers (cell seeds), got {cells!r}") from None
    if not seeds or min(seeds) < 0 or len(set(seeds)) != len(seeds):
        raise ExperimentSettingsError(f"--cells takes distinct cell seeds >= 0, got {cells!r}")
    return seeds


def run_disassembly(flags: ExperimentFlags, echo: Echo = print) -> None:
    """The disassembly domain: train on one measured computer, test on another and its variants."""
    from puzzlebox.lab.disassembly_run import run_disassembly
    from puzzlebox.learning.experiments.disassembly import AGENTS as DISASSEMBLY_AGENTS
    from puzzlebox.learning.experiments.disassembly import DisassemblyConfig
    from puzzlebox.learning.experiments.disassembly_report import plot as plot_disassembly
    from puzzlebox.learning.experiments.disassembly_report import table as disassembly_table

    if flags.memory is not None:
        raise ExperimentSettingsError("the disassembly protocol trains its own memories (no --memory)")
    agents = flags.agent_names(DISASSEMBLY_AGENTS)
    flags.check_workers(show=True)
    config = flags.with_runs(DisassemblyConfig().quick() if flags.quick else DisassemblyConfig(), "runs_per_test", 1)
    config = flags.with_seeds(config, "training_seeds")
    config = replace(config, validation=flags.validation, holding_rule=not flags.no_holding_rule)
    out = flags.out_dir(directory_only=True)
    flags.write_config(out, DISASSEMBLY, disassembly=asdict(config))
    try:
        summary = run_disassembly(out, agents, config, flags.workers, flags.ray)
    except LearningError as err:
        raise ExperimentFailed(str(err)) from err
    write_json(out / f"{DISASSEMBLY}.json", summary)
    plot_disassembly(summary, out / f"{DISASSEMBLY}.png")
    (out / f"{DISASSEMBLY}.md").write_text(f"# Disassembly\n\n{disassembly_table(summary)}")
    report(out, DISASSEMBLY, summary, echo)


def run_manipulation(flags: ExperimentFlags, echo: Echo = print) -> None:
    """PPO or SAC from scratch on ``BoxManipulation-v0``: a free slide, a free wheel (learning curves)."""
    from puzzlebox.lab.manipulation_experiment import ALGOS, ManipulationConfig, require_sb3, run_manipulation

    flags.only("--out, --quick, --seeds, --steps and --algo", "agents", "runs", "workers", "ray", "memory")
    config = ManipulationConfig().quick() if flags.quick else ManipulationConfig()
    if flags.algo is not None and flags.algo not in ALGOS:
        raise ExperimentSettingsError(f"--algo must be one of {list(ALGOS)}, got {flags.algo!r}")
    if flags.steps is not None and not 1 <= flags.steps <= 100_000_000:
        raise ExperimentSettingsError(f"--steps must be >= 1 and <= 100000000 (env steps per run), got {flags.steps}")
    config = flags.with_seeds(config, "seeds")
    config = replace(config, algo=flags.algo or config.algo, steps=flags.steps or config.steps)
    out = flags.out_dir()
    require_sb3()
    flags.write_config(out, MANIPULATION, manipulation=asdict(config))
    report(out, MANIPULATION, run_manipulation(out, config), echo)


def run_faults(flags: ExperimentFlags, echo: Echo = print) -> None:
    """Each fault class on purpose in real processes: kills and resumes, concurrent trainers, truncated memories,
    command-line mistakes."""
    from puzzlebox.lab.faults import FaultsConfig, run_faults

    if any(v is not None for v in (flags.agents, flags.seeds, flags.workers, flags.ray, flags.memory)):
        raise ExperimentSettingsError("the faults protocol takes only --out, --quick and --runs")
    config = flags.with_runs(FaultsConfig().quick() if flags.quick else FaultsConfig(), "trial_runs", 2,
                             " (a kill lands between two runs)")  # fmt: skip
    out = flags.out_dir()
    flags.write_config(out, FAULTS, faults=asdict(config))
    report(out, FAULTS, run_faults(out, config), echo)


def report(out: Path, name: str, summary: dict[str, Any], echo: Echo = print) -> None:
    """Hand ``DIR/<name>.md`` and the wall time to ``echo``."""
    echo((out / f"{name}.md").read_text())
    echo(f"{name}: {summary['wall_time_s']:.0f} s -> {out}/")
