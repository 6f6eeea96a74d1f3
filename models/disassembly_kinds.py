"""Component kinds of the computer-disassembly domain: the second kind family (issue 14).

A *disassembly scene* is a spec with no ``box`` whose components carry 6-DOF poses
``[x, y, z, roll, pitch, yaw]`` [m, rad] in one common frame (the two measured lab computers in
``learning/data/disassembly/``, shipped with the package, are relative to the first case screw). Every component has
two states: 0 = in place (mounted, as found), 1 = removed. The puzzle-box family (:mod:`models.kinds`:
door, slide, wheel) is a separate family; one spec never mixes the two.

Per kind (state 0 / state 1):

``screw``
    A case screw: 0 screwed in, 1 unscrewed and removed.
``panel``
    The case side panel: 0 mounted on the case, 1 taken off.
``cpu``
    The processor (with its cooler): 0 seated in its socket, 1 lifted out.
``ram``
    One memory stick: 0 clipped into its slot, 1 pulled out.
``gpu_cable``
    The graphics card's power cable: 0 plugged into the card, 1 unplugged and removed.
``gpu``
    The graphics card: 0 seated in its slot, 1 pulled out.
``motherboard``
    The main board: 0 mounted in the case, 1 taken out (the task's goal in the paper).

Allowed relations (:data:`ALLOWED_LOCKS`) are *directed*: ``(locker kind, locked kind)`` pairs whose
lock, "while the locker is in place, the locked component cannot be removed", occurs in the domain.
They are the union of the lock rules of ``lab-computer-a`` and ``lab-computer-b`` (every rule there is
locker state 0 holds locked state 0) and match the paper's description (PAPER_NOTES.md: screws,
side panel, CPU, RAM, GPU cable, GPU, motherboard; the panel is held by its screws, the motherboard
by everything on it): screws hold the panel; the panel holds everything inside the case; the GPU
cable holds the GPU; the CPU, the RAM sticks and the GPU hold the motherboard. Like the puzzle-box
family's :data:`models.kinds.ALLOWED_NEIGHBOURS`, they describe the domain for generators and priors;
validation does not reject a lock outside them (SPEC.md's validity rules do not mention kinds'
relations).
"""

from __future__ import annotations

from puzzlebox.models.errors import UnknownKindError
from puzzlebox.models.kinds import KIND_NAMES, registered_kinds, registry_family

DISASSEMBLY_FAMILY = "disassembly"
"""Name of this kind family."""
PUZZLE_BOX_FAMILY = "puzzle-box"
"""Name of the puzzle-box kind family (:mod:`models.kinds`)."""

DISASSEMBLY_POSE_SIZE = 6
"""A disassembly component's pose: ``[x, y, z, roll, pitch, yaw]`` [m, rad]."""

DISASSEMBLY_KINDS: dict[str, str] = {
    "screw": "a case screw: 0 screwed in, 1 unscrewed and removed",
    "panel": "the case side panel: 0 mounted, 1 taken off",
    "cpu": "the processor: 0 seated in its socket, 1 lifted out",
    "ram": "a memory stick: 0 clipped into its slot, 1 pulled out",
    "gpu_cable": "the graphics card's power cable: 0 plugged in, 1 unplugged and removed",
    "gpu": "the graphics card: 0 seated in its slot, 1 pulled out",
    "motherboard": "the main board: 0 mounted in the case, 1 taken out",
}
"""The disassembly kinds, by name: what states 0 and 1 mean (state 1 = removed)."""

DISASSEMBLY_KIND_NAMES: tuple[str, ...] = tuple(DISASSEMBLY_KINDS)
"""The disassembly kinds in a fixed order: a kind's integer code within its family is its index here."""

ALLOWED_LOCKS: frozenset[tuple[str, str]] = frozenset(
    {
        ("screw", "panel"),
        ("panel", "cpu"),
        ("panel", "ram"),
        ("panel", "gpu_cable"),
        ("panel", "gpu"),
        ("panel", "motherboard"),
        ("gpu_cable", "gpu"),
        ("cpu", "motherboard"),
        ("ram", "motherboard"),
        ("gpu", "motherboard"),
    }
)
"""Directed ``(locker kind, locked kind)`` pairs that may lock each other (see the module docstring)."""


def may_lock(locker_kind: str, locked_kind: str) -> bool:
    """Whether a component of ``locker_kind`` may hold one of ``locked_kind`` in place."""
    return (locker_kind, locked_kind) in ALLOWED_LOCKS


def holding_states(kind: str) -> tuple[int, ...]:
    """The states in which a component of ``kind`` can hold another in place: both for the puzzle-box kinds
    (an open door can block a slide as a closed one can), only 0 for the disassembly kinds — state 1 is
    *removed*, and a part out of the case holds nothing. :class:`UnknownKindError` lists every known kind."""
    return (0,) if kind_family(kind) == DISASSEMBLY_FAMILY else (0, 1)


def kind_family(kind: str) -> str:
    """``"puzzle-box"`` or ``"disassembly"``; :class:`UnknownKindError` lists every known kind."""
    if kind in registered_kinds():
        return PUZZLE_BOX_FAMILY
    if kind in DISASSEMBLY_KINDS:
        return DISASSEMBLY_FAMILY
    raise UnknownKindError(kind, (*registered_kinds(), *DISASSEMBLY_KIND_NAMES))


def family_kind_names(kinds: tuple[str, ...] | list[str]) -> tuple[str, ...]:
    """The kind names of the one family all ``kinds`` belong to (their integer codes are indices here):
    :data:`models.kinds.KIND_NAMES` (the paper's, when every kind is one of them), every registered kind
    (:func:`models.kinds.registry_family`, for boxes with another kind) or :data:`DISASSEMBLY_KIND_NAMES`.
    Raises :class:`UnknownKindError` for an unknown kind and ``ValueError`` for kinds of both families."""
    families = {kind_family(k) for k in kinds}
    if len(families) > 1:
        raise ValueError(f"kinds {sorted(set(kinds))} mix the puzzle-box and disassembly families")
    if families == {DISASSEMBLY_FAMILY}:
        return DISASSEMBLY_KIND_NAMES
    return KIND_NAMES if set(kinds) <= set(KIND_NAMES) else registry_family().kinds
