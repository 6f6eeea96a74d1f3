"""Exceptions of the `models` package.

Every error raised on purpose by `models` derives from :class:`ModelsError`, so callers can catch the
whole family at once; each message names what was wrong and what exists instead.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


class ModelsError(Exception):
    """Base class of every error raised by the `models` package."""


@dataclass(frozen=True)
class SpecProblem:
    """One problem found in a puzzle spec.

    Attributes:
        where: the field or component concerned, e.g. ``components[2].kind`` or ``component 'door-1'``.
        message: what is wrong, in words a user can act on.
    """

    where: str
    message: str

    def __str__(self) -> str:
        return f"{self.where}: {self.message}"


class SpecError(ModelsError):
    """A puzzle spec is invalid; :attr:`problems` lists every problem found, not only the first."""

    def __init__(self, problems: Iterable[SpecProblem], source: str | None = None) -> None:
        self.problems: tuple[SpecProblem, ...] = tuple(problems)
        self.source = source
        head = f"invalid puzzle spec{f' {source}' if source else ''}"
        lines = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"{head} ({len(self.problems)} problem(s)):\n{lines}")


class UnknownKindError(ModelsError, KeyError):
    """A component kind that no template describes."""

    def __init__(self, kind: str, available: Iterable[str], message: str | None = None) -> None:
        self.kind = kind
        self.available = tuple(sorted(available))
        super().__init__(message or f"unknown component kind {kind!r}. Available kinds: {list(self.available)}")

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


class GeneratorError(ModelsError, ValueError):
    """Generator parameters that cannot produce a valid puzzle (e.g. a forbidden kind neighbourhood)."""


class ReachabilityUndecided(ModelsError):
    """The state space is too large to decide by exhaustive search within the configured budget."""
