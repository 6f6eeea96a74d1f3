"""The kind registry: every component kind ``models`` can build, by name.

A kind is one module of this package that defines ``KIND`` (a :class:`~models.kinds.kind.Kind`); the
registry finds it there, so adding a kind is adding its module (and its tests). Builders, generators and
the skills ask the registry (:func:`registered_kind`) and hold no per-kind branches. Registering a kind
makes it buildable and part of :func:`registry_family` (every registered kind); it never enters the
paper's family (:data:`models.kinds.family.PAPER_FAMILY`), so the paper's boxes never change.

Order: door, slide and wheel (the paper's), then the other kind modules by module name. A kind's integer
code in :func:`registry_family` is its index in that order; deep-agent checkpoints record the kind list
they were built for and refuse another.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Iterable
from pathlib import Path

from puzzlebox.models.errors import ModelsError, UnknownKindError
from puzzlebox.models.kinds.door import KIND as DOOR_KIND
from puzzlebox.models.kinds.family import PAPER_FAMILY, KindFamily, UnknownFamilyError
from puzzlebox.models.kinds.kind import Kind
from puzzlebox.models.kinds.slide import KIND as SLIDE_KIND
from puzzlebox.models.kinds.template import KindTemplate
from puzzlebox.models.kinds.wheel import KIND as WHEEL_KIND

_NOT_KINDS = frozenset({"family", "kind", "parts", "registry", "template"})
"""Modules of this package that hold no kind."""


class DuplicateKindError(ModelsError, ValueError):
    """A kind registered under a name that is already taken."""

    def __init__(self, kind: str, registered: Iterable[str]) -> None:
        self.kind = kind
        self.registered = tuple(sorted(registered))
        super().__init__(
            f"kind {kind!r} is already registered; registered kinds: {list(self.registered)}. "
            "A kind is registered once: give the new kind its own name"
        )


class KindRegistry:
    """Kinds by name; a name is registered once and never replaced."""

    def __init__(self, kinds: Iterable[Kind] = ()) -> None:
        self._kinds: dict[str, Kind] = {}
        for kind in kinds:
            self.register(kind)

    def register(self, kind: Kind) -> Kind:
        """Add ``kind`` under its name; :class:`DuplicateKindError` if the name is taken. Returns ``kind``."""
        if not isinstance(kind, Kind):
            raise TypeError(f"register a models.kinds.Kind, got {type(kind).__name__}")
        if kind.name in self._kinds:
            raise DuplicateKindError(kind.name, self._kinds)
        self._kinds[kind.name] = kind
        return kind

    def get(self, name: str) -> Kind:
        """The kind registered as ``name``; :class:`UnknownKindError` lists the registered ones."""
        try:
            return self._kinds[name]
        except KeyError:
            raise UnknownKindError(name, self._kinds) from None

    def names(self) -> tuple[str, ...]:
        """Registered kind names, in registration order."""
        return tuple(self._kinds)

    def copy(self) -> KindRegistry:
        """A new registry holding the same kinds (to extend without touching this one)."""
        return KindRegistry(self._kinds.values())

    def __contains__(self, name: object) -> bool:
        return name in self._kinds


PAPER_KINDS: tuple[Kind, ...] = (DOOR_KIND, SLIDE_KIND, WHEEL_KIND)
"""The paper's kinds, registered first (their codes in :func:`registry_family` are the paper's)."""


def _kind_modules() -> list[str]:
    """Names of this package's modules that may define a kind, sorted (the paper's excluded)."""
    paper = {k.name for k in PAPER_KINDS}
    here = [str(Path(__file__).parent)]  # this package's folder (not the package: it imports this module)
    return sorted(m.name for m in pkgutil.iter_modules(here) if m.name not in _NOT_KINDS | paper)


def _discover() -> tuple[Kind, ...]:
    found = []
    for module_name in _kind_modules():
        module = importlib.import_module(f"puzzlebox.models.kinds.{module_name}")
        kind = getattr(module, "KIND", None)
        if isinstance(kind, Kind):
            found.append(kind)
    return (*PAPER_KINDS, *found)


BUILTIN_KINDS: tuple[Kind, ...] = _discover()
"""The kinds this package defines, one module each: the paper's, then the others by module name."""

_REGISTRY = KindRegistry(BUILTIN_KINDS)
"""The process-wide registry the builders use."""


def register(kind: Kind) -> Kind:
    """Register ``kind`` in the process-wide registry (see :meth:`KindRegistry.register`)."""
    return _REGISTRY.register(kind)


def registered_kind(name: str) -> Kind:
    """The registered kind ``name`` (template, dynamics, colour, MJCF builder); :class:`UnknownKindError`
    lists the registered kinds."""
    return _REGISTRY.get(name)


def registered_kinds() -> tuple[str, ...]:
    """Names of every registered kind, in registration order."""
    return _REGISTRY.names()


def get_kind(name: str) -> KindTemplate:
    """The geometry template of a registered kind; :class:`UnknownKindError` lists the registered kinds."""
    return _REGISTRY.get(name).template


def registry_family(registry: KindRegistry | None = None) -> KindFamily:
    """The family of every registered kind (``registry`` or the process-wide one): kinds in registration
    order, a pair allowed to lock each other when either kind names the other in its ``neighbours``."""
    registry = registry or _REGISTRY
    names = registry.names()
    pairs = {
        frozenset({kind.name, other})
        for kind in (registry.get(n) for n in names)
        for other in kind.neighbours
        if other in registry
    }
    return KindFamily(name="registry", kinds=names, neighbours=frozenset(pairs))


def family_named(name: str) -> KindFamily:
    """A puzzle-box kind family by name: ``paper`` (:data:`~models.kinds.family.PAPER_FAMILY`) or ``all``
    (:func:`registry_family`); an unknown name lists both."""
    families = {"paper": PAPER_FAMILY, "all": registry_family()}
    try:
        return families[name]
    except KeyError:
        raise UnknownFamilyError(name, families) from None
