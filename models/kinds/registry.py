"""The kind registry: every component kind ``models`` can build, by name.

A kind is registered once, as a :class:`~models.kinds.kind.Kind`; builders ask the registry
(:func:`registered_kind`) and hold no per-kind branches. Registering a kind makes it buildable; it
does not add it to any family (:mod:`models.kinds.family`), so the paper's boxes never change.
"""

from __future__ import annotations

from collections.abc import Iterable

from models.errors import ModelsError, UnknownKindError
from models.kinds import door, slide, wheel
from models.kinds.kind import Kind
from models.kinds.template import KindTemplate


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


BUILTIN_KINDS: tuple[Kind, ...] = (door.KIND, slide.KIND, wheel.KIND)
"""The kinds this package defines, one module each."""

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
