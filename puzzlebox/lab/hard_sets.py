"""The twin's hard test sets (issue 36): eight-part boxes of every registered kind, in three families.

- ``random8``: random lock graphs of N = 8 parts whose kinds are drawn from every registered kind
  (``generate.py random --components 8 --kinds all``);
- ``multi8``: the same with some parts held by two lockers (``--multi-locker``); the agent's belief is asked for
  sets of up to :attr:`HardFamily.max_lockers` = 2 lockers on them (``trial.py --max-lockers 2``);
- ``chain8``: chains of N = 8 parts (the paper's chain rules), the kinds a random walk over the pairs that may lock
  each other (``generate.py chain --kinds ...``).

A box is a pure function of (family, seed): test box ``i`` of a family has seed ``test_seed + i``, training box
``i`` seed ``train_seed + i``; the two ranges never meet (:meth:`HardSetConfig.__post_init__`), so the test boxes are
held out from any training on boxes of the same families. Every box stands where the robot reaches every handle
(the generators' reach fitting); in the twin each trial's seed then places it anew at a random reachable pose
(``RealityProfile.placement``). Its optimum, the fewest actions that open the goal, is the lock table's shortest
solution (:func:`optimum`), what the oracle agent takes symbolically.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from puzzlebox.models import LockTable, PuzzleSpec
from puzzlebox.models.errors import GeneratorError
from puzzlebox.models.generator import RandomGraphConfig, generate_chain, generate_random
from puzzlebox.models.kinds import get_kind, registry_family


@dataclass(frozen=True)
class HardFamily:
    """One hard family: how its boxes are drawn."""

    name: str
    generator: str
    """``random`` or ``chain``."""
    multi_locker: bool = False
    """Some parts held by two lockers (random graphs only)."""
    max_lockers: int = 1
    """The most lockers the agent's belief allows one part on these boxes (the ``--max-lockers`` a user gives)."""


HARD_FAMILIES = (
    HardFamily("random8", "random"),
    HardFamily("multi8", "random", multi_locker=True, max_lockers=2),
    HardFamily("chain8", "chain"),
)
"""The hard families, in the order the experiments report them."""
FAMILY_NAMES = tuple(f.name for f in HARD_FAMILIES)
MAX_CHAIN_DRAWS = 20
"""Walks of kinds drawn for one chain before giving up."""
MAX_EDGE_PARTS = 2
"""Most edge-mounted parts (drawers) in a chain: a walk with more is drawn again, as its layout search mostly fails
(a chain of 8 with 4 drawers took 34 s to lay out, one with 2 about 1.5 s)."""


@dataclass(frozen=True)
class HardSetConfig:
    """Sizes and seeds of the hard sets."""

    components: int = 8
    """Parts per box N."""
    test_seed: int = 36_000
    """Seed of test box 0 of every family (box ``i``: ``test_seed + i``)."""
    train_seed: int = 0
    """Seed of training box 0 of every family (box ``i``: ``train_seed + i``)."""
    max_boxes: int = 1000
    """Most boxes of one family in either range: the ranges ``[seed, seed + max_boxes)`` may not overlap."""

    def __post_init__(self) -> None:
        if abs(self.test_seed - self.train_seed) < self.max_boxes:
            raise ValueError(
                f"test seeds from {self.test_seed} and training seeds from {self.train_seed} overlap within "
                f"{self.max_boxes} boxes: the test boxes would not be held out"
            )


def family(name: str) -> HardFamily:
    """The hard family called ``name``; ``ValueError`` names the families."""
    for f in HARD_FAMILIES:
        if f.name == name:
            return f
    raise ValueError(f"unknown hard family {name!r}; families: {list(FAMILY_NAMES)}")


def chain_kinds(length: int, rng: np.random.Generator) -> list[str]:
    """A random walk of ``length`` kinds over the registry family's pairs that may lock each other."""
    kinds = registry_family()
    walk = [kinds.kinds[int(rng.integers(len(kinds.kinds)))]]
    while len(walk) < length:
        partners = [k for k in kinds.kinds if kinds.may_neighbour(walk[-1], k)]
        walk.append(partners[int(rng.integers(len(partners)))])
    return walk


def hard_box(name: str, seed: int, components: int = 8) -> PuzzleSpec:
    """Box ``seed`` of the hard family ``name`` (named ``hard-<family>-s<seed>``); pure in its arguments."""
    f = family(name)
    spec_name = f"hard-{f.name}-s{seed}"
    if f.generator == "chain":
        # the kinds from a stream of their own, so the layout draws (seeded by ``seed``) are the generator's
        rng = np.random.default_rng([seed, 1])
        for _ in range(MAX_CHAIN_DRAWS):
            kinds = chain_kinds(components, rng)
            if sum(get_kind(k).edge_x is not None for k in kinds) > MAX_EDGE_PARTS:
                continue
            try:  # some walks still cannot be laid out: draw the next one
                return generate_chain(kinds, seed=seed, name=spec_name)
            except GeneratorError:
                continue
        raise GeneratorError(
            f"no chain of {components} kinds could be laid out in {MAX_CHAIN_DRAWS} walks (seed {seed})"
        )
    config = RandomGraphConfig(components, multi_locker=f.multi_locker, family=registry_family())
    return generate_random(config, seed=seed, name=spec_name)


def hard_test_set(name: str, count: int, config: HardSetConfig | None = None) -> list[PuzzleSpec]:
    """The first ``count`` test boxes of family ``name``."""
    config = config or HardSetConfig()
    _check_count(count, config)
    return [hard_box(name, config.test_seed + i, config.components) for i in range(count)]


def hard_training_set(name: str, count: int, config: HardSetConfig | None = None) -> list[PuzzleSpec]:
    """The first ``count`` training boxes of family ``name`` (never a test box: other seeds)."""
    config = config or HardSetConfig()
    _check_count(count, config)
    return [hard_box(name, config.train_seed + i, config.components) for i in range(count)]


def _check_count(count: int, config: HardSetConfig) -> None:
    if not 0 <= count <= config.max_boxes:
        raise ValueError(f"a hard set holds 0..{config.max_boxes} boxes, got {count}")


def optimum(spec: PuzzleSpec) -> int:
    """The fewest actions that open ``spec``'s goal from all parts closed (its lock table's shortest solution)."""
    plan = LockTable.from_spec(spec).shortest_solution()
    if plan is None:  # every generated box is solvable by construction; a hand-made one may not be
        raise ValueError(f"spec {spec.name!r} has no solution")
    return len(plan)


def family_of(spec: PuzzleSpec) -> HardFamily:
    """The hard family a box generated here belongs to (from its name ``hard-<family>-s<seed>``)."""
    parts = spec.name.split("-")
    if len(parts) < 3 or parts[0] != "hard":
        raise ValueError(f"spec {spec.name!r} is not a hard-set box (hard-<family>-s<seed>)")
    return family(parts[1])
