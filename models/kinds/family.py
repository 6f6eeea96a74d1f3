"""A kind family: which kinds a set of puzzles draws from, their integer codes and which pairs may lock
each other. The paper's family is pinned here by name, so registering a new kind
(:mod:`models.kinds.registry`) can never change the paper's 12 boxes, their codes or their split."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from puzzlebox.models.errors import ModelsError, UnknownKindError


class UnknownFamilyError(ModelsError, ValueError):
    """A kind family asked for by a name that names none."""

    def __init__(self, name: str, available: Iterable[str]) -> None:
        self.family = name
        self.available = tuple(sorted(available))
        super().__init__(f"unknown kind family {name!r}; families: {list(self.available)}")


@dataclass(frozen=True)
class KindFamily:
    """A fixed, ordered set of kinds and the kind pairs that may lock each other."""

    name: str
    """Name of the family."""
    kinds: tuple[str, ...]
    """The family's kinds in a fixed order: the integer code of a kind is its index here."""
    neighbours: frozenset[frozenset[str]]
    """Kind pairs that may lock each other (a one-element set would be a kind locking its own kind)."""

    def __post_init__(self) -> None:
        # a neighbour pair naming a kind outside the family would silently never be drawn
        strangers = sorted({k for pair in self.neighbours for k in pair} - set(self.kinds))
        if strangers:
            raise UnknownKindError(strangers[0], self.kinds)
        if len(set(self.kinds)) != len(self.kinds):
            raise ValueError(f"family {self.name!r} lists a kind twice: {list(self.kinds)}")

    def code(self, kind: str) -> int:
        """Integer code of a kind (its index in :attr:`kinds`); :class:`UnknownKindError` lists the family."""
        try:
            return self.kinds.index(kind)
        except ValueError:
            raise UnknownKindError(kind, self.kinds) from None

    def may_neighbour(self, kind_a: str, kind_b: str) -> bool:
        """Whether components of these two kinds may lock each other."""
        return frozenset({kind_a, kind_b}) in self.neighbours


PAPER_FAMILY = KindFamily(
    name="paper",
    kinds=("door", "slide", "wheel"),
    neighbours=frozenset({frozenset({"door", "slide"}), frozenset({"slide", "wheel"})}),
)
"""The paper's puzzle-box family: doors and wheels never interact, nor do two components of the same
kind. Its kind order gives the kind codes the learners see; never derive it from the registry."""
