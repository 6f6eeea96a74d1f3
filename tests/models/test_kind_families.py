"""Kind families: the paper's is pinned, the registry's holds every registered kind with the pairs the kinds
name, generators draw from the family they are given, and validation accepts every registered kind."""

import itertools
import json

import pytest

from puzzlebox.models import LockTable, validate_data
from puzzlebox.models.disassembly_kinds import DISASSEMBLY_KIND_NAMES, family_kind_names
from puzzlebox.models.generator import RandomGraphConfig, generate_chain, generate_random, paper_family
from puzzlebox.models.kinds import (
    KIND_NAMES,
    PAPER_FAMILY,
    UnknownFamilyError,
    family_named,
    registered_kind,
    registered_kinds,
    registry_family,
)


def test_the_registry_family_holds_every_registered_kind_in_registration_order():
    family = registry_family()
    assert family.kinds == registered_kinds() and family.kinds[:3] == KIND_NAMES
    for a, b in itertools.product(family.kinds, repeat=2):  # a pair is allowed when either kind names the other
        named = b in registered_kind(a).neighbours or a in registered_kind(b).neighbours
        assert family.may_neighbour(a, b) == named, (a, b)
    for a, b in itertools.product(KIND_NAMES, repeat=2):  # on the paper's kinds, the paper's pairs exactly
        assert family.may_neighbour(a, b) == PAPER_FAMILY.may_neighbour(a, b), (a, b)


def test_families_are_asked_for_by_name_and_an_unknown_name_lists_them():
    assert family_named("paper") is PAPER_FAMILY
    assert family_named("all") == registry_family()
    with pytest.raises(UnknownFamilyError, match=r"'kitchen'.*\['all', 'paper'\]"):
        family_named("kitchen")


@pytest.mark.parametrize("seed", range(12))
def test_random_boxes_of_the_registry_family_use_only_its_kinds_and_pairs(seed):
    family = registry_family()
    spec = generate_random(RandomGraphConfig(6, multi_locker=seed % 2 == 1, family=family), seed=seed)
    assert set(spec.kinds) <= set(family.kinds)
    kinds = {c.name: c.kind for c in spec.components}
    for rule in spec.locks:
        assert family.may_neighbour(kinds[rule.locker], kinds[rule.locked]), rule
    assert not validate_data(json.loads(spec.to_json()))
    assert LockTable.from_spec(spec).shortest_solution() is not None


def test_the_default_random_family_is_the_papers_and_its_boxes_are_unchanged_by_the_field():
    for seed in range(5):
        default = generate_random(RandomGraphConfig(6), seed=seed)
        assert set(default.kinds) <= set(KIND_NAMES)
        assert default.to_json() == generate_random(RandomGraphConfig(6, family=PAPER_FAMILY), seed=seed).to_json()
    assert all(set(s.kinds) <= set(KIND_NAMES) for s in paper_family("all"))


def test_kind_codes_are_the_papers_for_paper_boxes_and_the_registrys_otherwise():
    assert family_kind_names(["door", "wheel"]) == KIND_NAMES
    assert family_kind_names(["screw", "panel"]) == DISASSEMBLY_KIND_NAMES
    others = [k for k in registered_kinds() if k not in KIND_NAMES]
    if others:
        assert family_kind_names(["door", others[0]]) == registered_kinds()
    with pytest.raises(ValueError, match="mix"):
        family_kind_names(["door", "screw"])


def test_a_chain_of_kinds_that_may_not_lock_each_other_is_refused_naming_the_allowed_pairs():
    from puzzlebox.models.errors import GeneratorError

    with pytest.raises(GeneratorError, match="door-slide"):
        generate_chain(["door", "wheel"], seed=0)
    with pytest.raises(GeneratorError, match="known kinds"):
        generate_chain(["door", "trapdoor"], seed=0)
