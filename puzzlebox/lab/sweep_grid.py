"""A sweep file (``scripts/sweep.py SWEEP.json``): the grid of trials it names, checked, as runner tasks.

Format (paths relative to the sweep file)::

    {
      "sim": "twin",                                    # or "symbolic"
      "specs": ["specs/paper-test-*.json"],             # globs; or, instead:
      "generate": {"generator": "random", "components": 8, "multi_locker": true, "seed": 0, "count": 10},
      "placements": 3,                                  # twin: K reachable poses per spec drawn from
                                                        # placement_seed, or a list of [x, y, yaw] [m, m, rad];
                                                        # absent: the profile's own (a new one per seed)
      "placement_seed": 0,
      "seeds": {"start": 1000, "count": 20},            # or a list of seeds
      "agents": ["oracle", {"name": "memory", "memory": "memory.sqlite"},
                 {"name": "memory", "memory": "memory.sqlite", "max_lockers": 2, "label": "memory-k2"}],
      "profiles": ["ideal", "realistic"],               # twin: reality profiles (names or JSON files)
      "calibrations": {"realistic": "calibration-realistic.json"},
      "max_actions": 30
    }

A cell is one (spec, placement, agent, profile); its runs are the seeds. An agent's ``max_lockers`` (symbolic
memory and dual agents; default 1, the paper's belief) lets its belief hold a component with up to that many
lockers (``learning.dual_controller.DualControllerConfig.max_lockers``).
"""

from __future__ import annotations

import glob
import json
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, cast

import numpy as np

from puzzlebox.lab.cells import profile_of_calibration
from puzzlebox.lab.trial_task import trial_task
from puzzlebox.learning import AGENT_NAMES
from puzzlebox.learning.agents.factory import BELIEF_AGENT_NAMES
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.runner import Task
from puzzlebox.models import PuzzleSpec, load_spec
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random
from puzzlebox.models.kinds import KindFamily, UnknownFamilyError, family_named
from puzzlebox.models.spec import file_precision

KEYS = {"sim", "specs", "generate", "placements", "placement_seed", "seeds", "agents", "profiles", "calibrations",
        "max_actions", "name"}  # fmt: skip


AGENT_KEYS = {"name", "memory", "checkpoint", "label", "max_lockers"}


class SweepError(ValueError):
    """A sweep file that cannot be run (the message names the key and what is allowed)."""


@dataclass(frozen=True)
class Cell:
    """One cell of the grid: which spec (placed), agent and profile; its runs are the sweep's seeds."""

    spec: str
    placement: int | None
    box_pose: tuple[float, float, float] | None
    agent: str
    profile: str

    @property
    def label(self) -> str:
        where = "" if self.placement is None else f" @p{self.placement}"
        return f"{self.spec}{where} | {self.agent} | {self.profile}"


def load_sweep(path: Path) -> dict[str, Any]:
    try:
        sweep = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise SweepError(f"cannot read sweep {path}: {err}") from None
    if not isinstance(sweep, dict):
        raise SweepError(f"sweep {path}: must be a JSON object with keys {sorted(KEYS)}")
    unknown = sorted(set(sweep) - KEYS)
    if unknown:
        raise SweepError(f"sweep {path}: unknown key(s) {unknown}; known: {sorted(KEYS)}")
    if sweep.get("sim") not in ("symbolic", "twin"):
        raise SweepError(f"sweep {path}: 'sim' must be 'symbolic' or 'twin', got {sweep.get('sim')!r}")
    if ("specs" in sweep) == ("generate" in sweep):
        raise SweepError(f"sweep {path}: give 'specs' (globs) or 'generate' (a recipe), one of them")
    if sweep["sim"] == "symbolic" and any(k in sweep for k in ("placements", "profiles", "calibrations")):
        raise SweepError(f"sweep {path}: placements, profiles and calibrations need 'sim': 'twin'")
    if not isinstance(sweep.get("max_actions"), int) or sweep["max_actions"] < 1:
        raise SweepError(f"sweep {path}: 'max_actions' must be an integer >= 1")
    return sweep


def _specs(sweep: dict[str, Any], base: Path) -> list[PuzzleSpec]:
    if "specs" in sweep:
        files = [f for pattern in sweep["specs"] for f in sorted(glob.glob(str(base / pattern)))]
        if not files:
            raise SweepError(f"'specs' {sweep['specs']} match no file under {base}")
        return [load_spec(f) for f in files]
    recipe = dict(sweep["generate"])
    kind, seed, count = recipe.pop("generator", None), recipe.pop("seed", 0), recipe.pop("count", 1)
    box = BoxConfig(fit_reach=not recipe.pop("anywhere", False))
    if kind == "random":
        config = RandomGraphConfig(
            num_components=recipe.pop("components"),
            multi_locker=recipe.pop("multi_locker", False),
            family=_family(recipe.pop("kinds", "paper")),
        )
        specs = [generate_random(config, seed=s, box=box) for s in range(seed, seed + count)]
    elif kind == "chain":
        specs = [generate_chain(recipe.pop("kinds"), seed=s, box=box) for s in range(seed, seed + count)]
    else:
        raise SweepError(f"'generate': 'generator' must be 'random' or 'chain', got {kind!r}")
    if recipe:
        raise SweepError(f"'generate': unknown key(s) {sorted(recipe)}")
    return specs


def _family(name: object) -> KindFamily:
    """The kind family a random recipe's ``kinds`` names (``paper`` or ``all``)."""
    try:
        return family_named(str(name))
    except UnknownFamilyError as err:
        raise SweepError(f"'generate': 'kinds': {err}") from None


def _seeds(sweep: dict[str, Any]) -> list[int]:
    seeds = sweep.get("seeds", {"start": 0, "count": 1})
    if isinstance(seeds, dict):
        seeds = list(range(int(seeds.get("start", 0)), int(seeds.get("start", 0)) + int(seeds.get("count", 1))))
    if not seeds or any(not isinstance(s, int) or s < 0 for s in seeds):
        raise SweepError(f"'seeds' must be non-negative integers, got {sweep.get('seeds')!r}")
    return seeds


def _agents(sweep: dict[str, Any], base: Path) -> list[dict[str, Any]]:
    agents = []
    for entry in sweep.get("agents", ["memory"]):
        agent: dict[str, Any] = {"name": entry} if isinstance(entry, str) else dict(entry)
        if agent.get("name") not in AGENT_NAMES:
            raise SweepError(f"unknown agent {agent.get('name')!r}; available: {sorted(AGENT_NAMES)}")
        for key in ("memory", "checkpoint"):
            if agent.get(key):
                agent[key] = str((base / agent[key]).resolve())
                if not Path(agent[key]).is_file():
                    raise SweepError(f"agent {agent['name']}: no {key} file at {agent[key]}")
        if (agent["name"] == "memory") != bool(agent.get("memory")):
            raise SweepError("agent 'memory' needs a 'memory' file (and only it has one)")
        unknown = sorted(set(agent) - AGENT_KEYS)
        if unknown:
            raise SweepError(f"agent {agent['name']}: unknown key(s) {unknown}; known: {sorted(AGENT_KEYS)}")
        if agent.get("max_lockers", 1) != 1:
            if sweep["sim"] != "symbolic" or agent["name"] not in BELIEF_AGENT_NAMES:
                raise SweepError(
                    f"agent {agent['name']}: 'max_lockers' is for the symbolic agents {list(BELIEF_AGENT_NAMES)}"
                )
            try:
                DualControllerConfig(max_lockers=agent["max_lockers"])
            except ConfigError as err:
                raise SweepError(f"agent {agent['name']}: {err}") from None
        agent["label"] = agent.get("label") or agent["name"]
        agents.append(agent)
    labels = [a["label"] for a in agents]
    if len(set(labels)) != len(labels):
        raise SweepError(f"agents need distinct labels (add 'label'): {labels}")
    return agents


def _placements(sweep: dict[str, Any], spec: PuzzleSpec) -> list[tuple[float, float, float] | None]:
    chosen = sweep.get("placements")
    if chosen is None:
        return [None]
    from puzzlebox.models.placement import sample_reachable_pose

    if isinstance(chosen, int):
        rng = np.random.default_rng([int(sweep.get("placement_seed", 0)), len(spec.components)])
        chosen = [sample_reachable_pose(spec, rng) for _ in range(chosen)]
    # as the placed spec stores it; each an [x, y, yaw] [m, m, rad] (the sweep format, sample_reachable_pose's)
    return [cast("tuple[float, float, float]", file_precision(tuple(float(v) for v in pose))) for pose in chosen]


def grid(sweep: dict[str, Any], base: Path) -> tuple[list[Task], dict[str, Cell]]:
    """Every task of the sweep and the cell each belongs to (by task key)."""
    from puzzlebox.models.placement import placed

    specs, seeds, agents = _specs(sweep, base), _seeds(sweep), _agents(sweep, base)
    twin = sweep["sim"] == "twin"
    profiles = sweep.get("profiles", ["ideal"]) if twin else ["-"]
    realities, calibrations = {}, {}
    if twin:
        from puzzlebox.models.calibration import CellCalibration
        from puzzlebox.twin.reality import PRESETS, load_profile

        for name in profiles:
            realities[name] = load_profile(name if name in PRESETS else base / name)
            file = sweep.get("calibrations", {}).get(name)
            calibrations[name] = CellCalibration.load(base / file) if file else None
            realities[name] = profile_of_calibration(realities[name], calibrations[name])  # the file's cell
    tasks, cells = [], {}
    for i, spec in enumerate(specs):
        poses = _placements(sweep, spec) if twin else [None]
        for p, pose in enumerate(poses):
            box = placed(spec, pose) if pose is not None else spec
            for agent in agents:
                for profile in profiles:
                    reality = realities.get(profile)
                    if pose is not None and reality is not None:
                        reality = replace(reality, placement=None)  # the sweep placed the box
                    calibration = calibrations.get(profile)
                    if calibration is not None and spec.box is not None:  # no box: the twin refuses it (SceneError)
                        assert reality is not None  # a calibration is only loaded for a twin profile, as its reality
                        calibration.check_cell(reality.name, reality.cell_seed, spec.box.size[2], spec=spec.name)
                    cell = Cell(spec.name, None if pose is None else p, pose, agent["label"], profile)
                    for seed in seeds:
                        key = f"{i:03d}-{spec.name}-p{p}-{agent['label']}-{profile}-seed{seed}"
                        tasks.append(trial_task(
                            key, box, seed, sim=sweep["sim"], agent=agent["name"], max_actions=sweep["max_actions"],
                            memory=agent.get("memory"), checkpoint=agent.get("checkpoint"),
                            reality=reality.to_dict() if reality is not None else None,
                            calibration=calibration.to_dict() if calibration is not None else None,
                            max_lockers=agent.get("max_lockers", 1),
                        ))  # fmt: skip
                        cells[key] = cell
    return tasks, cells
