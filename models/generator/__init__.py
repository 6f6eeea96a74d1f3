"""Procedural puzzle generators: the paper's family, chains of any kinds, random lock graphs, one-part boxes.

Every generator is a pure function of its parameters and seed: the same call gives byte-identical
JSON.
"""

from puzzlebox.models.generator.chain import BoxConfig, check_chain_kinds, generate_chain
from puzzlebox.models.generator.layout import LayoutConfig
from puzzlebox.models.generator.paper import (
    TEST_INDICES,
    TRAIN_INDICES,
    paper_family,
    paper_sequences,
    paper_variant,
    paper_variant_name,
)
from puzzlebox.models.generator.random_graph import MAX_RANDOM_COMPONENTS, RandomGraphConfig, generate_random
from puzzlebox.models.generator.single import single_part

__all__ = [
    "MAX_RANDOM_COMPONENTS",
    "TEST_INDICES",
    "TRAIN_INDICES",
    "BoxConfig",
    "LayoutConfig",
    "RandomGraphConfig",
    "check_chain_kinds",
    "generate_chain",
    "generate_random",
    "paper_family",
    "paper_sequences",
    "paper_variant",
    "paper_variant_name",
    "single_part",
]
