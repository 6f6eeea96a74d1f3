"""The settings of ``experiment.py`` as one value: which protocol, which agents, where to write, how big; the checks
every protocol shares (its agents, its runs, its workers), each failing with :class:`ExperimentSettingsError`
whose message names the flag; and the ``DIR/<name>.config.json`` written beside every result."""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from puzzlebox.lab.cli import versions, write_json
from puzzlebox.lab.errors import ExperimentSettingsError
from puzzlebox.lab.out_lock import OutputLock
from puzzlebox.learning.experiments import PROTOCOLS, SYMBOLIC_AGENTS
from puzzlebox.learning.experiments.deep_protocols import DEEP_AGENTS

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

DISASSEMBLY = "disassembly"
REALITY = "reality"
FAULTS = "faults"
TWIN_LEARNING = "twin-learning"
HARD_SETS = "hard-sets"
REGRESSION = "regression"
TRIES = "tries"
SYSID = "sysid"
KINDS = "kinds"
MANIPULATION = "manipulation"
ALL = "all"
PROTOCOL_NAMES = (
    *PROTOCOLS,
    ALL,
    REALITY,
    FAULTS,
    TWIN_LEARNING,
    HARD_SETS,
    REGRESSION,
    TRIES,
    SYSID,
    DISASSEMBLY,
    KINDS,
    MANIPULATION,
)
"""Every protocol ``experiment.py`` runs: the paper's symbolic ones, all three of them, and the twin's."""
AGENTS = (*SYMBOLIC_AGENTS, *DEEP_AGENTS)
"""The agents of the paper's symbolic protocols."""

MAX_RUNS, MAX_SEEDS, MAX_WORKERS = 100_000, 1000, 1024
"""Bounds of ``--runs``, ``--seeds`` and ``--workers``: far above any experiment's, below what exhausts memory."""

MAX_BOXES = 1000
"""Bound of ``--boxes``: a hard family's test range (:attr:`puzzlebox.lab.hard_sets.HardSetConfig.max_boxes`)."""

Config = TypeVar("Config", bound="DataclassInstance")  # a protocol's config, a dataclass (see with_runs)


@dataclass(frozen=True)
class ExperimentFlags:
    """The command line of ``experiment.py``, flag by flag (None: not given), in the order of its flags."""

    protocol: str
    agents: str | None = None
    out: str = "."
    quick: bool = False
    runs: int | None = None
    seeds: int | None = None
    workers: int | None = None
    ray: str | None = None
    poses: str = "relative"
    memory: str | None = None
    cells: str | None = None
    validation: bool = False
    no_holding_rule: bool = False
    steps: int | None = None
    algo: str | None = None
    test_set: str | None = None
    profile: str | None = None
    boxes: int | None = None
    seed: int | None = None
    calibration: str | None = None
    reference: str | None = None

    def check(self) -> None:
        """The flags that belong to one protocol only are not given to another; sizes are bounded."""
        for flag, value, bound in (("--runs", self.runs, MAX_RUNS), ("--seeds", self.seeds, MAX_SEEDS),
                                   ("--workers", self.workers, MAX_WORKERS)):  # fmt: skip
            if value is not None and value > bound:
                raise ExperimentSettingsError(f"{flag} must be <= {bound}, got {value}")
        if self.cells is not None and self.protocol != SYSID:
            raise ExperimentSettingsError("--cells goes with the sysid protocol")
        if (self.validation or self.no_holding_rule) and self.protocol != DISASSEMBLY:
            raise ExperimentSettingsError("--validation and --no-holding-rule go with the disassembly protocol")
        if (self.steps is not None or self.algo is not None) and self.protocol != MANIPULATION:
            raise ExperimentSettingsError("--steps and --algo go with the manipulation protocol")
        if self.test_set is not None and self.protocol != TWIN_LEARNING:
            raise ExperimentSettingsError("--test-set goes with the twin-learning protocol")
        hard_only = {"--profile": self.profile, "--boxes": self.boxes}
        given = [flag for flag, value in hard_only.items() if value is not None]
        if given and self.protocol != HARD_SETS:
            verb = "goes" if len(given) == 1 else "go"
            raise ExperimentSettingsError(f"{' and '.join(given)} {verb} with the hard-sets protocol")
        held_out = [
            flag for flag, value in (("--seed", self.seed), ("--calibration", self.calibration)) if value is not None
        ]
        if held_out and self.protocol not in (HARD_SETS, TWIN_LEARNING):
            verb = "goes" if len(held_out) == 1 else "go"
            raise ExperimentSettingsError(
                f"{' and '.join(held_out)} {verb} with the hard-sets and twin-learning protocols"
            )
        if self.reference is not None and self.protocol != REGRESSION:
            raise ExperimentSettingsError("--reference goes with the regression protocol")
        if self.boxes is not None and not 1 <= self.boxes <= MAX_BOXES:
            raise ExperimentSettingsError(f"--boxes must be >= 1 and <= {MAX_BOXES}, got {self.boxes}")

    def agent_names(self, available: tuple[str, ...]) -> list[str]:
        """The ``--agents`` of a protocol that needs them, each one of ``available``."""
        if self.agents is None:
            raise ExperimentSettingsError(
                f"protocol {self.protocol!r} needs --agents (comma-separated, from {list(available)})"
            )
        agents = [a.strip() for a in self.agents.split(",") if a.strip()]
        unknown = [a for a in agents if a not in available]
        if not agents or unknown:
            raise ExperimentSettingsError(
                f"unknown agents {unknown or agents} for {self.protocol!r}; available: {list(available)}"
            )
        return agents

    def check_workers(self, show: bool = False) -> None:
        """``--workers``, if given, is at least 1 (``show``: the message shows the value given)."""
        if self.workers is not None and self.workers < 1:
            raise ExperimentSettingsError("--workers must be >= 1" + (f", got {self.workers}" if show else ""))
        if self.workers is not None and self.workers > MAX_WORKERS:
            raise ExperimentSettingsError(f"--workers must be <= {MAX_WORKERS}, got {self.workers}")

    def with_runs(self, config: Config, field: str, minimum: int, why: str = "") -> Config:
        """``config`` with ``--runs`` in ``field`` (unchanged without it); at least ``minimum`` (``why`` says
        why, if it is not obvious)."""
        if self.runs is None:
            return config
        if self.runs < minimum:
            raise ExperimentSettingsError(f"--runs must be >= {minimum}{why}, got {self.runs}")
        if self.runs > MAX_RUNS:
            raise ExperimentSettingsError(f"--runs must be <= {MAX_RUNS}, got {self.runs}")
        return replace(config, **{field: self.runs})

    def with_seeds(self, config: Config, field: str, as_range: bool = False) -> Config:
        """``config`` with ``--seeds`` (at least 1) in ``field``: the number, or with ``as_range`` the seeds
        0..N-1; unchanged without it."""
        if self.seeds is None:
            return config
        if not 1 <= self.seeds <= MAX_SEEDS:
            raise ExperimentSettingsError(f"--seeds must be >= 1 and <= {MAX_SEEDS}, got {self.seeds}")
        return replace(config, **{field: tuple(range(self.seeds)) if as_range else self.seeds})

    def only(self, allowed: str, *names: str) -> None:
        """None of the flags ``names`` is given to a protocol that takes only ``allowed`` (a phrase)."""
        given = [f"--{name}" for name in names if getattr(self, name) is not None]
        if given:
            raise ExperimentSettingsError(f"the {self.protocol} protocol takes only {allowed}, got {' '.join(given)}")

    def out_dir(self, directory_only: bool = True) -> Path:
        """``--out`` as a path: a directory (a file there is refused before any work)."""
        out = Path(self.out)
        if directory_only and out.exists() and not out.is_dir():
            raise ExperimentSettingsError(f"--out {out} is a file, not a directory")
        return out

    def write_config(self, out: Path, name: str, **settings: Any) -> None:
        """``DIR/<name>.config.json``: the command line, the resolved settings and the versions, beside the
        results; written under the directory's lock (:func:`hold_output`), which every protocol takes here,
        before its work."""
        hold_output(out)
        write_json(out / f"{name}.config.json", {"command": "experiment", **asdict(self), **settings,
                                                  "versions": versions()})  # fmt: skip


_HELD: list[OutputLock] = []


def hold_output(out: Path) -> None:
    """Own ``--out`` until :func:`release_outputs` (or the process's end): a directory another process writes, a
    file, or a place that cannot be written is refused (a :class:`~puzzlebox.lab.errors.RunStoreError`)."""
    if out.exists() and not out.is_dir():
        raise ExperimentSettingsError(f"--out {out} is a file, not a directory")
    _HELD.append(OutputLock(out))


def release_outputs() -> None:
    """Release every output :func:`hold_output` took."""
    while _HELD:
        _HELD.pop().release()
