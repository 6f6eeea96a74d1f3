"""The five-kind experiment (issue 15): boxes mixing every registered kind, solved symbolically and end to end in
the twin, by the memory agent trained on other boxes of those kinds.

    python scripts/experiment.py kinds --out DIR [--quick] [--runs R] [--workers W]

1. Specs (``DIR/specs/``): every chain of the registry family's kinds (``models.kinds.registry_family``: door,
   slide, wheel, drawer, lever) in which each neighbour may lock the next, one per order (chain ``k`` drawn with
   seed ``k``); :attr:`KindsConfig.test_chains` of them held out with seed :attr:`KindsConfig.test_seed` for the
   twin; and :attr:`KindsConfig.random_boxes` random boxes of every registered kind (``generate.py random --kinds
   all``, :attr:`KindsConfig.random_components` components, seeds from 1000).
2. The memory (``DIR/memory.sqlite``): trained symbolically, one episode on each chain not held out. The training
   set was chosen on validation, never on the test chains: with 3 other chains held out of the rest, a memory of
   every remaining chain (42) took 5.33 actions on them, one of 9 chains 6.67 and one of 20 random boxes 6.33
   (50 seeds each).
3. Symbolic (``DIR/symbolic-chains``, ``DIR/symbolic-random``): every chain and every random box, ``runs`` seeds
   each (from 500).
4. Twin (``DIR/twin-ideal``, ``DIR/twin-realistic``): the held-out chains, ``runs`` seeds each (from 0), under the
   ``ideal`` profile and under ``realistic`` (the box at random reachable poses; the cell calibrated first from
   ChArUco images, ``DIR/calibration-realistic.json``); and the first :attr:`KindsConfig.twin_random` random boxes,
   one seed each, under ``realistic`` (``DIR/twin-random-realistic``: layouts unlike any the memory saw).

Every step is the project's own command line (``generate.py``'s generators, ``train.py``, ``trial.py``,
``calibrate.py``), so every step writes its outputs atomically and resumes: the same command after an
interruption reuses what finished. Writes ``DIR/kinds.{json,md,png}``: success, mean actions and the optimum's
ratio per set and profile, the twin's outcome agreement.
"""

from __future__ import annotations

import itertools
import json
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.lab.cli import scripts_folder, write_json
from puzzlebox.lab.errors import ExperimentStepFailed
from puzzlebox.lab.hard_sets import optimum as box_optimum
from puzzlebox.models import PuzzleSpec, load_spec, save_spec
from puzzlebox.models.atomic import write_atomically, write_text_atomically
from puzzlebox.models.generator import RandomGraphConfig, generate_chain, generate_random
from puzzlebox.models.kinds import registry_family

SCRIPTS = scripts_folder()


@dataclass(frozen=True)
class KindsConfig:
    """What the five-kind experiment runs."""

    test_chains: int = 3
    """Chains held out for the twin (the paper held out 3 of its 12)."""
    test_seed: int = 15
    """Seed of the held-out draw."""
    random_boxes: int = 100
    """Random boxes of every registered kind, run symbolically."""
    random_components: int = 6
    """Components per random box."""
    runs: int = 5
    """Seeds per spec, symbolic and twin."""
    max_actions: int = 30
    """Action budget of a trial."""
    profiles: tuple[str, ...] = ("ideal", "realistic")
    """Reality profiles of the twin trials."""
    twin_random: int = 10
    """Random boxes (the first of them) also run in the twin, one seed each, under the last profile: layouts
    unlike the chains the memory was trained on."""

    def quick(self) -> KindsConfig:
        """A smoke-sized run (a minute): 10 random boxes, 1 seed, the ideal twin only, 1 random box in it."""
        return replace(self, random_boxes=10, runs=1, profiles=("ideal",), twin_random=1)


def five_kind_chains() -> list[tuple[str, ...]]:
    """Every order of the registry family's kinds in which each neighbour may lock the next."""
    family = registry_family()
    return [
        order for order in itertools.permutations(family.kinds)
        if all(family.may_neighbour(a, b) for a, b in itertools.pairwise(order))
    ]  # fmt: skip


def make_specs(out: Path, config: KindsConfig) -> dict[str, list[Path]]:
    """Write the specs (``DIR/specs/{train,test,random}/``) and return their files by set."""
    chains = five_kind_chains()
    test = set(np.random.default_rng(config.test_seed).choice(len(chains), config.test_chains, replace=False).tolist())
    sets: dict[str, list[Path]] = {"train": [], "test": [], "random": []}
    for k, order in enumerate(chains):
        spec = generate_chain(list(order), seed=k)
        sets["test" if k in test else "train"].append(_save(spec, out / "specs" / ("test" if k in test else "train")))
    family = registry_family()
    for seed in range(1000, 1000 + config.random_boxes):
        spec = generate_random(RandomGraphConfig(config.random_components, family=family), seed=seed)
        sets["random"].append(_save(spec, out / "specs" / "random"))
    return sets


def _save(spec: PuzzleSpec, directory: Path) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    return save_spec(spec, directory / f"{spec.name}.json")


def _run(command: list[str]) -> None:
    """One of the project's scripts; its failure ends the experiment with its own message."""
    shown: list[str] = []
    for word in command:  # a spec list is shown as <specs>: the files are in DIR/specs/
        if word.endswith(".json") and shown and shown[-1] in ("--specs", "<specs>"):
            shown += ["<specs>"] if shown[-1] == "--specs" else []
            continue
        shown.append(Path(word).name if word.endswith(".py") else word)
    print("$", " ".join(shown), flush=True)
    done = subprocess.run([sys.executable, *command], check=False)
    if done.returncode != 0:
        raise ExperimentStepFailed(" ".join(shown), done.returncode)


def _trial(out: Path, specs: list[Path], settings: list[str]) -> dict[str, Any]:
    """``trial.py`` into ``out`` (resumed if it holds runs) and its results."""
    resume = ["--resume"] if (out / "config.json").exists() else []
    _run([str(SCRIPTS / "trial.py"), "--specs", *map(str, specs), "--out", str(out), *settings, *resume])
    return json.loads((out / "results.json").read_text())


def run_kinds(out: Path, config: KindsConfig, workers: int | None) -> dict[str, Any]:
    """Run the experiment into ``out`` (see the module docstring); returns the summary written to kinds.json."""
    start = time.time()
    out.mkdir(parents=True, exist_ok=True)
    sets = make_specs(out, config)
    memory = out / "memory.sqlite"
    train = [str(SCRIPTS / "train.py"), "--specs", *map(str, sets["train"]), "--episodes", str(len(sets["train"]))]
    _run([*train, "--memory", str(memory), "--seed", "0", *(["--resume"] if memory.exists() else [])])

    def agent(runs: int) -> list[str]:
        return ["--agent", "memory", "--memory", str(memory), "--runs", str(runs), "--max-actions",
                str(config.max_actions)]  # fmt: skip

    def twin(profile: str, runs: int) -> list[str]:
        reality = ["--reality", profile]
        if profile != "ideal":
            calibration = out / f"calibration-{profile}.json"
            if not calibration.exists():
                _run([str(SCRIPTS / "calibrate.py"), "--out", str(calibration), "--reality", profile])
            reality += ["--calibration", str(calibration)]
        return [
            "--sim",
            "twin",
            "--seed",
            "0",
            *agent(runs),
            *reality,
            *(["--workers", str(workers)] if workers else []),
        ]

    symbolic = ["--sim", "symbolic", "--seed", "500", *agent(config.runs)]
    results = {
        "symbolic-chains": _trial(out / "symbolic-chains", sets["train"] + sets["test"], symbolic),
        "symbolic-random": _trial(out / "symbolic-random", sets["random"], symbolic),
    }
    for profile in config.profiles:
        results[f"twin-{profile}"] = _trial(out / f"twin-{profile}", sets["test"], twin(profile, config.runs))
    if config.twin_random and config.profiles:
        name = f"twin-random-{config.profiles[-1]}"
        results[name] = _trial(out / name, sets["random"][: config.twin_random], twin(config.profiles[-1], 1))
    optimum = {spec.name: box_optimum(spec) for spec in (load_spec(p) for paths in sets.values() for p in paths)}
    summary = {
        "config": asdict(config),
        "kinds": list(registry_family().kinds),
        "chains": {"all": len(sets["train"]) + len(sets["test"]), "test": [p.stem for p in sets["test"]]},
        "sets": {name: _figures(result, optimum) for name, result in results.items()},
        "wall_time_s": time.time() - start,
    }
    write_json(out / "kinds.json", summary)
    write_text_atomically(out / "kinds.md", table(summary))
    plot(summary, out / "kinds.png")
    return summary


def _figures(result: dict[str, Any], optimum: dict[str, int]) -> dict[str, Any]:
    runs = result["runs"]
    actions = np.array([r["num_actions"] for r in runs], dtype=float)
    best = np.array([optimum[r["spec"]] for r in runs], dtype=float)
    figures = {
        "runs": len(runs),
        "success_rate": float(np.mean([r["solved"] for r in runs])),
        "mean_actions": float(actions.mean()),
        "mean_optimum": float(best.mean()),
        "ratio_to_optimum": float(actions.mean() / best.mean()),
    }
    if "outcome_agreement" in result:
        figures["outcome_agreement"] = result["outcome_agreement"]
        figures["peak_true_wrist_force_n"] = result["peak_true_wrist_force_n"]
    return figures


def table(summary: dict[str, Any]) -> str:
    """The summary as a Markdown table."""
    rows = [
        "| set | runs | solved | mean actions | optimum | ratio | outcome agreement |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, f in summary["sets"].items():
        agreement = f"{f['outcome_agreement']:.1%}" if "outcome_agreement" in f else ""
        rows.append(
            f"| {name} | {f['runs']} | {f['success_rate']:.1%} | {f['mean_actions']:.2f} | {f['mean_optimum']:.2f} "
            f"| {f['ratio_to_optimum']:.2f} | {agreement} |"
        )
    return (
        f"## Boxes of every registered kind ({', '.join(summary['kinds'])})\n\n"
        f"Held-out chains in the twin: {', '.join(summary['chains']['test'])}\n\n" + "\n".join(rows) + "\n"
    )


def plot(summary: dict[str, Any], path: Path) -> None:
    """Success and mean actions beside the optimum, per set."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(summary["sets"])
    figures = [summary["sets"][n] for n in names]
    x = np.arange(len(names))
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.6))
    left.bar(x, [100 * f["success_rate"] for f in figures], color="#4C72B0")
    left.set(ylabel="solved [%]", ylim=(0, 105), xticks=x, title="success")
    left.set_xticklabels(names, rotation=20, ha="right")
    right.bar(x - 0.2, [f["mean_actions"] for f in figures], 0.4, label="memory agent", color="#DD8452")
    right.bar(x + 0.2, [f["mean_optimum"] for f in figures], 0.4, label="optimum", color="#55A868")
    right.set(ylabel="actions per run", xticks=x, title="mean actions")
    right.set_xticklabels(names, rotation=20, ha="right")
    right.legend(loc="lower right", framealpha=0.9)
    fig.tight_layout()
    write_atomically(path, lambda tmp: fig.savefig(tmp, dpi=120, format="png"))
    plt.close(fig)
