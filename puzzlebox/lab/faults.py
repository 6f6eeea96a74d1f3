"""The fault suite of ``experiment.py faults``: each fault class run on purpose, in real processes, with its
figure — cases run, detected (said so, in one line), survived (no traceback, the command went on or stopped
cleanly), data kept (nothing finished was lost or duplicated).

Classes so far:

- ``trial killed``: ``trial.py`` SIGKILLed at random moments of a trial, then ``--resume``d; its results
  compared with an uninterrupted run's (wall times aside).
- ``concurrent trainers``: 2 and 4 ``train.py`` on one memory file; every episode in the memory and its log.
- ``memory truncated``: a trained memory cut at every SQLite page boundary (and inside the first page),
  opened by ``trial.py``: refused in one line each time.
- ``command-line mistakes``: each ordinary mistake a user makes, one line and exit 2.
- ``worker killed``: one worker of ``trial.py --workers 2`` SIGKILLed mid-trial: the driver says so, starts
  another, reruns the run it held; every run recorded once, results identical to an uninterrupted run.
- ``physics diverges``: the twin's velocities made infinite mid-trial in every run: each run ends with
  ``SimulationDiverged`` named, its record kept, and the trial goes on to the next run.
- the twin's faults (:data:`TWIN_FAULTS`): frames dropped, occluded, noised; F/T noise; parts that jam;
  handles that slip — one oracle trial each, which must end with its reason named (or solve anyway).
- the second round (:func:`second_round`, :mod:`puzzlebox.lab.input_faults`): two writers into one ``--out``,
  names of every kind, malformed inputs, crafted memories, ``experiment.py`` stopped by a signal;
- the third round (:func:`third_round_rows`, :mod:`puzzlebox.lab.third_round_faults`): agents that misbehave,
  inputs that are not regular files, a closed stdout, the environment and odd paths, bad memory contents, boxes
  given twice, absurd profile values.

Writes ``DIR/faults.json`` and ``DIR/faults.md`` (one table; the measured one is in docs/faults.md).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, cast

import numpy as np

from puzzlebox.lab.cli import scripts_folder, write_json
from puzzlebox.lab.trial_task import without_timing
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models.try_outcome import Cause

SCRIPTS = scripts_folder()
"""The command-line scripts, run in real processes as a user runs them."""


@dataclass(frozen=True)
class FaultsConfig:
    """Sizes of the fault suite."""

    sim: str = "twin"
    """Simulator of the killed trial: ``twin`` (the issue's figure) or ``symbolic`` (seconds)."""
    trial_runs: int = 20
    """Runs of the killed trial (on paper-test-0; seeds 0..runs-1)."""
    kills: int = 10
    """SIGKILLs, each at a random moment of its own trial, each followed by a resume."""
    trainer_episodes: int = 4
    """Episodes per concurrent trainer."""
    worker_runs: int = 6
    """Runs of each trial whose worker is killed (paper-test-0, ``--workers 2``)."""
    worker_kills: int = 3
    """Trials in which one worker is SIGKILLed (each at a random moment)."""
    seed: int = 0
    """Seeds the kill moments."""
    races: int = 20
    """Races of two writers into one ``--out``, of ``trial.py`` and of ``sweep.py`` each."""
    sample: bool = False
    """Check a sample of the cases that differ only in their input (every third cut of the truncated memory, one
    malformed input of each command and loader); the tests check every case in process."""

    def quick(self) -> FaultsConfig:
        return FaultsConfig(sim="symbolic", trial_runs=60, kills=3, trainer_episodes=2, worker_runs=400,
                            worker_kills=1, seed=self.seed, races=2, sample=True)  # fmt: skip


@dataclass
class FaultRow:
    """One fault class's figure."""

    fault: str
    cases: int
    detected: str
    survived: str
    data_kept: str
    notes: str = ""


def _python(*args: Any, timeout: float = 1800) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=timeout)


def _one_line_error(result: subprocess.CompletedProcess) -> bool:
    lines = [line for line in result.stderr.splitlines() if line.strip() and not line.startswith("\r")]
    errors = [line for line in lines if line.startswith("error: ")]
    return result.returncode == 2 and len(errors) == 1 and "Traceback" not in result.stderr


def _specs(out: Path) -> Path:
    specs = out / "specs"
    if not (specs / "paper-test-0.json").exists():
        _python(SCRIPTS / "generate.py", "paper", "--split", "all", "--out", specs).check_returncode()
    return specs


def _uninterrupted(directory: Path, base: list[Any]) -> Any:
    """The results of ``base`` run to the end in ``directory`` (computed once), wall times aside."""
    if not (directory / "results.json").exists():
        shutil.rmtree(directory, ignore_errors=True)
        _python(*base, "--out", directory).check_returncode()
    return without_timing(json.loads((directory / "results.json").read_text()))


def _lost_and_duplicated(results_path: Path, planned: int) -> tuple[dict[str, Any], int, int]:
    """A resumed trial's results, its runs missing of ``planned`` and its runs recorded twice."""
    got = json.loads(results_path.read_text()) if results_path.exists() else {}
    names = [f"{r['spec']}-{r['seed']}" for r in got.get("runs", [])]
    return got, planned - len(set(names)), len(names) - len(set(names))


def killed_trial(out: Path, config: FaultsConfig) -> FaultRow:
    """SIGKILL ``trial.py`` at ``config.kills`` random moments (each in its own directory), resume each, and
    compare with an uninterrupted run."""
    spec = _specs(out) / "paper-test-0.json"
    base = [SCRIPTS / "trial.py", "--specs", spec, "--sim", config.sim, "--agent", "oracle",
            "--runs", config.trial_runs, "--seed", 0, "--max-actions", 30]  # fmt: skip
    whole = _uninterrupted(out / "killed-trial" / "whole", base)
    rng = np.random.default_rng(config.seed)
    lost = duplicated = identical = resumed = 0
    moments = []
    for k in range(config.kills):
        target = out / "killed-trial" / f"kill-{k}"
        shutil.rmtree(target, ignore_errors=True)
        at = int(rng.integers(1, config.trial_runs))  # kill once this many runs are recorded
        proc = subprocess.Popen([sys.executable, *map(str, base), "--out", str(target)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
        while proc.poll() is None and len(list((target / "runs").glob("*.json"))) < at:
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        kept = sorted(p.name for p in (target / "runs").glob("*.json")) if (target / "runs").is_dir() else []
        moments.append(len(kept))
        result = _python(*base, "--out", target, "--resume")
        resumed += result.returncode == 0
        got, missing, twice = _lost_and_duplicated(target / "results.json", config.trial_runs)
        lost, duplicated = lost + missing, duplicated + twice
        identical += without_timing(got) == whole
    return FaultRow(
        "trial.py killed (SIGKILL) and resumed",
        config.kills,
        "n/a (a kill cannot be seen)",
        f"{resumed}/{config.kills} resumed",
        f"{lost} runs lost, {duplicated} duplicated; {identical}/{config.kills} results identical to an "
        "uninterrupted run (wall times aside)",
        f"{config.sim}, {config.trial_runs} runs; killed with {moments} runs recorded",
    )


def pool_workers(driver: int) -> list[int]:
    """Process ids of the pool workers of process ``driver`` (its spawned children, not the resource tracker)."""
    workers = []
    for child in Path(f"/proc/{driver}/task/{driver}/children").read_text().split():
        try:
            command = Path(f"/proc/{child}/cmdline").read_bytes().replace(b"\0", b" ")
        except OSError:
            continue
        if b"spawn_main" in command:
            workers.append(int(child))
    return workers


def killed_worker(out: Path, config: FaultsConfig) -> FaultRow:
    """SIGKILL one pool worker of a ``trial.py --workers 2`` at ``config.worker_kills`` random moments."""
    spec = _specs(out) / "paper-test-0.json"
    base = [SCRIPTS / "trial.py", "--specs", spec, "--sim", config.sim, "--agent", "oracle",
            "--runs", config.worker_runs, "--seed", 0, "--max-actions", 30]  # fmt: skip
    whole = _uninterrupted(out / "killed-worker" / "whole", [*base, "--workers", 1])
    rng = np.random.default_rng(config.seed + 1)
    killed = detected = survived = lost = duplicated = identical = 0
    for k in range(config.worker_kills):
        target = out / "killed-worker" / f"kill-{k}"
        shutil.rmtree(target, ignore_errors=True)
        at = int(rng.integers(0, config.worker_runs // 2))  # kill once this many runs are recorded
        proc = subprocess.Popen([sys.executable, *map(str, base), "--workers", "2", "--out", str(target)],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)  # fmt: skip
        workers: list[int] = []
        while proc.poll() is None and not (len(list((target / "runs").glob("*.json"))) >= at and workers):
            workers = pool_workers(proc.pid)
            time.sleep(0.01)
        if workers and proc.poll() is None:
            os.kill(workers[0], signal.SIGKILL)
            killed += 1
        _, stderr = proc.communicate(timeout=1800)
        detected += "a worker died" in stderr
        survived += proc.returncode == 0 and "Traceback" not in stderr
        got, missing, twice = _lost_and_duplicated(target / "results.json", config.worker_runs)
        lost, duplicated = lost + missing, duplicated + twice
        identical += without_timing(got) == whole
    n = config.worker_kills
    return FaultRow(
        "a trial.py pool worker killed (SIGKILL)",
        n,
        f"{detected}/{killed} said (a worker died)",
        f"{survived}/{n} finished (exit 0, no traceback)",
        f"{lost} runs lost, {duplicated} duplicated; {identical}/{n} results identical to an uninterrupted run",
        f"{config.sim}, {config.worker_runs} runs, --workers 2; {killed}/{n} kills landed before the trial ended",
    )


DIVERGE_AT_S = 3.0
"""Simulated time at which :func:`physics_divergence` makes the twin's velocities infinite [s] (mid-survey)."""

_DIVERGING_TRIAL = f"""
import sys
import numpy as np
from puzzlebox.twin.session import TwinSession
after_steps = TwinSession._after_steps
def diverging(self):
    if self.data.time > {DIVERGE_AT_S} and not getattr(self, "_diverged", False):
        self._diverged = True
        self.data.qvel[:] = np.inf  # MuJoCo flags it (BADQVEL) at the next step
    after_steps(self)
TwinSession._after_steps = diverging
from puzzlebox.scripts import trial
sys.exit(trial.main(sys.argv[1:]))
"""


def physics_divergence(out: Path, runs: int = 3) -> FaultRow:
    """A twin trial of ``runs`` runs in which the physics of every run blows up at :data:`DIVERGE_AT_S`."""
    spec = _specs(out) / "paper-test-0.json"
    target = out / "diverged"
    result = subprocess.run(  # in DIR: MuJoCo may log the warnings to MUJOCO_LOG.TXT in its working directory
        [sys.executable, "-c", _DIVERGING_TRIAL, "--specs", str(spec.resolve()), "--sim", "twin", "--agent", "oracle",
         "--runs", str(runs), "--seed", "0", "--max-actions", "6", "--workers", "1", "--out", str(target.resolve()),
         "--force"],
        capture_output=True, text=True, timeout=1800, cwd=out.resolve(),
    )  # fmt: skip
    path = target / "results.json"
    got = json.loads(path.read_text()) if path.exists() else {}
    named = sum((r.get("ended") or "").startswith("SimulationDiverged") for r in got.get("runs", []))
    return FaultRow(
        "twin: physics diverges (velocities made infinite)",
        runs,
        f"{named}/{runs} runs ended naming SimulationDiverged",
        f"{runs if result.returncode == 0 and 'Traceback' not in result.stderr else 0}/{runs} without a traceback",
        f"{len(got.get('runs', []))}/{runs} runs recorded",
        f"at t = {DIVERGE_AT_S} s of every run; e.g. {got['runs'][0]['ended'][:80]!r}" if got.get("runs") else "",
    )


def concurrent_trainers(out: Path, config: FaultsConfig, trainers: int) -> FaultRow:
    """``trainers`` processes of ``train.py`` on one new memory file at once."""
    specs = sorted(_specs(out).glob("paper-train-*.json"))
    memory = out / "concurrent" / f"{trainers}" / "memory.sqlite"
    shutil.rmtree(memory.parent, ignore_errors=True)
    memory.parent.mkdir(parents=True)
    command = [sys.executable, str(SCRIPTS / "train.py"), "--specs", *map(str, specs), "--episodes",
               str(config.trainer_episodes), "--memory", str(memory)]  # fmt: skip
    procs = [
        subprocess.Popen(
            [*command, "--seed", str(100 * k)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
        )
        for k in range(trainers)
    ]
    errors = [p.communicate(timeout=1800)[1] for p in procs]
    ok = sum(p.returncode == 0 for p in procs)
    store = MemoryStore.open_existing(memory)
    logged = sum(len(cast(list, r["episodes"])) for r in store.training_log())  # each run's episodes: a list
    wanted = trainers * config.trainer_episodes
    store.close()
    return FaultRow(
        f"{trainers} concurrent train.py on one memory",
        trainers,
        "n/a (not a fault: must just work)",
        f"{ok}/{trainers} trainers succeeded" + ("" if ok == trainers else f" ({errors})"),
        f"{store.num_episodes}/{wanted} episodes in the memory, {logged}/{wanted} in its log",
    )


def truncated_memory(out: Path, sample: bool = False) -> FaultRow:
    """A trained memory cut at every page boundary (and mid first page), each opened by ``trial.py`` (``sample``:
    every third cut, the whole file's last page among them)."""
    specs = _specs(out)
    memory = out / "truncated" / "memory.sqlite"
    if not memory.exists():
        memory.parent.mkdir(parents=True, exist_ok=True)
        _python(SCRIPTS / "train.py", "--specs", *sorted(specs.glob("paper-train-*.json")), "--episodes", 9,
                "--memory", memory).check_returncode()  # fmt: skip
    data = memory.read_bytes()
    page = int.from_bytes(data[16:18], "big") or 65536
    cuts = [0, 50, page // 2, *range(page, len(data), page)]
    if sample:
        cuts = sorted({*cuts[::3], cuts[-1]})
    detected = survived = 0
    for cut in cuts:
        cut_file = memory.parent / f"cut-{cut}.sqlite"
        cut_file.write_bytes(data[:cut])
        result = _python(SCRIPTS / "trial.py", "--specs", specs / "paper-test-0.json", "--sim", "symbolic",
                         "--agent", "memory", "--memory", cut_file, "--runs", 1, "--seed", 0, "--max-actions", 30,
                         "--out", memory.parent / f"trial-{cut}", "--force")  # fmt: skip
        detected += _one_line_error(result)
        survived += "Traceback" not in result.stderr
        cut_file.unlink()
    return FaultRow(
        "memory file truncated at every page" + (" (every third)" if sample else ""),
        len(cuts),
        f"{detected}/{len(cuts)} refused in one line (exit 2)",
        f"{survived}/{len(cuts)} without a traceback",
        "the trial never ran on a damaged memory",
        f"{len(data)} bytes, {page}-byte pages",
    )


def cli_mistakes(out: Path) -> FaultRow:
    """Ordinary command-line mistakes: each must be one ``error:`` line and exit 2."""
    specs = _specs(out)
    spec = specs / "paper-test-0.json"
    a_file = out / "cli" / "a-file"
    a_file.parent.mkdir(parents=True, exist_ok=True)
    a_file.write_text("")
    broken = out / "cli" / "broken.json"
    broken.write_text('{"format": "puzzlebox-spec/1", "format": "x"}')
    bad_pt = out / "cli" / "bad.pt"
    bad_pt.write_bytes(b"not a checkpoint")
    Path(str(bad_pt) + ".json").write_text('{"format": "nothing"}')
    trial = [SCRIPTS / "trial.py", "--specs", spec, "--sim", "symbolic", "--runs", 1, "--max-actions", 5]
    cases = {
        "--out names a file": [*trial, "--seed", 0, "--agent", "dual", "--out", a_file],
        "negative --seed": [*trial, "--seed", -1, "--agent", "dual", "--out", out / "cli" / "o1"],
        "unknown agent": [*trial, "--seed", 0, "--agent", "genius", "--out", out / "cli" / "o2"],
        "spec with a duplicate key": [SCRIPTS / "trial.py", "--specs", broken, "--sim", "symbolic", "--runs", 1,
                                      "--max-actions", 5, "--seed", 0, "--agent", "dual", "--out", out / "cli" / "o3"],
        "no such memory": [*trial, "--seed", 0, "--agent", "memory", "--memory", out / "cli" / "none.sqlite",
                           "--out", out / "cli" / "o4"],
        "a .pt that is not a checkpoint": [*trial, "--seed", 0, "--agent", "dqn", "--checkpoint", bad_pt, "--out",
                                           out / "cli" / "o5"],
        "memory under a file": [SCRIPTS / "train.py", "--specs", spec, "--episodes", 1, "--memory", a_file / "m"],
        "unknown reality profile": [*trial[:4], "twin", *trial[5:], "--seed", 0, "--agent", "oracle",
                                    "--reality", "stormy", "--out", out / "cli" / "o6"],
        "random box too large to reach": [SCRIPTS / "generate.py", "random", "--components", 40, "--seed", 0,
                                          "--out", out / "cli" / "r.json"],
        "--out empty (an unset variable)": [*trial, "--seed", 0, "--agent", "dual", "--out", ""],
    }  # fmt: skip
    failed = []
    for name, args in cases.items():
        if not _one_line_error(_python(*args)):
            failed.append(name)
    return FaultRow(
        "command-line mistakes",
        len(cases),
        f"{len(cases) - len(failed)}/{len(cases)} one line, exit 2",
        f"{len(cases) - len(failed)}/{len(cases)} without a traceback",
        "n/a",
        ", ".join(cases) + (f"; NOT one line: {failed}" if failed else ""),
    )


def second_round(out: Path, config: FaultsConfig) -> list[FaultRow]:
    """The classes of issue 37 (:mod:`puzzlebox.lab.input_faults`): two writers into one ``--out``, names of
    every kind, malformed inputs, crafted memories, ``experiment.py`` stopped by a signal (the full suite only)."""
    from puzzlebox.lab import input_faults

    spec = _specs(out) / "paper-test-0.json"
    rows = []
    for kind in ("trial", "sweep"):
        f = input_faults.writer_races(out / "races", kind, config.races, spec)
        rows.append(FaultRow(
            f"two {kind}.py into one --out, started together", f["races"],
            f"{f['second_refused']}/{f['races']} second writers refused in one line ({f['refused_by_lock']} by the "
            f"lock, {f['refused_holding_results']} finding the first's results)",
            f"{f['races'] * 2 - f['tracebacks']}/{f['races'] * 2} without a traceback",
            f"{f['summaries_lost']} summaries lost", "symbolic, different seeds, exit codes "
            + ", ".join("/".join(map(str, r["codes"])) for r in f["rows"]),
        ))  # fmt: skip
    planned, done, clean = input_faults.names_run(out, spec)
    rows.append(FaultRow(
        "names with spaces, unicode, HTML, / and ..", len(input_faults.NAMES), f"{done}/{planned} runs done",
        f"{len(input_faults.NAMES) if clean else 0}/{len(input_faults.NAMES)} without a traceback",
        f"{done}/{planned} runs recorded", "record keys are slugs of the names plus a short hash",
    ))  # fmt: skip
    verdicts = input_faults.malformed_inputs(out, spec, input_faults.QUICK_MALFORMED if config.sample else None)
    bad = [name for name, ok in verdicts.items() if not ok]
    rows.append(FaultRow(
        "malformed inputs", len(verdicts), f"{len(verdicts) - len(bad)}/{len(verdicts)} one line, exit 2",
        f"{len(verdicts) - len(bad)}/{len(verdicts)} without a traceback", "nothing run",
        ", ".join(verdicts) + (f"; NOT one line: {bad}" if bad else ""),
    ))  # fmt: skip
    crafted = input_faults.crafted_memories(out, spec)
    rows.append(FaultRow(
        "memory with a trigger, a view, an extra table", len(crafted),
        f"{sum(crafted.values())}/{len(crafted)} refused in one line (exit 2)",
        f"{sum(crafted.values())}/{len(crafted)} without a traceback",
        f"{sum(crafted.values())}/{len(crafted)} files unchanged: nothing ran on them", ", ".join(crafted),
    ))  # fmt: skip
    if config.sim == "symbolic":  # the quick suite: tests/scripts/test_experiment_signals.py stops it instead
        return rows
    stopped = input_faults.experiment_stopped(out)
    stops = stopped["stops"]
    rows.append(FaultRow(
        "experiment.py sent SIGTERM, SIGINT (inherited ignored)", len(stops),
        f"{sum(s['one_line'] for s in stops.values())}/{len(stops)} said so in one line, exits "
        f"{[s['exit'] for s in stops.values()]}",
        f"{sum(s['one_line'] for s in stops.values())}/{len(stops)} without a traceback",
        f"jobs kept after each stop: {[s['jobs_kept'] for s in stops.values()]}; rerun exit {stopped['final_exit']}",
        "; ".join(stopped["reused"]),
    ))  # fmt: skip
    return rows


def third_round_rows(out: Path) -> list[FaultRow]:
    """The classes of issue 56 (:mod:`puzzlebox.lab.third_round_faults`), one row each."""
    from puzzlebox.lab.third_round_faults import third_round

    classes = third_round(out / "third", _specs(out) / "paper-test-0.json")
    return [
        FaultRow(
            fault,
            c["cases"],
            f"{c['detected']}/{c['cases']} said so (exit code and line)",
            f"{c['survived']}/{c['cases']} without a traceback or a hang",
            "nothing run or written",
            "; NOT: " + "; ".join(c["missed"]) if c["missed"] else "",
        )  # fmt: skip
        for fault, c in classes.items()
    ]


TWIN_FAULTS: dict[str, dict[str, dict[str, Any]]] = {
    "camera: every frame dropped": {"camera": {"dropped_frame_probability": 1.0}},
    "every free part jams on every try": {"physics": {"jam_probability": 1.0}},
    "camera: occluders in every frame": {"camera": {"occluder_probability": 1.0, "occluder_count": 6}},
    "camera: image noise sigma 25 DN": {"camera": {"noise_sigma": 25.0}},
    "F/T noise sigma 30 N": {"force_torque": {"force_noise": 30.0}},
    "handles slip out of the pads (pad mu 0.02)": {"physics": {"pad_friction": 0.02}},
}
"""The twin's faults, each a reality profile (ideal plus this), run as one oracle trial of paper-test-0."""
QUICK_TWIN_FAULTS = ("camera: every frame dropped", "every free part jams on every try")


def twin_faults(out: Path, config: FaultsConfig) -> list[FaultRow]:
    """One twin trial per fault of :data:`TWIN_FAULTS` (the quick suite: :data:`QUICK_TWIN_FAULTS`): did the
    run end with its reason named (or solve anyway), without a traceback, with its record kept?"""
    from puzzlebox.twin.reality import IDEAL

    spec = _specs(out) / "paper-test-0.json"
    names = QUICK_TWIN_FAULTS if config.sim == "symbolic" else tuple(TWIN_FAULTS)
    rows = []
    for k, name in enumerate(names):
        profile = IDEAL.to_dict()
        profile["name"] = f"fault-{k}"
        for section, values in TWIN_FAULTS[name].items():
            profile[section].update(values)
        path = out / "twin" / f"fault-{k}.json"
        write_json(path, profile)
        result = _python(SCRIPTS / "trial.py", "--specs", spec, "--sim", "twin", "--agent", "oracle", "--runs", 1,
                         "--seed", 0, "--max-actions", 6, "--reality", path, "--out", out / "twin" / f"trial-{k}",
                         "--force")  # fmt: skip
        results_path = out / "twin" / f"trial-{k}" / "results.json"
        results = json.loads(results_path.read_text()) if results_path.exists() else {}
        runs = results.get("runs", [])
        run = runs[0] if runs else {}
        failed = {
            Cause(a["cause"]).prefix for a in run.get("timeline", []) if a["outcome"] == "failed" and a.get("cause")
        }
        said = "solved anyway" if run.get("solved") else f"ended: {run.get('ended') or 'out of actions'}"
        rows.append(FaultRow(
            f"twin: {name}", 1,
            said + (f"; failed tries named {sorted(failed)}" if failed else ""),
            "1/1 without a traceback" if result.returncode == 0 and "Traceback" not in result.stderr else
            f"0/1 (exit {result.returncode})",
            "1/1 run recorded" if runs else "0/1 run recorded",
            f"{run.get('num_actions', 0)} actions, agreement "
            f"{results.get('outcome_agreement', 0):.0%}" if runs else "",
        ))  # fmt: skip
    return rows


def run_faults(out: Path, config: FaultsConfig) -> dict[str, Any]:
    """Run every fault class; write ``DIR/faults.{json,md}`` after each (nothing lost if interrupted)."""
    start = time.perf_counter()
    rows: list[FaultRow] = []
    steps: list[Callable[[], FaultRow | list[FaultRow]]] = [
        lambda: cli_mistakes(out),
        lambda: truncated_memory(out, config.sample),
        lambda: concurrent_trainers(out, config, 2),
        lambda: concurrent_trainers(out, config, 4),
        lambda: killed_trial(out, config),
        lambda: killed_worker(out, config),
        lambda: physics_divergence(out),
        lambda: second_round(out, config),
        lambda: third_round_rows(out),
    ]
    steps.append(lambda: twin_faults(out, config))
    summary: dict[str, Any] = {}
    for step in steps:
        made = step()
        rows.extend(made if isinstance(made, list) else [made])
        summary = {"config": asdict(config), "rows": [asdict(r) for r in rows],
                   "wall_time_s": time.perf_counter() - start}  # fmt: skip
        write_json(out / "faults.json", summary)
        (out / "faults.md").write_text(markdown(rows))
    return summary


def markdown(rows: list[FaultRow]) -> str:
    lines = [
        "# Fault suite",
        "",
        "Each fault run on purpose in real processes (`python scripts/experiment.py faults --out DIR`).",
        "",
        "| fault | cases | detected | survived | data kept | notes |",
        "|---|---|---|---|---|---|",
    ]
    lines += [f"| {r.fault} | {r.cases} | {r.detected} | {r.survived} | {r.data_kept} | {r.notes} |" for r in rows]
    return "\n".join(lines) + "\n"
