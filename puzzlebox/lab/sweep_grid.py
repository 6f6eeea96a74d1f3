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
from typing import Any, TypeGuard, cast

import numpy as np

from puzzlebox.lab.cells import CellError, check_twin_cameras, profile_of_calibration
from puzzlebox.lab.inputs import MAX_ACTIONS, MAX_COUNT, MAX_TASKS, InputError, check_seed
from puzzlebox.lab.runner import Task
from puzzlebox.lab.spec_files import check_distinct_specs
from puzzlebox.lab.trial_task import trial_task
from puzzlebox.learning import AGENT_NAMES
from puzzlebox.learning.agents.factory import BELIEF_AGENT_NAMES
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import ConfigError
from puzzlebox.models import PuzzleSpec, load_spec
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random
from puzzlebox.models.json_input import JsonInputError, finite, read_json
from puzzlebox.models.kinds import KindFamily, UnknownFamilyError, family_named
from puzzlebox.models.names import name_slug
from puzzlebox.models.spec import file_precision

KEYS = {"sim", "specs", "generate", "placements", "placement_seed", "seeds", "agents", "profiles", "calibrations",
        "max_actions", "name"}  # fmt: skip


AGENT_KEYS = {"name", "memory", "checkpoint", "label", "max_lockers"}
MAX_LABEL = 64
"""Longest agent label of a sweep [characters]."""

MAX_PLACEMENTS = 1000
"""Most placements per spec."""
MAX_COMPONENTS = 64
"""Most components of a generated box (the reach allows 28)."""


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
    """Read and check a sweep file in full before any work: every key's type, range and finiteness, and the
    grid's size (:data:`~puzzlebox.lab.inputs.MAX_TASKS` trials at most); :class:`SweepError` names the key."""
    try:
        sweep = read_json(path)
    except JsonInputError as err:
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
    if not _integer(sweep.get("max_actions")) or not 1 <= sweep["max_actions"] <= MAX_ACTIONS:
        raise SweepError(f"sweep {path}: 'max_actions' must be an integer >= 1 and <= {MAX_ACTIONS}")
    try:
        _check_types(sweep)
    except SweepError as err:
        raise SweepError(f"sweep {path}: {err}") from None
    return sweep


def _integer(value: object) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool)


def _strings(value: object, key: str, *, allow_empty: bool = False) -> list[str]:
    """``value`` is a list of non-empty strings (non-empty unless ``allow_empty``)."""
    if isinstance(value, str):
        raise SweepError(f"'{key}' must be a list, got the string {value!r} (write [{json.dumps(value)}])")
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise SweepError(f"'{key}' must be a list of non-empty strings, got {_shown(value)}")
    if not value and not allow_empty:
        raise SweepError(f"'{key}' must name at least one, got []")
    return value


def _shown(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _check_types(sweep: dict[str, Any]) -> None:
    """Every key's type and range (the grid itself is checked by :func:`grid`)."""
    if "name" in sweep and not isinstance(sweep["name"], str):
        raise SweepError(f"'name' must be a string, got {_shown(sweep['name'])}")
    if "specs" in sweep:
        _strings(sweep["specs"], "specs")
    if "generate" in sweep:
        _check_recipe(sweep["generate"])
    placements = sweep.get("placements")
    if placements is not None:
        if _integer(placements):
            if not 1 <= placements <= MAX_PLACEMENTS:
                raise SweepError(f"'placements' must be >= 1 and <= {MAX_PLACEMENTS}, got {placements}")
        elif not (isinstance(placements, list) and placements and len(placements) <= MAX_PLACEMENTS and all(
                isinstance(p, list) and len(p) == 3 and all(finite(v) for v in p) for p in placements)):  # fmt: skip
            raise SweepError(
                f"'placements' must be a count or a non-empty list of [x, y, yaw] finite numbers, got "
                f"{_shown(placements)}"
            )
    if "placement_seed" in sweep:
        _seed(sweep["placement_seed"], "'placement_seed'")
    seeds = sweep.get("seeds", {"start": 0, "count": 1})
    if isinstance(seeds, dict):
        if set(seeds) - {"start", "count"}:
            raise SweepError(f"'seeds' takes 'start' and 'count', got {sorted(seeds)}")
        count = seeds.get("count", 1)
        if not _integer(count) or not 1 <= count <= MAX_TASKS:
            raise SweepError(f"'seeds': 'count' must be an integer >= 1 and <= {MAX_TASKS}, got {_shown(count)}")
        _seed(seeds.get("start", 0), "'seeds': 'start'", count)
    elif isinstance(seeds, list) and seeds and len(seeds) <= MAX_TASKS:
        for seed in seeds:
            _seed(seed, "'seeds'")
    else:
        raise SweepError(f"'seeds' must be non-negative integers, got {_shown(seeds)}")
    agents = sweep.get("agents", ["memory"])
    if not isinstance(agents, list) or not agents:
        raise SweepError(f"'agents' must be a non-empty list of names or objects, got {_shown(agents)}")
    for entry in agents:
        if isinstance(entry, str):
            continue
        if not isinstance(entry, dict):
            raise SweepError(f"'agents': each is a name or an object with 'name', got {_shown(entry)}")
        for key in ("name", "memory", "checkpoint", "label"):
            if key in entry and not (isinstance(entry[key], str) and (entry[key] or key != "name")):
                raise SweepError(f"'agents': '{key}' must be a string, got {_shown(entry[key])}")
        label = entry.get("label", "")
        if not label.isprintable() or "|" in label or len(label) > MAX_LABEL:
            # it heads a column of cells.md and names the cells' files: a newline or a '|' broke the table
            raise SweepError(f"'agents': 'label' must be printable text of at most {MAX_LABEL} characters without "
                             f"'|' (it heads a table column), got {_shown(label)}")  # fmt: skip
        if "max_lockers" in entry and not _integer(entry["max_lockers"]):
            raise SweepError(f"'agents': 'max_lockers' must be an integer, got {_shown(entry['max_lockers'])}")
    if "profiles" in sweep:
        profiles = _strings(sweep["profiles"], "profiles")
        if len(set(profiles)) != len(profiles):
            raise SweepError(f"'profiles' must be distinct, got {profiles}")
    calibrations = sweep.get("calibrations", {})
    if not isinstance(calibrations, dict) or not all(isinstance(v, str) and v for v in calibrations.values()):
        raise SweepError(f"'calibrations' must map profile names to files, got {_shown(calibrations)}")
    others = sorted(set(calibrations) - set(sweep.get("profiles", ["ideal"])))
    if others:
        raise SweepError(f"'calibrations' names profile(s) {others} the sweep does not run")


def _seed(value: object, key: str, count: int = 1) -> None:
    try:
        check_seed(value, key, count)
    except InputError as err:
        raise SweepError(str(err)) from None


RECIPE_KEYS = {"generator", "components", "multi_locker", "seed", "count", "kinds", "anywhere"}


def _check_recipe(recipe: object) -> None:
    if not isinstance(recipe, dict):
        raise SweepError(f"'generate' must be an object (a recipe), got {_shown(recipe)}")
    unknown = sorted(set(recipe) - RECIPE_KEYS)
    if unknown:
        raise SweepError(f"'generate': unknown key(s) {unknown}; known: {sorted(RECIPE_KEYS)}")
    count = recipe.get("count", 1)
    if not _integer(count) or not 1 <= count <= MAX_COUNT:
        raise SweepError(f"'generate': 'count' must be an integer >= 1 and <= {MAX_COUNT}, got {_shown(count)}")
    _seed(recipe.get("seed", 0), "'generate': 'seed'", count)
    for key in ("multi_locker", "anywhere"):
        if key in recipe and not isinstance(recipe[key], bool):
            raise SweepError(f"'generate': '{key}' must be true or false, got {_shown(recipe[key])}")
    if recipe.get("generator") == "random":
        components = recipe.get("components")
        if not _integer(components) or not 2 <= components <= MAX_COMPONENTS:
            raise SweepError(
                f"'generate': 'components' must be an integer >= 2 and <= {MAX_COMPONENTS}, got {_shown(components)}"
            )
        if "kinds" in recipe and not isinstance(recipe["kinds"], str):
            kinds = _shown(recipe["kinds"])
            raise SweepError(f"'generate': 'kinds' of a random recipe is 'paper' or 'all', got {kinds}")
    elif recipe.get("generator") == "chain":
        _strings(recipe.get("kinds"), "generate': 'kinds")
        if len(recipe["kinds"]) > MAX_COMPONENTS:
            raise SweepError(f"'generate': a chain has at most {MAX_COMPONENTS} kinds, got {len(recipe['kinds'])}")
    else:
        raise SweepError(f"'generate': 'generator' must be 'random' or 'chain', got {_shown(recipe.get('generator'))}")


def sweep_specs(sweep: dict[str, Any], base: Path) -> list[PuzzleSpec]:
    """The specs a checked sweep (:func:`load_sweep`) runs, its paths relative to ``base`` (its file's folder)."""
    return _specs(sweep, base)


def _specs(sweep: dict[str, Any], base: Path) -> list[PuzzleSpec]:
    if "specs" in sweep:
        files = [f for pattern in sweep["specs"] for f in sorted(glob.glob(str(base / pattern)))]
        if not files:
            raise SweepError(f"'specs' {sweep['specs']} match no file under {base}")
        specs = [load_spec(f) for f in files]
        try:  # cells are named by the box: two boxes of one name were reported as one cell of both
            check_distinct_specs(specs, files)
        except InputError as err:
            raise SweepError(str(err).replace("--specs gives", "'specs' match", 1)) from None
        return specs
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


def _check_size(planned: int) -> None:
    if planned > MAX_TASKS:
        raise SweepError(f"the grid has {planned} trials; at most {MAX_TASKS} in one sweep (split it)")


def grid(sweep: dict[str, Any], base: Path) -> tuple[list[Task], dict[str, Cell]]:
    """Every task of the sweep and the cell each belongs to (by task key)."""
    from puzzlebox.models.placement import placed

    seeds, agents = _seeds(sweep), _agents(sweep, base)
    twin = sweep["sim"] == "twin"
    profiles = sweep.get("profiles", ["ideal"]) if twin else ["-"]
    chosen = sweep.get("placements") if twin else None
    placements = 1 if chosen is None else chosen if isinstance(chosen, int) else len(chosen)
    per_spec = placements * len(agents) * len(profiles) * len(seeds)
    if "generate" in sweep:  # before generating the specs
        _check_size(sweep["generate"].get("count", 1) * per_spec)
    specs = _specs(sweep, base)
    _check_size(len(specs) * per_spec)
    realities, calibrations = {}, {}
    if twin:
        from puzzlebox.models.calibration import CellCalibration
        from puzzlebox.twin.reality import PRESETS, load_profile

        for name in profiles:
            realities[name] = load_profile(name if name in PRESETS else base / name)
            file = sweep.get("calibrations", {}).get(name)
            calibrations[name] = CellCalibration.load(base / file) if file else None
            if calibrations[name] is not None:
                try:  # the twin's cameras, checked before any trial (else every trial fails on it)
                    check_twin_cameras(calibrations[name], f"'calibrations': {file}")
                except CellError as err:
                    raise SweepError(str(err)) from None
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
                    where = "-" if profile == "-" else name_slug(profile)  # "-": no profile (symbolic)
                    slugs = f"{name_slug(spec.name)}-p{p}-{name_slug(agent['label'])}-{where}"
                    for seed in seeds:
                        key = f"{i:03d}-{slugs}-seed{seed}"
                        tasks.append(trial_task(
                            key, box, seed, sim=sweep["sim"], agent=agent["name"], max_actions=sweep["max_actions"],
                            memory=agent.get("memory"), checkpoint=agent.get("checkpoint"),
                            reality=reality.to_dict() if reality is not None else None,
                            calibration=calibration.to_dict() if calibration is not None else None,
                            max_lockers=agent.get("max_lockers"),  # None: what fits the scene
                        ))  # fmt: skip
                        cells[key] = cell
    return tasks, cells
