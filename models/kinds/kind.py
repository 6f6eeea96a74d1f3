"""A registered component kind: everything ``models`` needs to build one (template, joint dynamics,
colour, MJCF parts), bundled so that the builders ask the kind and hold no per-kind branches."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from puzzlebox.models.kinds.template import KindTemplate

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


@dataclass(frozen=True)
class Handling:
    """How the robot grasps and moves a kind, and how its marker shows that it moved (the skills read this;
    they hold no kind names)."""

    grasp: Literal["across_motion", "along_axis"] = "across_motion"
    """How the fingers close on the handle: ``across_motion``, along the handle's direction of motion at the
    start (the pads push it: slides, wheels, drawers); ``along_axis``, along the hinge axis, so the handle
    pivots between the pads like a pin as the part turns and the gripper need not tilt with it (doors, levers)."""
    verdict: Literal["left_pose", "arc"] = "left_pose"
    """How a marker seen after a try tells that the part moved: ``left_pose``, it left its closed planar pose
    (moved ``skills.robot_world.MOVED_DISTANCE`` or turned ``MOVED_ANGLE``); ``arc``, the marker centre's turn
    about the hinge as a fraction of the travel (a door's marker rises with its flap, a lever's drops)."""
    read_close_up: bool = False
    """Whether a try's outcome is always read from the wrist camera close up, not from the overview: a part
    whose marker moves too little for the overview to tell (a lever's 12 mm: the overview's depth along its
    line of sight is off by 5-11 mm under a realistic calibration)."""
    swings_up: bool = False
    """Opens by swinging its plate up out of the lid plane (a door): pushed where a pinch cannot hold it,
    carried past its travel into its end stop, may stand open over its neighbours, and hides its marker when
    open (the skills' door rules: :mod:`skills.door_push`, :mod:`skills.door_clearance`)."""
    yields_across: bool = False
    """Whether the hand's path yields across itself to the load there as it moves the part (only the load along
    the motion tells a latch): a hinge turned about an axis perceived a little off drags its handle across the
    true arc, which the part resists without moving — a free door 57 N, 39 N yielding; free wheels under an
    uncalibrated camera 30-46 N, 23 N yielding. Slides and drawers hold their handle on a straight line."""
    axis_yield: float = 1.0
    """The share of the load along the hinge axis that the path yields to [-] (1: all of it, as across the motion). A
    wheel's knob stands on a vertical axis and is held in the pads by their friction along it: yielding to all of that
    load set the hand bouncing up and down on the knob (+-20 N at ~7 Hz against the F/T filter's lag; 49 N true on a
    wheel held part-way by its lock), yielding to none of it left a knob gripped a couple of millimetres off in height
    pressing on the hand (42 N true on a free wheel without a calibration file). A wheel yields to 0.3 of it: 34 N and
    24 N on those two trials."""


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
    neighbours: tuple[str, ...] = ()
    """Kinds a component of this kind may lock or be locked by, in a family that holds both (the relation is
    symmetric: a pair is allowed when either kind names the other). The paper's family pins its own pairs."""
    handling: Handling = Handling()
    """How the robot grasps and moves it and reads its marker (see :class:`Handling`)."""

    @property
    def name(self) -> str:
        """Kind name as written in specs (the template's)."""
        return self.template.name
