"""The paper's puzzle family: all 12 five-component chains and the authors' train/test split.

Neighbours in a chain are door-slide or slide-wheel only, which leaves exactly 12 kind sequences of
length 5. Enumerated in lexicographic order with door=0, slide=1, wheel=2, the authors' release trains
on indices 0,1,2,4,5,7,8,10,11 and tests on 3, 6, 9 (PAPER_NOTES.md). Specs are named
``paper-train-<k>`` / ``paper-test-<k>`` with ``k`` counting within the split in index order, so
``paper-test-0`` is door-slide-wheel-slide-wheel.

All 12 boxes share one lid size (the smallest that holds every layout), as the paper's boxes share one
physical box.
"""

from __future__ import annotations

import itertools
from dataclasses import replace
from typing import Literal

import numpy as np

from puzzlebox.models.errors import GeneratorError
from puzzlebox.models.generator.chain import BoxConfig, assemble, chain_layout, chain_rules, fit_to_reach
from puzzlebox.models.kinds import KIND_NAMES, may_neighbour
from puzzlebox.models.spec import PuzzleSpec

PAPER_LENGTH = 5
TRAIN_INDICES = (0, 1, 2, 4, 5, 7, 8, 10, 11)
TEST_INDICES = (3, 6, 9)

Split = Literal["train", "test", "all"]


def paper_sequences() -> list[tuple[str, ...]]:
    """The 12 five-component kind sequences in lexicographic order (door < slide < wheel)."""
    return [
        seq
        for seq in itertools.product(KIND_NAMES, repeat=PAPER_LENGTH)
        if all(may_neighbour(a, b) for a, b in itertools.pairwise(seq))
    ]


def paper_variant_name(index: int) -> str:
    """``paper-train-k`` or ``paper-test-k`` for variant ``index`` (0..11)."""
    if index in TEST_INDICES:
        return f"paper-test-{TEST_INDICES.index(index)}"
    return f"paper-train-{TRAIN_INDICES.index(index)}"


def paper_variant(index: int, seed: int, box: BoxConfig | None = None) -> PuzzleSpec:
    """One paper variant (0..11) with a layout drawn from ``seed`` — for protocols that sample a new
    layout per trial, as the paper does. The lid is sized to this layout alone unless ``box`` says."""
    sequences = paper_sequences()
    if not 0 <= index < len(sequences):
        raise ValueError(f"paper variant index must be in 0..{len(sequences) - 1}, got {index}")
    box = box or BoxConfig()
    layout = chain_layout(sequences[index], np.random.default_rng([seed, index]), box.layout)
    spec = assemble(
        paper_variant_name(index), sequences[index], layout, chain_rules(PAPER_LENGTH), PAPER_LENGTH - 1, box
    )
    return _fitted(spec, box)


def paper_family(split: Split = "all", seed: int = 0, box: BoxConfig | None = None) -> list[PuzzleSpec]:
    """The paper's boxes of a split, as specs; a pure function of (split, seed, box).

    Args:
        split: ``train`` (9 variants), ``test`` (3) or ``all`` (12, in variant-index order).
        seed: seeds every variant's layout (variant ``i`` uses ``default_rng([seed, i])``).
        box: the box; by default one lid size shared by all 12 variants.
    """
    if split not in ("train", "test", "all"):
        raise ValueError(f"unknown split {split!r}; choose 'train', 'test' or 'all'")
    box = box or BoxConfig()
    sequences = paper_sequences()
    layouts = [chain_layout(seq, np.random.default_rng([seed, i]), box.layout) for i, seq in enumerate(sequences)]
    if box.lid_size is None:  # one box for the whole family, sized on all 12 layouts
        sizes = np.array([layout.lid_size() for layout in layouts])
        box = replace(box, lid_size=(float(sizes[:, 0].max()), float(sizes[:, 1].max())))
    wanted = {"train": TRAIN_INDICES, "test": TEST_INDICES, "all": tuple(range(len(sequences)))}[split]
    specs = []
    for i in wanted:
        rules = chain_rules(PAPER_LENGTH)
        spec = assemble(paper_variant_name(i), sequences[i], layouts[i], rules, PAPER_LENGTH - 1, box)
        specs.append(_fitted(spec, box))
    return specs


def _fitted(spec: PuzzleSpec, box: BoxConfig) -> PuzzleSpec:
    """The paper's 5-component boxes always fit the reach (at the default pose, as it happens)."""
    fitted = fit_to_reach(spec, box)
    if fitted is None:
        raise GeneratorError(f"{spec.name}: no box pose puts every handle within the robot's reach")
    return fitted
