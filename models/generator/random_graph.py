"""Random lock graphs: N components in a tree of neighbours, always valid and solvable.

Components are placed one at a time, each next to an already placed *anchor* of an allowed kind (the config's
family: the paper's door-slide, slide-wheel by default), so a locker always sits next to what it locks. The
anchor locks the new component closed (``anchor 0 keeps new 0``) and, with probability
``reverse_lock_probability``, the new component open keeps the anchor open (the paper's second chain rule).
With ``multi_locker``, some components get a second locker: another placed neighbour of an allowed kind.

Every locker of a component is placed before it, so opening the components in placement order
solves the puzzle: every generated spec is solvable by construction (and validated anyway).
The goal is the component with the longest chain of lockers behind it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from puzzlebox.models.errors import GeneratorError
from puzzlebox.models.generator.chain import (
    MAX_LAYOUT_ATTEMPTS,
    BoxConfig,
    assemble,
    check_reach_size,
    fit_to_reach,
    realizable,
)
from puzzlebox.models.generator.layout import Layout
from puzzlebox.models.kinds import PAPER_FAMILY, KindFamily
from puzzlebox.models.spec import PuzzleSpec

MAX_RANDOM_COMPONENTS = 40
"""Layouts and the validator's reachability search stay fast up to this many components."""


@dataclass(frozen=True)
class RandomGraphConfig:
    """Parameters of a random lock graph."""

    num_components: int = 6
    """Number of components N (2..40)."""
    multi_locker: bool = False
    """Give some components two lockers (at least one component when the layout allows)."""
    second_locker_probability: float = 0.5
    """With ``multi_locker``: chance that a component with a free neighbour gets a second locker."""
    reverse_lock_probability: float = 0.5
    """Chance of the rule 'new component open keeps its anchor open'."""
    family: KindFamily = PAPER_FAMILY
    """Kinds drawn and the pairs that may lock each other: the paper's (default; its boxes unchanged) or
    :func:`models.kinds.registry_family` (every registered kind: ``generate.py random --kinds all``)."""
    required_kinds: tuple[str, ...] = ()
    """Kinds every box must hold at least one of (``generate.py random --require-kinds``): layouts without them are
    drawn again. Empty (default): any, the boxes unchanged."""


def _partner_kinds(family: KindFamily, kind: str) -> list[str]:
    return [k for k in family.kinds if family.may_neighbour(kind, k)]


def generate_random(
    config: RandomGraphConfig, seed: int, name: str | None = None, box: BoxConfig | None = None
) -> PuzzleSpec:
    """A random solvable lock graph; a pure function of (config, seed, name, box)."""
    n = config.num_components
    if not 2 <= n <= MAX_RANDOM_COMPONENTS:
        raise GeneratorError(f"num_components must be in 2..{MAX_RANDOM_COMPONENTS}, got {n}")
    if config.multi_locker and n < 4:
        # two lockers of the same kind group must both touch the new component: a square of four
        raise GeneratorError(f"multi_locker needs at least 4 components, got {n}")
    for label, p in (
        ("second_locker_probability", config.second_locker_probability),
        ("reverse_lock_probability", config.reverse_lock_probability),
    ):
        if not 0.0 <= p <= 1.0:
            raise GeneratorError(f"{label} must be in [0, 1], got {p}")
    unknown = sorted(set(config.required_kinds) - set(config.family.kinds))
    if unknown:
        raise GeneratorError(f"required kinds {unknown} are not of the family drawn from: {list(config.family.kinds)}")
    if len(set(config.required_kinds)) > n:
        raise GeneratorError(f"{len(set(config.required_kinds))} required kinds do not fit in {n} components")
    box = box or BoxConfig()
    check_reach_size(n, box)
    rng = np.random.default_rng(seed)
    name = name or f"random-n{n}{'-multi' if config.multi_locker else ''}-s{seed}"
    for _ in range(MAX_LAYOUT_ATTEMPTS):
        built = _try_build(config, rng, box)
        if built is not None:
            layout, rules, goal = built
            spec = fit_to_reach(assemble(name, layout.kinds, layout, rules, goal, box), box)
            if spec is not None and realizable(spec, box):
                return spec
    raise GeneratorError(
        f"no layout of {n} components that fits the robot's reach{' with every lock a mechanism' * box.realizable} "
        f"in {MAX_LAYOUT_ATTEMPTS} attempts"
    )


def _try_build(
    config: RandomGraphConfig, rng: np.random.Generator, box: BoxConfig
) -> tuple[Layout, list[tuple[int, int, int, int]], int] | None:
    layout = Layout(box.layout)
    kinds = config.family.kinds
    layout.place_first(kinds[int(rng.integers(len(kinds)))])
    lockers: list[list[int]] = [[]]
    rules: list[tuple[int, int, int, int]] = []
    for new in range(1, config.num_components):
        placed = False
        for anchor in rng.permutation(len(layout)):
            partners = _partner_kinds(config.family, layout.kinds[anchor])
            kind = partners[int(rng.integers(len(partners)))]
            if layout.attach(int(anchor), kind, rng):
                placed = True
                break
        if not placed:
            return None
        anchor = int(anchor)
        lockers.append([anchor])
        rules.append((anchor, 0, new, 0))
        if rng.random() < config.reverse_lock_probability:
            rules.append((new, 1, anchor, 1))
        if config.multi_locker and rng.random() < config.second_locker_probability:
            second = _second_locker(config.family, layout, new, anchor, rng)
            if second is not None:
                lockers[new].append(second)
                rules.append((second, 0, new, 0))
    if config.multi_locker and all(len(ls) < 2 for ls in lockers):
        return None  # asked for a two-locker component and this layout has none: draw another
    if not set(config.required_kinds) <= set(layout.kinds):
        return None  # a kind asked for is missing: draw another
    depth = [0] * config.num_components
    for c in range(1, config.num_components):  # lockers come first, so one pass suffices
        depth[c] = 1 + max(depth[locker] for locker in lockers[c])
    goal = int(np.flatnonzero(np.array(depth) == max(depth))[-1])
    layout.turn_lengthwise()
    return layout, rules, goal


def _second_locker(family: KindFamily, layout: Layout, new: int, anchor: int, rng: np.random.Generator) -> int | None:
    options = [
        other
        for other in range(new)
        if other != anchor
        and family.may_neighbour(layout.kinds[other], layout.kinds[new])
        and layout.are_neighbours(other, new)
    ]
    return int(options[int(rng.integers(len(options)))]) if options else None
