"""One-part boxes: a single free component of one kind, open it to solve the box (the low-level manipulation
environment's default, ``puzzlebox/BoxManipulation-v0``, and the first rung of a curriculum).

The component stands at the lid centre with its +x along the lid length (a slide then opens away from the
robot at the default box pose); no lock rule holds it; the goal is that component open (state 1). The lid is
sized to the part as the chain generator sizes it, and the box stands where the robot reaches the handle.
"""

from __future__ import annotations

from puzzlebox.models.errors import GeneratorError
from puzzlebox.models.generator.chain import BoxConfig, assemble, fit_to_reach
from puzzlebox.models.generator.layout import Layout
from puzzlebox.models.kinds import registered_kinds
from puzzlebox.models.spec import PuzzleSpec


def single_part(kind: str = "slide", box: BoxConfig | None = None, name: str | None = None) -> PuzzleSpec:
    """A box of one free component of ``kind`` (see the module docstring); a pure function of its arguments.

    Args:
        kind: a registered kind (``slide``, ``wheel``, ``door``...).
        box: the box; default :class:`BoxConfig` (at ``(0.45, 0, 0)`` [m, m, rad], lid sized to the part).
        name: spec name; default ``single-<kind>``.

    Raises:
        GeneratorError: an unknown kind (the message lists the registered ones), or a box pose from which no
            reachable pose is found.
    """
    if kind not in registered_kinds():
        raise GeneratorError(f"unknown kind {kind!r}; known kinds: {sorted(registered_kinds())}")
    box = box or BoxConfig()
    layout = Layout(box.layout)
    layout.place_first(kind)
    spec = fit_to_reach(assemble(name or f"single-{kind}", [kind], layout, [], 0, box), box)
    if spec is None:
        raise GeneratorError(f"no box pose puts the handle of a single {kind!r} within the robot's reach")
    return spec


__all__ = ["single_part"]
