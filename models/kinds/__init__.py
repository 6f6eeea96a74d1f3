"""Component kinds of the puzzle box: one module per kind, a registry, and the paper's family.

- :mod:`models.kinds.template`: :class:`KindTemplate` (joint, travel, handle, footprint in the component
  frame) and the dimensions every kind shares (marker, handle).
- :mod:`models.kinds.door`, :mod:`~models.kinds.slide`, :mod:`~models.kinds.wheel`: each kind's frame,
  dimensions, template, joint dynamics, colour and MJCF parts.
- :mod:`models.kinds.registry`: the kinds ``models`` can build, by name: every module here defining
  ``KIND``, found by the registry (adding a kind is adding its module), and :func:`registry_family`.
- :mod:`models.kinds.family`: :data:`PAPER_FAMILY`, the paper's kinds, codes and allowed neighbours,
  pinned so that registering a kind never changes the paper's boxes.

Dimensions are chosen for the xArm-7's gripper and for markers an overview camera reads reliably;
travels follow the motions measured on this stack in DESIGN.md (door 85 deg, slide 50 mm, wheel 85 deg).
"""

from __future__ import annotations

from puzzlebox.models.errors import UnknownKindError
from puzzlebox.models.kinds.door import DOOR, DOOR_HALF
from puzzlebox.models.kinds.family import PAPER_FAMILY, KindFamily, UnknownFamilyError
from puzzlebox.models.kinds.kind import Handling, JointDynamics, Kind
from puzzlebox.models.kinds.registry import (
    DuplicateKindError,
    KindRegistry,
    family_named,
    get_kind,
    register,
    registered_kind,
    registered_kinds,
    registry_family,
)
from puzzlebox.models.kinds.slide import SLIDE, SLIDE_BACK, SLIDE_HALF
from puzzlebox.models.kinds.template import (
    HANDLE_HEIGHT,
    HANDLE_MARGIN,
    HANDLE_OFFSET,
    HANDLE_SIZE,
    MARKER_SIZE,
    KindTemplate,
)
from puzzlebox.models.kinds.wheel import WHEEL, WHEEL_RADIUS

PUZZLE_KINDS: dict[str, KindTemplate] = {k.name: k for k in (DOOR, SLIDE, WHEEL)}
"""The paper family's kinds, by name (pinned: a newly registered kind is not a paper kind)."""

KIND_NAMES: tuple[str, ...] = PAPER_FAMILY.kinds
"""The paper family's kinds in a fixed order: the integer code of a kind is its index here."""

ALLOWED_NEIGHBOURS: frozenset[frozenset[str]] = PAPER_FAMILY.neighbours
"""Kind pairs that may lock each other (the paper: doors and wheels never interact, nor do two
components of the same kind)."""


def kind_code(name: str, kinds: tuple[str, ...] = KIND_NAMES) -> int:
    """Integer code of a kind: its index in ``kinds``, the kind names of a family (default :data:`KIND_NAMES`, the
    paper's; a box's own: ``models.disassembly_kinds.family_kind_names(spec.kinds)``, as the environments code
    them). :class:`UnknownKindError` says when the kind is registered but not of that family."""
    if name in kinds:
        return kinds.index(name)
    if name in registered_kinds():
        raise UnknownKindError(
            name,
            kinds,
            f"kind {name!r} is registered but not one of {list(kinds)}, whose codes these are (the paper's "
            "family by default); a box of other kinds codes them as the environments do: "
            f"kind_code(kind, family_kind_names(spec.kinds)), here {list(registry_family().kinds)}",
        )
    raise UnknownKindError(name, registered_kinds())


def may_neighbour(kind_a: str, kind_b: str) -> bool:
    """Whether components of these two kinds may lock each other (in the paper's family)."""
    return PAPER_FAMILY.may_neighbour(kind_a, kind_b)


__all__ = [
    "ALLOWED_NEIGHBOURS",
    "DOOR",
    "DOOR_HALF",
    "HANDLE_HEIGHT",
    "HANDLE_MARGIN",
    "HANDLE_OFFSET",
    "HANDLE_SIZE",
    "KIND_NAMES",
    "MARKER_SIZE",
    "PAPER_FAMILY",
    "PUZZLE_KINDS",
    "SLIDE",
    "SLIDE_BACK",
    "SLIDE_HALF",
    "WHEEL",
    "WHEEL_RADIUS",
    "DuplicateKindError",
    "Handling",
    "JointDynamics",
    "Kind",
    "KindFamily",
    "KindRegistry",
    "KindTemplate",
    "UnknownFamilyError",
    "UnknownKindError",
    "family_named",
    "get_kind",
    "kind_code",
    "may_neighbour",
    "register",
    "registered_kind",
    "registered_kinds",
    "registry_family",
]
