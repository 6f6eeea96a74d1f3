"""A registered component kind: everything ``models`` needs to build one (template, joint dynamics,
colour, MJCF parts), bundled so that the builders ask the kind and hold no per-kind branches."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from models.kinds.template import KindTemplate

if TYPE_CHECKING:  # dm_control only for the type: importing models.kinds stays free of MuJoCo
    from dm_control import mjcf


@dataclass(frozen=True)
class JointDynamics:
    """Passive joint properties of a kind (realistic for small plastic parts on metal pins/rails)."""

    damping: float
    """Viscous damping [N·m·s/rad or N·s/m]."""
    frictionloss: float
    """Dry friction [N·m or N]: keeps a released component where the robot left it."""
    armature: float = 1e-4
    """Reflected inertia [kg·m² or kg], for numerical stability of light parts."""


PartBuilder = Callable[["mjcf.Element", str], "mjcf.Element"]
"""``build(body, name) -> joint``: adds a kind's parts (plate or disc, handle, joint) to the component
body ``body`` (whose frame is the component frame), names them ``<name>:...``, returns the joint."""


@dataclass(frozen=True)
class Kind:
    """One component kind as the registry holds it (:mod:`models.kinds.registry`)."""

    template: KindTemplate
    """Geometry: joint, travel, handle and footprint in the component frame."""
    dynamics: JointDynamics
    """Passive dynamics of the kind's joint."""
    colour: tuple[float, float, float, float]
    """RGBA [0-1] of the kind's plate or disc."""
    build: PartBuilder
    """Adds the kind's MJCF parts to a component body; see :data:`PartBuilder`."""
    glyph: str
    """Matplotlib colour of the kind in plots (a spec's top view)."""
    sweep_effort: float
    """Largest effort the twin's ghost-hand sweep applies to open it [N·m or N]: enough to beat friction and
    lift a door, far below what would tear a latch (DESIGN.md: latches held against 100-245 N of robot pull)."""

    @property
    def name(self) -> str:
        """Kind name as written in specs (the template's)."""
        return self.template.name
