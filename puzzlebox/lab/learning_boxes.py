"""The boxes ``experiment.py twin-learning`` trains on and tests on, per test set.

- ``paper``: the paper's 9 training boxes and (the first ``count`` of) its 3 test boxes; the one-locker belief.
- ``hard``: the hard sets of :mod:`puzzlebox.lab.hard_sets` (eight parts of every kind: random, multi-locker and
  chains), ``count`` test boxes of each family, and training boxes of the same families drawn with other seeds
  (held out: never a test box). The multi-locker family's boxes are tried with a belief over sets of up to two
  lockers (what ``--max-lockers 2`` asks of ``trial.py``).

Each box carries its optimum (the fewest actions that solve it), reported beside every figure. Generating an
eight-part box takes seconds (the mechanism design search), so the hard boxes are kept as spec files in a folder
and read back from there by the next run (the same seeds give the same boxes: the file is only a cache).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from puzzlebox.lab.hard_sets import HARD_FAMILIES, HardSetConfig, hard_box, optimum
from puzzlebox.models import PuzzleSpec, load_spec, save_spec
from puzzlebox.models.generator import paper_family

TEST_SETS = ("paper", "hard")
"""The test sets of ``experiment.py twin-learning --test-set``."""


@dataclass(frozen=True)
class LearningBox:
    """A box of the experiment, with what its trials need to know about it."""

    spec: PuzzleSpec
    family: str
    """``paper`` or the hard family (``random8``, ``multi8``, ``chain8``)."""
    max_lockers: int
    """The most lockers the agent's belief allows one part on this box."""
    optimum: int
    """The fewest actions that solve it."""


def test_boxes(test_set: str, count: int, folder: Path, hard: HardSetConfig | None = None) -> list[LearningBox]:
    """The test boxes: the first ``count`` paper test boxes, or ``count`` boxes of each hard family (cached in
    ``folder``)."""
    if test_set == "paper":
        return [LearningBox(s, "paper", 1, optimum(s)) for s in paper_family("test", seed=0)[:count]]
    hard = _hard_config(test_set, hard)
    return [_hard(f.name, hard.test_seed + i, hard, folder) for f in HARD_FAMILIES for i in range(count)]


def training_boxes(test_set: str, count: int, folder: Path, hard: HardSetConfig | None = None) -> list[LearningBox]:
    """The training boxes: the 9 paper training boxes (``count`` unused), or ``count`` boxes of each hard family,
    the families interleaved (so any first ``3 k`` of them hold ``k`` of each)."""
    if test_set == "paper":
        return [LearningBox(s, "paper", 1, optimum(s)) for s in paper_family("train", seed=0)]
    hard = _hard_config(test_set, hard)
    return [_hard(f.name, hard.train_seed + i, hard, folder) for i in range(count) for f in HARD_FAMILIES]


def _hard_config(test_set: str, hard: HardSetConfig | None) -> HardSetConfig:
    if test_set not in TEST_SETS:
        raise ValueError(f"unknown test set {test_set!r}; test sets: {list(TEST_SETS)}")
    return hard or HardSetConfig()


def _hard(name: str, seed: int, config: HardSetConfig, folder: Path) -> LearningBox:
    family = next(f for f in HARD_FAMILIES if f.name == name)
    path = folder / f"hard-{name}-n{config.components}-s{seed}.json"
    if path.exists():
        spec = load_spec(path)
    else:
        spec = hard_box(name, seed, config.components)
        save_spec(spec, path)
    return LearningBox(spec, name, family.max_lockers, optimum(spec))
