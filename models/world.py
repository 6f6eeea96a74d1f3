"""The ``World`` protocol: the only thing an agent ever talks to.

The symbolic environment is one ``World``; the twin behind perception and skills is another; the agent
cannot tell which (DESIGN.md, "Layers"). It lives in ``models`` so that ``learning`` and ``skills``
both use it without knowing each other.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from puzzlebox.models.observation import SceneObservation
from puzzlebox.models.try_outcome import TryResult


@runtime_checkable
class World(Protocol):
    """A puzzle the agent can look at and act on."""

    def observe(self) -> SceneObservation:
        """The components' kinds, poses and states, in this episode's (shuffled) order."""
        ...

    def try_toggle(self, index: int) -> TryResult:
        """Try to move component ``index`` of the observation to its other state: ``moved``,
        ``blocked`` (felt held: evidence of a lock) or ``failed`` (no proper try: no evidence)."""
        ...
