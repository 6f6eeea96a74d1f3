"""Manipulation primitives: toggle a component with the arm, feeling through the wrist F/T sensor
whether it was latched.

A toggle approaches the handle from above, descends, closes the gripper, drives the grasp point
along the perceived joint (arc for hinges, line for slides) towards the other state, then releases
and retreats. A door whose handle the pads could not hold is then pushed, in the same try
(:mod:`skills.door_push`; ``door_push``): a door's handle moves along its own post, so pinching it moves the
door by pad friction alone, which a weak grip does not give (harsh profile: 12 of 60 trials ended with the
handle slipping out). A pushed door opens under the inner face of a finger pad pressed on the back of its
handle, and closes under the pads' edges pressed on its plate; doors are always shut that way
(``push.close_by_push``). Beside a door that may stand open over the part (``cautious``), descents are slow
and stop at a light touch (:mod:`skills.door_clearance`); every other descent runs its last ``touch_height``
slowly under that light touch, where fingers aimed beside a handle (a wrong hand-eye calibration) land on it.

Motion is differential IK on the robot-only model at a 10 ms control tick, targets sent to the position
servos. The wrist wrench is read every tick and filtered (a running median over
``force_filter_samples`` ticks, so no single noisy sample decides anything). The sensor's noise is measured
as the arm comes to rest above each part: a noisy sensor is tared on more readings (``tare_noise``), its median
is longer (``filtered_noise``), and every motion in contact is slowed by the same ratio (:attr:`Toggler.slowdown`),
so that a force rising against a stop builds no more during the longer median's delay. While actuating, the
filtered force — rotated into the base frame, tared with the fingers open — is projected on the
handle's direction of motion: if the force opposing the motion exceeds ``blocked_force`` while the
measured progress is below ``blocked_progress``, the component is latched: the arm backs off to where
it started and lets go (DESIGN.md: this rule made no error in 36 randomized attempts and stopped every
latched attempt within 0.13-1.2 s; without a stop the grasp is torn off at 100-300 N). A handle pressed down
along its own post (a lever), which the pads hold by friction alone, is held once the opposing force exceeds the
lighter ``press_force``, at any progress short of ``moved_fraction``. The start of the
travel, where latches and sticky parts are met, is driven at ``breakaway_pace`` of the rest's pace, and a
door's or a wheel's path yields across itself to the load there (``comply_gain``, ``Handling.yields_across``): only
the load along the motion tells a latch, and a path planned from a slightly wrong hinge otherwise drags the handle
across its true arc (57 N on a free door at one placement, 39 N yielding). A closed grasp yields across the
fingers' closing axis too before it pulls (:meth:`Toggler._close_slowly`).

Whatever the motion (approach, descent, actuation, retreat), a filtered force above ``force_limit``
stops it at once: the gripper opens and the arm withdraws, and the try ends ``failed: force limit``
— a real arm's collision detection does the same. A handle that leaves the fingers during the motion
(the gripper closes past the handle's width) ends the try ``failed`` too: a slip is not a move.

Outcomes are ``moved``, ``blocked`` or ``failed`` (with a reason); IK failures, empty grasps, slips and
the force limit are typed errors underneath and reported as ``failed``.
"""

from __future__ import annotations

import collections
import collections.abc
import functools
import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from puzzlebox.models.cell_config import CellConfig
from puzzlebox.models.robot import Robot
from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.door_push import DoorPushConfig, DoorPushing
from puzzlebox.skills.errors import ForceLimitExceeded, GraspFailure, IKFailure, SlipDetected
from puzzlebox.skills.joint_model import JointModel
from puzzlebox.skills.kinematics import ArmKinematics, top_down
from puzzlebox.skills.pacing import Pacing
from puzzlebox.skills.toggle_result import HELD_PART_WAY, LATCHED, ToggleResult

SLIPPED_OFF = LATCHED[Cause.LOCKED_SLIPPED_OFF]
MAX_HEAD_START = 0.5
"""Largest :attr:`Toggler.head_start` believed [-]: a part seen further along is not where its state says."""
INCOMPLETE_TRAVEL = "IncompleteTravel"
"""Reason prefix of a motion that ran its course short of ``moved_fraction`` (no latch read)."""
STOPPED = "motion stopped"
"""End of the reason of a motion the force guard stopped: ``... while <phase>, motion stopped``."""
STOPPED_DESCENDING = f"while descending, {STOPPED}"
"""End of the reason of a try the force guard stopped on the way down onto the handle."""
PADS_LOST_HOLD = frozenset({Cause.SLIPPED, Cause.GRASP_EMPTY, Cause.LOCKED_SLIPPED_OFF})
"""Causes of a pinch that ended for want of a hold on the handle (it slipped out, the grasp closed on nothing,
or the part held until the pads slid off: a latch, or a door heavier than the grip holds). A door is then
pushed, and the push's verdict stands."""


@dataclass(frozen=True)
class PrimitiveConfig:
    """Timing and thresholds of a toggle."""

    tick: float = 0.01
    """Control period [s]."""
    ik_iterations_per_tick: int = 2
    pregrasp_closure: float = 0.6
    """Gripper closure while descending onto a handle: open just enough to clear the 12 mm post, so the
    fingers stay over the part and do not land on a neighbour 1.5 cm away (fully open they span ~8 cm)."""
    approach_height: float = 0.08
    """Pre-grasp height above the grasp point [m]."""
    approach_time: float = 1.5
    descend_time: float = 2.0
    """Time of the 8 cm descent onto a handle [s]: slow enough (peak 6 cm/s) that a part standing in
    the way (a door left leaning over its neighbour) is met softly and the force guard stops the arm
    near its limit; at 1 s the impact put up to 270 N of true force on the wrist."""
    touch_height: float = 0.018
    """Last part of a descent that is made slowly and stopped at a light touch (``cautious_contact_force``) [m]:
    fingers aimed beside a handle land on its top 12.6-12.9 mm above the grasp point (``GRASP_DEPTH``), on a
    neighbour's at about the same height. Met at the ~4.5 cm/s of the normal descent there, the impact alone put
    112 N on the wrist in one tick, and the servos went on pressing with 55-70 N while the 40 ms late, filtered
    reading caught up with the 60 N guard (wrist camera's hand-eye pose 20 mm off; issue 37)."""
    touch_speed: float = 0.006
    """TCP speed over ``touch_height`` [m/s] (slower by :attr:`Toggler.slowdown`): the impact of the touch, one
    tick's spike, grows with it (fingers on a handle's top: 112 N at 4.5 cm/s, 22-45 N at 0.5-1.1 cm/s), and so
    does the servos' tracking lag they press on with while the filtered reading catches up."""
    cautious_descend_time: float = 6.5
    """Time of the descent beside a door that may stand open over it (``toggle(cautious=True)``) [s]: met at
    the 6 cm/s peak of a normal descent, a flap's edge put 80 N on the wrist at the first touch; at a third of
    that speed 20-25 N (harsh profile). Made at a constant speed (1.2 cm/s over 8 cm): in 5 s with a smooth start
    and stop, its 2.4 cm/s peak met an open door's plate 4 cm above a slide's grasp point, and the pad bounced on it
    for 11 ticks (47 N true) while the filtered reading, a median that needs most of its window in contact, read
    3 N (paper-test-2 seed 100, harsh); at a constant 1.6 cm/s a knuckle met a plate with 42 N true (hard chain8,
    harsh)."""
    cautious_contact_force: float = 15.0
    """Filtered force that stops a cautious descent, and the last ``touch_height`` of every descent [N]: nothing
    should touch the fingers on the way down, and
    the servos keep pushing into what they met by ~1 N per 10 ms tick while the 30 ms late, filtered reading
    catches up."""
    cautious_noise_margin: float = 4.0
    """A cautious descent stops at ``cautious_contact_force`` or this many times the F/T force noise, whichever
    is larger: the noise is the rms per-axis spread of the raw force over the ``noise_samples`` ticks before
    the descent's tare (the arm coming to rest above the part). At 7 N of noise a fixed 15 N stopped 2 of 3
    sweep trials' descents with nothing in the way."""
    noise_samples: int = 30
    """Raw force samples kept for the noise estimate [ticks]."""
    close_time: float = 0.6
    grasp_centre_force: float = 20.0
    """Filtered load along the fingers' closing axis above which the wrist yields to it while the gripper closes
    [N] (at ``comply_gain`` per newton above it, or above ``comply_noise_margin`` times the F/T noise, if larger):
    a finger that meets a fixed post first pushes it with the whole grip while the stiff arm holds the hand where it
    was aimed. Aimed beside a handle (the wrist camera's hand-eye pose 2 deg or 20 mm off), the closing grip put
    53-68 N true on the wrist and the pads pinched the handle's edge; yielding, the hand is centred on the post.
    Centred grasps load the wrist along that axis with less (a free part's pad drags it along)."""
    grasp_centre_limit: float = 0.02
    """Farthest the wrist yields along the closing axis while the gripper closes [m]: about the pre-grasp opening."""
    close_speed: float = 0.4
    """Rate at which the gripper's commanded closure ramps up while closing on a handle [1/s]: the
    servo alone snaps the fingers shut at ~2/s, and pads meeting a post at that speed put a 30 ms,
    60 N impact on the wrist."""
    actuate_time: float = 2.5
    breakaway_fraction: float = 0.3
    """Start of the travel commanded at ``breakaway_pace`` (fraction of the travel), then a ramp up to the full pace
    (``skills.pacing``): where a lock or a sticky part is met, so that it is met slowly — a one-way latch within
    ``blocked_progress``, an interlock's rod once the held part has left its closed band (27-45 % of its travel,
    mostly 27-35 %: ``models.lock_mechanisms``; the ramp is still slow there). Met at full pace, a door held part-way
    at 32 % put 91 N on the wrist before the stall was read; at this pace 31 N, and a try takes ~7 % longer. Over
    half the travel, a free door's pinch then met its end stop with 51 N true (hard-random8-s5004 seed 3636; 47 N at
    this span, 40 N at the old 10 %)."""
    breakaway_pace: float = 0.4
    """Pace of the start of the travel, as a fraction of the pace of the rest [-]: a part that sticks after
    moving 2 % of its travel stops the grasp dead, and at full pace (a door handle at ~4 cm/s) the arm drove
    on into it with 75 N of true force before the 20-30 ms late, filtered reading reached the force guard."""
    comply_gain: float = 0.002
    """Speed at which a door's actuation path yields across itself to the load there, per newton [m/(N s)]: with
    the ~2 N/mm of a pinched handle, a time constant of ~0.25 s, ten times the F/T reading's delay."""
    comply_deadband: float = 5.0
    """Load across the path below which the path does not yield [N] (the noise of a filtered reading)..."""
    comply_noise_margin: float = 2.0
    """... or this many times the F/T force noise measured as the arm came to rest above the part, if larger: at
    15 N of noise a fixed 5 N let the noise walk the path 3 cm off the arc (68 N on the wrist)."""
    comply_limit: float = 0.03
    """Farthest the path yields across itself [m]."""
    comply_return_time: float = 0.25
    """Time constant of a door path's return to the planned arc past the end of the travel [s]: yielding on into
    the end stop hid the load that tells a door is open (a top-up push then took 17 s more), and an offset kept
    there met the stop with 71 N (F/T delayed 30 ms)."""
    release_time: float = 0.4
    retreat_time: float = 0.8
    lift_contact_force: float = 20.0
    """The lift off a part that was let go stops at this filtered force (or ``lift_noise_margin`` times the
    filtered noise, if larger) [N]: nothing should touch an open gripper rising from a handle, and a slide
    opened under the handle of an open door (which stands past vertical over its neighbours) brought the pad
    up against it at the 60 N guard with 84 N true (paper-train-0, realistic)."""
    lift_noise_margin: float = 3.0
    """... or this many times the filtered F/T noise of the toggle, if larger: noise must not read as a touch."""
    lift_slow_height: float = 0.02
    """The first part of that lift runs slowly [m]: what stands over the pads is met within a centimetre or two
    of the handle (an open door's post 8 mm over a pad), and met at the lift's full pace (~15 cm/s) the wrist
    took 84 N true before the filtered reading passed even 20 N."""
    lift_slow_time: float = 1.0
    """... over this time [s] (2 cm/s, smooth start and stop)."""
    lift_sidestep: float = 0.03
    """How far the open gripper steps along its pads (parallel to the handle it straddles, which it then never
    pushes) to clear what stopped the lift [m]: a pad is 30 mm long, a post 12 mm wide."""
    gentle_release_speed: float = 0.4
    """Rate at which the gripper's commanded closure ramps open to let go of a handle [1/s], divided by
    :attr:`Toggler.slowdown`: the servo alone snaps the fingers open at ~2/s, and an inner knuckle swinging out
    under the plate of an open door (one the world did not count as standing over the part) met it with 38 N in
    one tick and 93 N before the late, filtered reading passed the guard (paper-test-2, harsh; 34 N ramped)."""
    base_radius: float = 0.22
    """A lift whose TCP stands closer than this to the vertical axis of the arm's base [m] first moves out to it,
    ``base_rise`` above where it let go: the arm folded over its own shoulder to reach there (a drawer pulled
    towards the base, the TCP 0.176 m from its axis), and straight up the gripper's knuckle met link 2 (224 N
    true) 6 cm up, with 1 cm of clearance where it let go; moved out first, never under 6 mm (robot model). An
    approach to above such a part comes in from it at ``base_rise`` (:meth:`Toggler._approach`)."""
    base_rise: float = 0.035
    """How far the gripper rises above where it let go before it moves out to ``base_radius`` [m]: clear of the
    35 mm post it straddled, which moving across would push; and the height above the grasp point from which a
    descent near the base begins."""
    lean_angle: float = math.radians(20.0)
    """Tilt of the gripper about its closing axis, its upper part leaning away from a door that may stand open
    over the part it grasps (``toggle(lean=...)``) [rad]: at its end stop a door's 35 mm post stands out
    horizontally ~7 cm above the lid, past its hinge line over the neighbour; upright, the gripper's knuckles
    met it 3 cm above the neighbouring slide's handle as the slide opened under it (61 N, every try: 5 of the
    9 training boxes have a slide there). Tilted 20 deg they pass ~1 cm further from it; the pads, turned about
    the axis they close along, still meet the handle's faces square."""
    lift_time: float = 0.8
    """Time to lift the TCP to ``transit_height`` before going to rest [s]."""
    rest_time: float = 1.5
    """Time to return to the rest posture after a toggle [s]: out of the overview camera's view, and
    every toggle starts from the same arm configuration."""
    transit_height: float = 0.35
    """TCP height of the waypoint of a move from afar (``Toggler.travel_to``) [m]: well above the 8 cm box
    and its 3.5 cm handles."""
    transit_xy: tuple[float, float] = (0.42, 0.0)
    """Where that waypoint is, in the base frame [m]: over the middle of the reachable workspace."""
    settle_time: float = 0.6
    """Extra time allowed at the end of a move for the servos to catch up [s]."""
    lead: float = 0.02
    """How far the commanded grasp point may run ahead of the measured one, along the path [m]: a
    pre-planned arc from a slightly wrong perceived hinge would otherwise pull the handle out of the
    fingers; 2 cm still pulls a latched part with more than ``blocked_force``."""
    push_force: float = 5.0
    """A part that ends without progress after being pulled with at least this force is latched [N]."""
    blocked_force: float = 20.0
    """Force opposing the motion that, with little progress, means a latch [N]."""
    blocked_progress: float = 0.10
    """Progress (fraction of the travel) below which a large opposing force means a latch."""
    blocked_magnitude: float = 35.0
    """Force magnitude (any direction) that, with little progress, also means a latch [N]: a latched wheel
    or a part pulled along a slightly wrong direction loads the grasp sideways more than along the path."""
    back_off_force: float = 35.0
    """The force guard's threshold while a held handle is taken back to where it was grasped [N]; above it the arm
    backs off along the load instead: a wheel pulled as a door (a misread kind) was dragged there with 49 N true."""
    stall_force: float = 20.0
    """Force opposing the motion that, past ``blocked_progress`` within the travel and with the part stalled
    (``stall_progress`` over ``stall_window``), means it is held part-way [N]: a lock's pins leave play (a part
    held open moves up to ~30 % of its travel before they meet), and a slide closed into it was driven on to the
    60 N guard (63 N true; its retry then descended onto the post it had left part-way: 65 N). Stopped there, the
    handle is taken back along its path to where it was grasped; one stalled past ``moved_fraction`` is at its
    stop, and pushed no further."""
    press_force: float = 10.0
    """Force opposing a handle pressed down along its own post (``press_angle``) that means it is held, whatever
    the progress short of ``moved_fraction`` [N]: the pads hold a post along its length by friction alone, and
    under the harsh grip they slid down a locked lever's post at 13 N (the lever still) until the fingers met its
    arm, where the load rose 4.5 N a tick to 56 N true before the stall was read; a free lever is pressed with
    ~5 N (harsh), and past ``moved_fraction`` more force is its end stop.
    The same for a handle pulled up its post (a lever lifted; a door swings up under a pinch of its own): a lever held
    open by its lock stopped after the lock's play while the realistic pads slid up its post at 15-19 N along the
    motion, never stalling (the hand kept rising), until they slid off its top, seen at 73-89 % and given up; a free
    lever is lifted with 3-4 N."""
    press_noise_margin: float = 3.0
    """... or this many times the filtered F/T noise of the toggle, if larger: noise must not read as a hold."""
    press_pace: float = 0.5
    """Pace of the actuation of a handle pressed along its post (``press_angle``), as a fraction of the usual [-]
    (``careful_pace`` is not compounded): the pads of the harsh grip slid down a locked lever's post with 6-9 N
    along the motion (a free lever is pressed with ~4 N: no force tells the slide under ``press_force``), 8 mm
    (40 % of the travel) until the fingers met the lever's arm, where the true load rose from 16 N by 12 N in the
    first tick and to 45 N in the five before the 30 ms late, filtered reading showed it; stopped, 46.5 N
    (hard-random8-s36014 seed 36100). That rise scales with the pace the arm meets the arm at:
    at half the pace, 6 N in the first tick and 34 N true at the most."""
    press_angle: float = math.radians(30.0)
    """Largest angle between the motion of a grasped handle and the gripper's approach axis (down, into the part)
    at which it is pressed along its post (``press_force``) [rad]: a lever's handle starts down at ~20 deg."""
    stall_progress: float = 0.01
    """Least progress (fraction of the travel) over ``stall_window`` of a part that has not stalled: a free part
    covers ~2 % in that time; a slide met by a pin crept 0.6 % in 0.15 s as the load rose 10 N a tick."""
    stall_window: float = 0.05
    """Time over which a stall is measured [s] (longer by :attr:`Toggler.slowdown` with the motions)."""
    door_overtravel: float = 0.15
    """How far past the far end of a door's travel the grasp point is driven (fraction of the travel), at half
    the pace of the arc: a handle pivoting between the pads lags the fingers by up to ~15 mm along an 85 deg
    door arc, which left doors at ~74 deg, leaning over their neighbours' handles; the joint's end stop takes
    the rest. Past the travel, a filtered force above ``overtravel_force`` stops the over-travel where the
    handle is. (Under the harsh grip the lag is a fifth of the fingers' turn, fingers at 98 deg leaving a
    door at 78: more over-travel met the end stop with 70 N jolts; a top-up push finishes those doors.)"""
    overtravel_comply: bool = True
    """Yield across the path in the over-travel too (:meth:`Toggler._yield_across`), until the end stop is felt
    (``end_stop_force``), then return to the planned arc: the planned arc's mismatch with the door's true arc grows
    past the travel (a door still rising, near upright), and held on the arc it loaded the grasp with ~32 N
    *across* the motion (2-5 N along it), on which the handle's stick-slip in the pads put one-tick spikes of
    45-48 N true (realistic: paper-test-2 seed 105, hard-chain8-s36004 seed 36100). Yielding,
    the same pinches peaked at 27 and 22 N with the doors in their stops; a door that reaches its stop without
    20 N felt is then topped up (``push.top_up``)."""
    end_stop_force: float = 20.0
    """Filtered force magnitude past the travel that tells a pinched door has reached its end stop [N] (a
    lagging handle pressed into it loads the grasp with 20-30 N, one that follows closely 47 N; weak pads
    dragging a door still short of it, 12-15 N): a door not felt there is pushed on (``push.top_up``)."""
    overtravel_force: float = 40.0
    """Filtered force magnitude that ends a door's over-travel [N]: a lagging handle pulled into its end stop
    loads the grasp with 20-30 N; a handle that follows the fingers closely is pushed towards the safety
    limit (47 N at 80 deg, then 60 N, with the box 0.34 m from the base)."""
    moved_fraction: float = 0.75
    """Progress that counts as reaching the other state (the twin's hysteresis threshold)."""
    empty_grasp_closure: float = 0.95
    """Gripper closure at or above which nothing is between the fingers."""
    slip_closure_rise: float = 0.012
    """Rise of the gripper closure within :attr:`slip_window` that means the handle left the fingers [-]:
    a lost handle lets the fingers close 0.02 within ~0.2 s (slowly at a reduced grip force, so
    :attr:`empty_grasp_closure` came seconds late), while a held one creeps steadily, 0.003 per 0.25 s at
    the harsh 10 N grip, up to 0.02 over a whole toggle (a rise over the grasp's closure misread that)."""
    slip_window: float = 0.25
    """Time over which the closure's rise is measured [s]."""
    force_filter_samples: int = 5
    """Ticks in the running median of the wrench (5 x 10 ms: a 50 ms window, short beside the 0.13 s
    it took the fastest latched attempt to build up force, long enough that no single sample decides)..."""
    filtered_noise: float = 4.0
    """... or more, up to ``force_filter_max_samples``, so that the median's noise stays under this [N per axis]
    for the F/T force noise measured as the arm came to rest above the part: a median of n samples spreads
    sqrt(pi/2)/sqrt(n) times the noise. Longer from 7.2 N of noise on (at 15 N: 23 ticks); with 5 ticks at 15 N
    every toggle's filtered force passed ``blocked_force`` by noise alone and read latched (sweep: 0 of 3
    solved)."""
    tare_noise: float = 1.0
    """Largest error of the F/T tare wanted [N per axis]: the tare averages ten readings, or as many as bring the
    noise measured above the part under this (up to ``tare_max_samples``): at 15 N of noise ten readings left a
    5 N bias per axis, which on top of a grasp's 21 N sideways load read a free wheel latched."""
    tare_max_samples: int = 400
    """Most readings a tare averages (a real sensor's bias reset samples at ~1 kHz: 0.4 s)."""
    force_filter_max_samples: int = 30
    """Longest running median of the wrench [ticks]. A longer median is later by half its growth, so every
    motion in contact (descent, closing on the handle, actuation, pushes) is slowed by the same ratio
    (:attr:`Toggler.slowdown`): a force rising against a stop then builds no more during the delay than it
    does with the 5-tick median. At 15 N of noise a 23-tick median at full pace met a door shut on its lid
    with 100 N (random agent)."""
    door_push: bool = True
    """Push a door (:mod:`skills.door_push`) when pinching its handle failed for want of a hold
    (:data:`PADS_LOST_HOLD`): a pinched post moves the door by pad friction alone, which a weak grip does not
    give. Not first: with grippy pads (mu above ~0.2) the pad's friction on the pushed face can lock the push
    (realistic profile, pushing first: 98.3 % solved in 5.57 actions against 100 % in 5.18)."""
    relieve_load: float = 3.0
    """Filtered force above which a stopped arm backs off along it before letting go [N]."""
    relieve_distance: float = 0.005
    """How far the arm backs off along the load after a force stop, before letting go [m]."""
    push: DoorPushConfig = field(default_factory=DoorPushConfig)
    """How doors are pushed (:mod:`skills.door_push`)."""
    careful_pace: float = 0.5
    """Pace of every motion in contact (descent, closing, actuation, pushes) of a careful toggle
    (``toggle(careful=True)``: a part tried as a kind it was not told, whose path may meet a post or a stop where
    none was expected), as a fraction of the usual [-]: a force rising against it builds half as fast during the
    filtered reading's delay."""
    force_limit: float = 60.0
    """Safety limit on the filtered wrist force, whatever the motion [N]. A toggle needs 8-9 N, a latch is
    felt at 20 N (``blocked_force``); UFACTORY publishes no newton threshold for its collision detection
    (REALITY_NOTES.md §1), so this sits where a latched pull is already decided and far below the
    100-300 N that tore grasps off, and below the F/T range (150 N)."""

    @classmethod
    def for_cell(cls, cell: CellConfig, **overrides: Any) -> PrimitiveConfig:
        """The primitives of a cell: its force limit and blocked threshold [N] (the rest as given, or the
        defaults, which are the twin's)."""
        return cls(**{"force_limit": cell.force_limit, "blocked_force": cell.blocked_force, **overrides})

    def __post_init__(self) -> None:
        if not 1 <= self.force_filter_samples <= self.force_filter_max_samples:
            raise ValueError(
                "need 1 <= force_filter_samples <= force_filter_max_samples [ticks], got "
                f"{self.force_filter_samples}, {self.force_filter_max_samples}"
            )
        if self.filtered_noise <= 0.0 or self.tare_noise <= 0.0:
            raise ValueError(
                f"filtered_noise and tare_noise must be > 0 [N], got {self.filtered_noise}, {self.tare_noise}"
            )
        if self.tare_max_samples < TARE_SAMPLES:
            raise ValueError(f"tare_max_samples must be >= {TARE_SAMPLES}, got {self.tare_max_samples}")
        if not 0.0 < self.blocked_force < self.blocked_magnitude < self.force_limit:
            raise ValueError(
                "need 0 < blocked_force < blocked_magnitude < force_limit [N], got "
                f"{self.blocked_force}, {self.blocked_magnitude}, {self.force_limit}"
            )
        if not (0.0 < self.breakaway_pace <= 1.0 and 0.0 <= self.breakaway_fraction < 1.0):
            raise ValueError(
                "need 0 < breakaway_pace <= 1 and 0 <= breakaway_fraction < 1, got "
                f"{self.breakaway_pace}, {self.breakaway_fraction}"
            )
        if min(self.comply_gain, self.comply_deadband, self.comply_noise_margin, self.comply_limit) < 0.0:
            raise ValueError(
                "comply_gain [m/(N s)], comply_deadband [N], comply_noise_margin and comply_limit [m] must be >= 0,"
                f" got {self.comply_gain}, {self.comply_deadband}, {self.comply_noise_margin}, {self.comply_limit}"
            )
        if self.grasp_centre_force <= 0.0 or self.grasp_centre_limit < 0.0:
            raise ValueError(
                "need grasp_centre_force > 0 [N] and grasp_centre_limit >= 0 [m], got "
                f"{self.grasp_centre_force}, {self.grasp_centre_limit}"
            )
        if self.comply_return_time < self.tick:
            raise ValueError(f"comply_return_time must be >= tick [s], got {self.comply_return_time}")
        if not 0.0 < self.lift_contact_force < self.force_limit or min(self.lift_noise_margin, self.lift_sidestep) < 0:
            raise ValueError(
                "need 0 < lift_contact_force < force_limit [N] and lift_noise_margin, lift_sidestep [m] >= 0, got "
                f"{self.lift_contact_force}, {self.force_limit}, {self.lift_noise_margin}, {self.lift_sidestep}"
            )
        if self.lift_slow_height < 0.0 or self.lift_slow_time < self.tick:
            raise ValueError(
                f"need lift_slow_height >= 0 [m] and lift_slow_time >= tick [s], got {self.lift_slow_height}, "
                f"{self.lift_slow_time}"
            )
        if self.gentle_release_speed <= 0.0 or min(self.base_radius, self.base_rise) < 0.0:
            raise ValueError(
                "need gentle_release_speed > 0 [1/s] and base_radius, base_rise >= 0 [m], got "
                f"{self.gentle_release_speed}, {self.base_radius}, {self.base_rise}"
            )
        if not (0.0 < self.stall_force < self.force_limit and self.stall_progress >= 0.0 and self.stall_window > 0.0):
            raise ValueError(
                "need 0 < stall_force < force_limit [N], stall_progress >= 0 and stall_window > 0 [s], got "
                f"{self.stall_force}, {self.stall_progress}, {self.stall_window}"
            )
        if not self.blocked_force < self.back_off_force <= self.force_limit:
            raise ValueError(
                "need blocked_force < back_off_force <= force_limit [N], got "
                f"{self.blocked_force}, {self.back_off_force}, {self.force_limit}"
            )
        if self.press_force <= 0.0 or self.press_noise_margin < 0.0 or not 0.0 <= self.press_angle <= math.pi / 2:
            raise ValueError(
                "need press_force > 0 [N], press_noise_margin >= 0 and 0 <= press_angle <= pi/2 [rad], got "
                f"{self.press_force}, {self.press_noise_margin}, {self.press_angle}"
            )
        if not (0.0 < self.careful_pace <= 1.0 and 0.0 < self.press_pace <= 1.0):
            raise ValueError(
                f"need 0 < careful_pace <= 1 and 0 < press_pace <= 1, got {self.careful_pace}, {self.press_pace}"
            )
        if not 0.0 < self.touch_height < self.approach_height or self.touch_speed <= 0.0:
            raise ValueError(
                "need 0 < touch_height < approach_height [m] and touch_speed > 0 [m/s], got "
                f"{self.touch_height}, {self.approach_height}, {self.touch_speed}"
            )
        if not 0.0 < self.cautious_contact_force < self.force_limit:
            raise ValueError(
                "need 0 < cautious_contact_force < force_limit [N], got "
                f"{self.cautious_contact_force}, {self.force_limit}"
            )


TARE_SAMPLES = 10
"""Readings a tare averages at low noise (the :class:`models.robot.Robot` protocol's default)."""

_MEDIAN_SPREAD = math.sqrt(math.pi / 2)
"""Spread of the median of n samples of a Gaussian, times sqrt(n), over the samples' spread (large n)."""


def _out_to_radius(pose: np.ndarray, radius: float) -> None:
    """Move ``pose`` (4x4, base frame; in place) out horizontally from the base's vertical axis to ``radius`` [m] if
    it stands closer (and not on the axis itself)."""
    now = math.hypot(pose[0, 3], pose[1, 3])
    if 1e-6 <= now < radius:
        pose[:2, 3] *= radius / now


def _median_rows(rows: collections.abc.Sequence[np.ndarray]) -> np.ndarray:
    """``np.median(rows, axis=0)``, bit for bit, at a fifth of its cost on a few short rows (it runs every tick)."""
    ordered = np.sort(np.array(rows), axis=0)
    mid = len(ordered) // 2
    return ordered[mid] if len(ordered) % 2 else (ordered[mid - 1] + ordered[mid]) / 2


class Toggler(DoorPushing):
    """Runs toggle primitives on a robot interface (``twin.robot_interface.RobotInterface`` or a real one)."""

    config: PrimitiveConfig

    def __init__(
        self, robot: Robot, config: PrimitiveConfig | None = None, kinematics: ArmKinematics | None = None
    ) -> None:
        self.robot = robot
        self.config = config or PrimitiveConfig()
        self.ik = kinematics or ArmKinematics()
        self.rest_posture = robot.joint_positions()  # where the robot was handed over: out of view
        self._joint_limits = tuple(robot.joint_limits().T)  # (low, high) [rad]: an arm's servo ranges are fixed
        self._force_window: collections.deque[np.ndarray] = collections.deque(maxlen=self.config.force_filter_samples)
        self._raw_forces: collections.deque[np.ndarray] = collections.deque(maxlen=self.config.noise_samples)
        """The last raw wrist forces in the base frame [N]: how noisy the sensor is (:attr:`rest_noise`)."""
        self.force_in_base = np.zeros(3)
        """The filtered wrist force after the last tick, in the base frame [N]."""
        self.phase = "moving"
        """What the arm is doing (for the reasons of failed tries)."""
        self.rest_noise = 0.0
        """F/T force noise measured as the arm came to rest above the part of the toggle in progress [N]."""
        self.progress = 0.0
        """Measured progress of the current toggle's actuation so far (kept when a stop ends it)."""
        c = self.config
        self._closures: collections.deque[float] = collections.deque(maxlen=max(2, round(c.slip_window / c.tick) + 1))
        """Gripper closures over the last ``slip_window`` of the toggle in progress (the slip test)."""
        self.peak_force = 0.0
        """Largest filtered force magnitude since the last :meth:`reset_force_watch` [N]."""
        self.guard = True
        """Stop motions at ``force_limit`` (off only while withdrawing from a stop)."""
        self.limit = self.config.force_limit
        """The force guard's threshold now [N]: ``force_limit``, or ``cautious_contact_force`` in a cautious descent."""
        self.cautious = False
        """Whether the toggle in progress descends cautiously (``toggle(cautious=True)``)."""
        self.careful = False
        """Whether the toggle in progress moves in contact at ``careful_pace`` (``toggle(careful=True)``)."""
        self.slowdown = 1.0
        """How much slower than configured the motions in contact of the toggle in progress run [-]: the
        running median's length over ``force_filter_samples`` (1 below 7.2 N of F/T noise)."""
        self.head_start = 0.0
        """Fraction of the travel towards the other state a part stood at when the toggle in progress began
        (``toggle(stands_at=...)``), counted into the progress that tells it reached its stop: the fingers' progress
        counts from the perceived closed (or open) pose, and the handle of a lever left part-way is that much ahead
        of them (a lever rests up to ~20 % pressed once lifted, a try taken back leaves it at 30-45 %). Its stop
        was met with the fingers at 57-73 % and read ``held part-way``; taken back, the lever was tried again and
        again until the grasp closed on nothing."""
        self.lean: np.ndarray | None = None
        """Horizontal vector (base frame) along which the gripper leans over the part of the toggle in progress,
        by ``lean_angle`` times its length (``toggle(lean=...)``), or None: upright."""
        self._lean_drift = np.zeros(3)
        """Horizontal motion of the TCP per metre it rises along the approach axis of its last descent [m/m]
        (zero upright; set by :meth:`_descend_to`)."""

    # -- force -------------------------------------------------------------------------------------
    def reset_force_watch(self) -> None:
        """Forget the force history (after a tare: older samples have another zero)."""
        self._force_window.clear()
        self.peak_force = 0.0

    def _sense(self) -> None:
        """Read the wrench into the filter window (a running median, :attr:`force_in_base`) and enforce
        the safety limit."""
        raw = self.robot.ft_rotation_in_base() @ self.robot.wrench()[:3]
        self._force_window.append(raw)
        self._raw_forces.append(raw)
        self.force_in_base = _median_rows(self._force_window)
        magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
        self.peak_force = max(self.peak_force, magnitude)
        if self.guard and magnitude > self.limit:
            raise ForceLimitExceeded(magnitude, self.limit, self.phase)

    def force_noise(self) -> float:
        """The F/T force noise now: the rms over the axes of the raw force's spread over the last
        ``noise_samples`` ticks [N] (0 before there are 10)."""
        if len(self._raw_forces) < 10:
            return 0.0
        return float(np.sqrt(np.mean(np.var(np.array(self._raw_forces), axis=0))))

    def filter_samples(self, noise: float) -> int:
        """Ticks in the running median of the wrench for an F/T force noise ``noise`` [N, rms per axis]:
        ``force_filter_samples``, or as many as keep the median's noise under ``filtered_noise``."""
        c = self.config
        needed = math.ceil((_MEDIAN_SPREAD * noise / c.filtered_noise) ** 2)
        return max(c.force_filter_samples, min(needed, c.force_filter_max_samples))

    def filtered_noise_now(self) -> float:
        """The noise of the filtered force in the toggle in progress [N per axis]: the F/T force noise measured
        above the part through the running median of its length."""
        return _MEDIAN_SPREAD * self.rest_noise / math.sqrt(self._force_window.maxlen or 1)

    def tare_samples(self, noise: float) -> int:
        """Readings a tare averages for an F/T force noise ``noise`` [N, rms per axis]: ten, or as many as keep
        the tare's error under ``tare_noise``."""
        c = self.config
        return max(TARE_SAMPLES, min(math.ceil((noise / c.tare_noise) ** 2), c.tare_max_samples))

    def _clip(self, q: np.ndarray) -> np.ndarray:
        """``q`` within the servo ranges [rad] (``np.clip`` for finite ``q``, without its dispatch layers)."""
        low, high = self._joint_limits
        return np.minimum(np.maximum(q, low), high)

    def _wait_tick(self) -> None:
        self.robot.wait(self.config.tick)
        self._sense()

    # -- motion ------------------------------------------------------------------------------------
    def _tick(self, target: np.ndarray) -> tuple[float, float]:
        q, position_error, orientation_error = self.ik.step_towards(target, self.config.ik_iterations_per_tick)
        self.robot.command_joint_positions(self._clip(q))
        self._wait_tick()
        return position_error, orientation_error

    def move_to(self, target: np.ndarray, duration: float, smooth: bool = True) -> None:
        """Move the TCP to ``target`` (4x4) along a straight line and a slerp over ``duration`` [s], with a smooth
        start and stop, or at a constant speed (``smooth=False``: no faster than the mean anywhere)."""
        self.ik.set_joints(self.robot.joint_positions())
        start = self.ik.tcp_pose()
        slerp = Slerp([0.0, 1.0], Rotation.from_matrix([start[:3, :3], target[:3, :3]]))
        ticks = max(1, round(duration / self.config.tick))
        s = np.arange(1, ticks + 1) / ticks
        if smooth:
            s = s * s * (3 - 2 * s)
        rotations = slerp(s).as_matrix()  # all at once: one scipy call per tick cost ~0.2 ms
        for k in range(ticks):
            waypoint = np.eye(4)
            waypoint[:3, :3] = rotations[k]
            waypoint[:3, 3] = (1 - s[k]) * start[:3, 3] + s[k] * target[:3, 3]
            self._tick(waypoint)
        for _ in range(round(self.config.settle_time / self.config.tick)):
            position_error, orientation_error = self._tick(target)
            reached = np.linalg.norm(self.robot.tcp_pose_in_base()[:3, 3] - target[:3, 3]) < 0.003
            if reached and position_error < 0.002:
                return
        if position_error > 0.01:
            raise IKFailure(f"TCP target {np.round(target[:3, 3], 3).tolist()} not reached: out of reach")

    def travel_to(self, target: np.ndarray, duration: float) -> None:
        """Reach ``target`` (4x4) from afar through a waypoint ``transit_height`` above the middle of the
        workspace: from the rest posture a straight TCP line to a box near the robot passes by the base
        and folds the arm onto itself (the gripper hit links 1, 4 and 5 at ~200 N). (A joint-space move
        to an IK solution avoided that but reached postures whose forearm then met the box.)"""
        via = target.copy()
        via[:3, 3] = (*self.config.transit_xy, max(target[2, 3], self.config.transit_height))
        self.move_to(via, 0.5 * duration)
        self.move_to(target, duration)

    def _joint_move(self, q_goal: np.ndarray, duration: float) -> None:
        """Interpolate the joints to ``q_goal`` [rad] over ``duration`` [s] (no IK: always feasible)."""
        start = self.robot.joint_positions()
        ticks = max(1, round(duration / self.config.tick))
        for k in range(1, ticks + 1):
            s = k / ticks
            s = s * s * (3 - 2 * s)
            self.robot.command_joint_positions(self._clip((1 - s) * start + s * q_goal))
            self._wait_tick()

    def _gripper(self, closure: float, duration: float) -> None:
        self.robot.command_gripper(closure)
        ticks = round(duration / self.config.tick)
        for _ in range(ticks):
            self._tick(self.ik.tcp_pose())

    def _close_slowly(self, settle: bool = False) -> np.ndarray:
        """Ramp the gripper command from its pre-grasp closure to fully closed at ``close_speed``, then
        hold for ``close_time`` while the grip builds, the wrist yielding along the closing axis to a load there
        (``grasp_centre_force``) and, with ``settle``, once closed, across it too (``comply_deadband``). Returns how
        far it yielded [m, base frame]: where the handle was found to be beside where it was aimed."""
        c = self.config
        ramp = max(1, round((1.0 - c.pregrasp_closure) / c.close_speed * self.slowdown / c.tick))
        hold = self.ik.tcp_pose()
        axis = hold[:3, 1].copy()  # the fingers close along the TCP's y axis (skills.kinematics.top_down)
        shift = 0.0
        # once closed on a handle the pads push along its motion (a slide's, a wheel's, a drawer's), the hand also
        # yields across the closing axis, as a door's path does (:meth:`_yield_across`): a handle gripped a few
        # millimetres from where it was aimed (an uncalibrated camera) loads the stiff arm across the fingers —
        # 15-18 N on a free wheel, 28 N as it turned about the aimed point, read as held part-way at 29 % — and
        # the hand settles on the handle before it pulls. A post that pivots between the pads (a door's, a lever's)
        # keeps the grasp it had: settled, the doors' replayed loads fitted a friction 31 % below the nominal
        # model's on ideal-world logs (tests/twin/test_system_id.py); a door's path yields as it moves
        settled = np.zeros(3)
        for k in range(1, ramp + round(c.close_time / c.tick) + 1):
            if k <= ramp:
                self.robot.command_gripper(c.pregrasp_closure + (1.0 - c.pregrasp_closure) * k / ramp)
            elif settle:
                settled = self._yield_across(settled, axis)
            shift = self._centring(shift, axis)
            if shift == 0.0 and not settled.any():  # (the aimed pose itself, to the bit, while nothing pushes)
                self._tick(hold)
            else:
                shifted = hold.copy()
                shifted[:3, 3] += shift * axis + settled
                self._tick(shifted)
        return shift * axis + settled

    def _centring(self, shift: float, axis: np.ndarray) -> float:
        """The hand's offset ``shift`` [m] along the closing ``axis`` (unit, base frame) moved along the filtered
        load on that axis above ``grasp_centre_force`` (or the noise margin), at ``comply_gain``, within
        ``grasp_centre_limit``."""
        c = self.config
        load = float(self.force_in_base @ axis)
        deadband = max(c.grasp_centre_force, c.comply_noise_margin * self.rest_noise)
        if abs(load) <= deadband:
            return shift
        shift += c.comply_gain * c.tick * math.copysign(abs(load) - deadband, load)
        return max(-c.grasp_centre_limit, min(c.grasp_centre_limit, shift))

    # -- the toggle --------------------------------------------------------------------------------
    def grasp_yaw(self, jm: JointModel) -> float:
        """Yaw of the gripper (the kind's ``Handling.grasp``). Slides and wheels: the fingers close along
        the handle's (horizontal) direction of motion, so the pads push it. Doors: along the hinge axis, so the
        handle pivots between the pads like a pin as the door swings and the gripper need not tilt 85 degrees
        (tilting with it folded the arm onto itself)."""
        direction = jm.axis if jm.handling.grasp == "along_axis" else jm.motion_direction(0.0)
        return float(np.arctan2(direction[1], direction[0]) + np.pi / 2)

    def toggle(
        self,
        jm: JointModel,
        opening: bool = True,
        where_is: collections.abc.Callable[[], float | None] | None = None,
        door_at: float | None = None,
        push: bool = False,
        raised: bool = False,
        cautious: bool = False,
        lean: np.ndarray | None = None,
        careful: bool = False,
        stands_at: float | None = None,
    ) -> ToggleResult:
        """Try to move the component of joint model ``jm`` to its other state (see the module docstring).
        ``where_is`` looks at the part and tells the fraction of its travel at which it stands now (0 closed,
        1 open; None if not seen): a door the pinch could not hold is pushed from there. ``door_at``: where a
        door was just seen to stand; one part-way (past ``blocked_progress`` of the motion) is pushed from
        there at once, as its handle is not where a pinch would descend. ``push``: push a door without
        pinching it first (from ``door_at``, else from its start). ``raised``: a door stands raised where no
        look sees it (above ~50 deg its handle hides its marker): pushed on up under its plate. ``cautious``: a
        door may stand open over the part (:mod:`skills.door_clearance`): every descent of the try is made at
        ``cautious_descend_time`` and stopped at ``cautious_contact_force``. ``lean``: a horizontal vector (base
        frame) in whose direction a pinch's gripper leans by ``lean_angle`` times its length (at most 1) about its
        closing axis, away from what may stand over the part (:func:`skills.door_clearance.lean_away`); it
        descends and lifts along its tilted axis. ``careful``: every motion in contact at ``careful_pace`` (a part
        tried as a kind it was not told). ``stands_at``: where a part that does not swing up was just seen to stand
        (fraction of its travel, 0 closed, 1 open; :attr:`head_start`)."""
        wall = time.perf_counter()
        self.cautious = cautious
        self.careful = careful
        ahead = None if stands_at is None or jm.handling.swings_up else (stands_at if opening else 1.0 - stands_at)
        self.head_start = 0.0 if ahead is None else min(max(ahead, 0.0), MAX_HEAD_START)
        self.lean = lean
        start_time = self.robot.time
        self.reset_force_watch()
        c = self.config
        pushable = jm.handling.swings_up and c.door_push
        covered = None if door_at is None else (door_at if opening else 1.0 - door_at)
        if pushable and opening and raised:
            result = self._attempt(lambda: self._top_up_door(jm))
        elif pushable and (push or (not opening and c.push.close_by_push) or (covered or 0.0) >= c.blocked_progress):
            result = self._push_on(jm, opening, 0.0 if covered is None else covered, where_is)
        else:
            result = self._attempt(lambda: self._toggle(jm, 1.0 if opening else -1.0))
            empty = result.cause is Cause.GRASP_EMPTY
            if pushable and opening and result.outcome == "moved" and not result.end_stop_felt and c.push.top_up:
                self._attempt(lambda: self._top_up_door(jm))  # best effort: the pinch's verdict stands
            if pushable and result.cause in PADS_LOST_HOLD:
                # the pads could not hold the handle: push the door instead, in the same try, from where it stands
                covered = self._push_start(result, opening, where_is)
                if covered is not None:
                    result = self._push_on(jm, opening, covered, where_is)
                elif result.progress < c.moved_fraction:  # (past it, the world looks whether it moved)
                    result.reason += "; the door stands part-way where it cannot be seen: not pushed"
                    result.not_pushed = True
            result.closed_on_nothing = empty
        result.peak_force = self.peak_force  # over the whole try, withdrawal included
        result.sim_time = self.robot.time - start_time
        result.wall_time = time.perf_counter() - wall
        return result

    def _push_on(
        self,
        jm: JointModel,
        opening: bool,
        covered: float,
        where_is: collections.abc.Callable[[], float | None] | None = None,
    ) -> ToggleResult:
        """:meth:`_push`, and an opening push that lost the handle's face short of the travel (``IncompleteTravel``:
        under the harsh profile's perception error the pad drifted off a post at 62 deg) followed by a top-up
        under the plate (:meth:`DoorPushing._top_up_door`) if ``where_is`` does not see the door (above ~50 deg
        its handle hides its marker), whose verdict then stands (the world checks a ``moved`` against the
        marker). A door seen lower is left to a retry's push from where it stands: under a plate that low
        the top-up's pads pass over it and read "moved"."""
        result = self._push(jm, opening, covered)
        if opening and self.config.push.top_up and result.cause is Cause.INCOMPLETE_TRAVEL:
            if where_is is not None and where_is() is not None:
                return result
            topped = self._attempt(lambda: self._top_up_door(jm))
            if topped.outcome == "moved":
                return topped
            result.reason += f"; pushed on under its plate: {topped.reason}"
            result.pushed_on = topped
        return result

    def _push(self, jm: JointModel, opening: bool, covered: float) -> ToggleResult:
        """Push door ``jm`` open or shut from where it stands, ``covered`` (fraction of this motion's travel),
        beginning ``push.start_margin`` behind it: a door let go part-way falls back ~1 deg while the arm
        comes round, and behind the handle the pad only sits higher on the post (~1.7 mm per deg)."""
        c = self.config
        start = min(max(covered - c.push.start_margin, 0.0), c.moved_fraction)
        push = self._push_door_open if opening else self._push_door_closed
        return self._attempt(lambda: push(jm, start))

    def _push_start(
        self, pinch: ToggleResult, opening: bool, where_is: collections.abc.Callable[[], float | None] | None
    ) -> float | None:
        """Fraction of the motion's travel a door has covered after a pinch lost its hold, as seen by
        ``where_is``: the pinch's own progress is the fingers', and a handle sliding in weak pads lags them (a
        door at 43 deg after fingers at 68 deg), so a push placed from it met the raised post at 60-100 N, or
        swung through the air; a grasp that closed on nothing may be a door left part-way by an earlier try.
        Not seen: a pinch short of ``blocked_progress`` left the door near its start (0); a closing push
        descends onto the plate from above and meets it on the way down (0); an opening push of a door opened
        part-way (above ~50 deg its handle hides its marker from above) has nowhere safe to start (None)."""
        seen = where_is() if where_is is not None else None
        if seen is not None:
            return seen if opening else 1.0 - seen
        if pinch.progress < self.config.blocked_progress or not opening:
            return 0.0
        return None

    def _attempt(self, motion: collections.abc.Callable[[], ToggleResult]) -> ToggleResult:
        """Run one toggle motion; a typed failure ends it ``failed`` with its reason, the arm withdrawn."""
        self.progress = 0.0
        try:
            return motion()
        except (IKFailure, GraspFailure, SlipDetected, ForceLimitExceeded) as err:
            result = ToggleResult(
                "failed", reason=f"{type(err).__name__}: {err}", progress=self.progress, cause=err.cause,
                stopped_while=err.phase if isinstance(err, ForceLimitExceeded) else "",
            )  # fmt: skip
            self.withdraw()
            return result

    def _descend_to(self, target: np.ndarray) -> None:
        """Open to the pre-grasp closure, travel above ``target`` (4x4; :meth:`_approach`), tare the F/T there and
        descend onto it."""
        c = self.config
        # the lift off this part goes back the same way: a pinch's lean, not a push's upright pads after it
        self._lean_drift = target[:3, 2] / target[2, 2]
        self._lean_drift[2] = 0.0
        self.robot.command_gripper(c.pregrasp_closure)
        self.phase = "approaching"
        height = self._approach(target)
        self.rest_noise = self.force_noise()  # coming to rest above the part
        self.robot.tare(self.tare_samples(self.rest_noise))  # fingers open, arm still: the gripper's load alone
        # older samples were taken with another zero; the window is as long as this noise needs
        samples = self.filter_samples(self.rest_noise)
        self._force_window = collections.deque(maxlen=samples)
        self.slowdown = samples / c.force_filter_samples / (c.careful_pace if self.careful else 1.0)
        self.phase = "descending"
        if self.cautious:  # the whole way slowly, under the light touch
            slow = c.cautious_descend_time * height / c.approach_height
        else:
            # quickly down to where the fingers could first meet a handle they were aimed beside, then slowly, so
            # that one met (a wrong perception or calibration) stops the arm at a light touch: the try fails, not
            # the part
            near = target.copy()
            near[:3, 3] -= c.touch_height * target[:3, 2]
            self.move_to(near, c.descend_time * (height - c.touch_height) / c.approach_height * self.slowdown)
            slow = c.touch_height / c.touch_speed
        self.limit = max(c.cautious_contact_force, c.cautious_noise_margin * self.rest_noise)
        try:
            self.move_to(target, slow * self.slowdown, smooth=False)
        finally:
            self.limit = c.force_limit

    def _approach(self, target: np.ndarray) -> float:
        """Travel to above ``target`` (4x4) along its approach axis (up, when upright) and return how high above it
        [m]: ``approach_height``, or, where that point stands within ``base_radius`` of the vertical axis of the
        arm's base, ``base_rise``, reached at that height from ``base_radius`` out and moving in horizontally (the
        way :meth:`_out_from_base` leaves): the arm reaches there folded over its own shoulder, and every route to 8
        cm above a drawer's handle 0.176 m from the axis put the gripper's knuckle on link 2 (101-137 N, 17 mm deep in
        the robot model); arriving 3.5 cm above it from outside kept 3-6 mm of clearance, more on the way down."""
        c = self.config
        above = target.copy()
        above[:3, 3] -= c.approach_height * target[:3, 2]
        radius = math.hypot(above[0, 3], above[1, 3])
        if not 1e-6 <= radius < c.base_radius:
            self.travel_to(above, c.approach_time)
            return c.approach_height
        height = max(c.base_rise, c.touch_height)
        above[:3, 3] = target[:3, 3] - height * target[:3, 2]
        out = above.copy()
        _out_to_radius(out, c.base_radius)
        self.travel_to(out, c.approach_time)
        self.move_to(above, c.retreat_time)
        return height

    def _toggle(self, jm: JointModel, sign: float) -> ToggleResult:
        c = self.config
        begin = 0.0 if sign > 0 else 1.0
        grasp_yaw = self.grasp_yaw(jm)
        at_grasp = self._leaning(top_down(jm.grasp_point_at(begin), grasp_yaw))
        self._descend_to(at_grasp)
        self.phase = "grasping"
        found = self._close_slowly(settle=jm.handling.grasp == "across_motion")
        if found.any():  # the handle stands that far beside where it was aimed: the path starts from it
            jm = replace(jm, origin=jm.origin + found, grasp_point=jm.grasp_point + found)
            at_grasp = at_grasp.copy()
            at_grasp[:3, 3] += found
        grasp_closure = self.robot.gripper_opening()
        self._closures.clear()
        self._closures.append(grasp_closure)
        if grasp_closure >= c.empty_grasp_closure:
            raise GraspFailure(f"the gripper closed on nothing at {np.round(at_grasp[:3, 3], 3).tolist()}")

        self.phase = "actuating"
        result = self._actuate(jm, sign, begin, at_grasp)
        self.phase = "retreating"
        self._let_go_and_retreat()
        self.phase = "moving"
        return result

    def _actuate(self, jm: JointModel, sign: float, begin: float, at_grasp: np.ndarray) -> ToggleResult:
        c = self.config
        along_post = float(sign * jm.motion_direction(begin) @ at_grasp[:3, 2])  # cosine to the approach axis
        pressed = along_post > math.cos(c.press_angle)
        # pulled up along its post (``press_force``), but not from a head start of MAX_HEAD_START: a part seen that far
        # along is not where its state says, and may be lifted into its stop
        pulled = (
            along_post < -math.cos(c.press_angle) and not jm.handling.swings_up and self.head_start < MAX_HEAD_START
        )
        slowdown = self.slowdown
        if pressed:  # at press_pace at the most (a careful toggle may already go slower)
            slowdown *= max(1.0, (c.careful_pace if self.careful else 1.0) / c.press_pace)
        ticks = round(c.actuate_time * slowdown / c.tick)
        forces: list[float] = []
        progress = 0.0
        path_length = (
            jm.travel
            if jm.joint == "slide"
            else jm.travel
            * float(
                np.linalg.norm((jm.grasp_point - jm.origin) - np.dot(jm.grasp_point - jm.origin, jm.axis) * jm.axis)
            )
        )
        lead = c.lead / path_length  # as a fraction of the travel
        end = 1.0 + (c.door_overtravel if jm.handling.swings_up and sign > 0 else 0.0)
        pace = end / ticks  # travel per tick up to the travel's end
        pacing = Pacing(pace, pace * c.breakaway_pace, c.breakaway_fraction)  # slow start, then a ramp up
        last_tick = pacing.ticks_to(1.0 + 2 * (end - 1.0))
        progress_at_peak = 0.0
        in_end_stop = False  # felt the door reach its end stop: open, whatever the pads do next
        across = np.zeros(3)  # the path's offset across itself, yielding to the load there [m, base frame]
        yields = jm.handling.yields_across
        held_along = None if jm.handling.axis_yield == 1.0 else jm.axis  # (a load along it: yielded to in part)
        axis_yield = jm.handling.axis_yield
        returning = 1.0 - c.tick / c.comply_return_time  # the offset kept per tick past the travel
        window = max(2, round(c.stall_window * slowdown / c.tick))
        press_limit = (
            max(c.press_force, c.press_noise_margin * self.filtered_noise_now()) if pressed or pulled else math.inf
        )
        recent: collections.deque[float] = collections.deque(maxlen=window)  # progress over the last stall_window
        self.ik.set_joints(self.robot.joint_positions())
        for k in range(1, last_tick + 1):
            paced = pacing.at(k)
            paced = paced if paced <= 1.0 else 1.0 + 0.5 * (paced - 1.0)  # past the travel at half pace
            s = min(end, paced, max(progress, 0.0) + lead)
            fraction = begin + sign * s
            target = self._pose_along(jm, fraction, at_grasp, begin)
            target[:3, 3] += across
            self._tick(target)
            direction = sign * jm.motion_direction(fraction)
            opposing = float(-np.dot(self.force_in_base, direction))
            if yields:  # once the end stop is felt, back to the planned arc: its load tells the door is open
                if s <= 1.0 or (c.overtravel_comply and not in_end_stop):
                    across = self._yield_across(across, direction, held_along, axis_yield)
                else:
                    across = across * returning
            forces.append(opposing)
            progress = self.progress = self._progress(jm, sign, begin)
            if opposing >= max(forces):
                progress_at_peak = progress
            try:
                self._check_grip(progress)
            except SlipDetected:
                if progress_at_peak < c.blocked_progress and max(forces) >= c.push_force:
                    # the part held while pulled until the pads slid off its handle: a latch, not a slip
                    return ToggleResult("blocked", SLIPPED_OFF, progress, max(forces),
                                        forces=forces, cause=Cause.LOCKED_SLIPPED_OFF)  # fmt: skip
                if in_end_stop:  # the pads slid off a post pressed into its end stop: the door is open
                    return ToggleResult("moved", "", progress, max(forces), forces=forces, end_stop_felt=True)
                raise
            magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
            in_end_stop = in_end_stop or (s > 1.0 and magnitude > c.end_stop_force)
            if s > 1.0 and magnitude > c.overtravel_force:  # past the travel and pushing hard: stop here
                end = max(1.0, min(progress, s))
            held = opposing > press_limit and s <= 1.0  # a handle pressed along its post: held at a light force
            if (
                opposing > c.blocked_force or magnitude > c.blocked_magnitude or held
            ) and progress < c.blocked_progress:
                self._take_back(functools.partial(self.move_to, at_grasp, 0.5))  # back to where the handle was grasped
                return ToggleResult(
                    "blocked", LATCHED[Cause.LOCKED_NO_PROGRESS], progress, max(forces), forces=forces,
                    cause=Cause.LOCKED_NO_PROGRESS,
                )  # fmt: skip
            recent.append(progress)
            stalled = len(recent) == recent.maxlen and progress - recent[0] < c.stall_progress
            held = held or (stalled and opposing > c.stall_force and s <= 1.0)
            if held and progress + self.head_start >= c.moved_fraction:
                end = max(progress, 0.0)  # at its stop short of the perceived travel: pushed no further
                break
            if held:  # (progress >= blocked_progress: tested above)
                self._take_back(functools.partial(self._return_along, jm, sign, begin, progress, at_grasp, across))
                return ToggleResult(
                    "blocked", f"{HELD_PART_WAY} ({progress:.0%} of the travel)", progress, max(forces), forces=forces,
                    cause=Cause.HELD_PART_WAY, held_at=progress,
                )  # fmt: skip
        for _ in range(round(2 * c.settle_time / c.tick)):  # let the part catch up with the end target
            progress = self.progress = self._progress(jm, sign, begin)
            target = self._pose_along(jm, begin + sign * min(end, max(progress, 0.0) + lead), at_grasp, begin)
            target[:3, 3] += across
            self._tick(target)
            try:
                self._check_grip(progress)
            except SlipDetected:
                if not in_end_stop:
                    raise
                break
        reached = self._progress(jm, sign, begin) + self.head_start
        result = self._verdict(reached, forces, Cause.LOCKED_PULLED)
        result.end_stop_felt = in_end_stop
        if result.outcome == "blocked":
            self._take_back(functools.partial(self.move_to, at_grasp, 0.5))
        return result

    def _take_back(self, motion: collections.abc.Callable[[], None]) -> None:
        """Run ``motion``, a held handle's way back to where it was grasped, under ``back_off_force``: stopped there,
        the arm backs off along the load (:meth:`_relieve`) and sets out once more; stopped again, it stays backed
        off (the try's verdict stands). The load of the hold still rises for a few ticks after it is read (the
        filter's lag): a wheel held at 35-40 N had its way back stopped on the second tick and was left at 27 % of
        its travel, where its next try began with the hand believing it closed (it met its stop at 73 % of the way
        and read held part-way)."""
        limit = self.limit
        self.limit = min(limit, self.config.back_off_force)
        try:
            for _ in range(2):  # (once more after backing off)
                try:
                    motion()
                    return
                except ForceLimitExceeded:
                    self.guard = False
                    try:
                        self._relieve()
                    finally:
                        self.guard = True
        finally:
            self.limit = limit

    def _return_along(
        self, jm: JointModel, sign: float, begin: float, covered: float, at_grasp: np.ndarray, across: np.ndarray
    ) -> None:
        """Take a handle held part-way, ``covered`` of the travel from ``begin``, back along its path to where it
        was grasped (``at_grasp``; ``across``: the path's offset, let go on the way) over ``release_time`` per 10 %
        of the travel: a straight line cuts a hinge's arc."""
        c = self.config
        ticks = max(1, round(c.release_time * max(covered, 0.0) / 0.1 / c.tick))
        for k in range(1, ticks + 1):
            left = 1.0 - k / ticks
            target = self._pose_along(jm, begin + sign * covered * left, at_grasp, begin)
            target[:3, 3] += across * left
            self._tick(target)

    def _yield_across(
        self, across: np.ndarray, direction: np.ndarray, held_along: np.ndarray | None = None, share: float = 1.0
    ) -> np.ndarray:
        """The path's offset ``across`` [m] moved along the filtered force's component across the direction of
        motion ``direction`` (unit, base frame), at ``comply_gain`` per newton above a deadband
        (``comply_deadband``, ``comply_noise_margin``), within ``comply_limit``: a path planned from a slightly
        wrong hinge pulls the handle across its true arc, which the part resists with no motion, and only the
        load along the motion tells a latch. ``held_along``: a unit axis along which only ``share`` of the load is
        yielded to (``Handling.axis_yield``)."""
        c = self.config
        force = self.force_in_base
        load = force - float(force @ direction) * direction
        if held_along is not None:  # only in part along this (unit) axis, where the part holds the handle in the pads
            load = load - (1.0 - share) * float(load @ held_along) * held_along
        size = math.sqrt(load @ load)
        deadband = max(c.comply_deadband, c.comply_noise_margin * self.rest_noise)
        if size <= deadband:
            return across
        across = across + (c.comply_gain * c.tick * (size - deadband) / size) * load
        length = math.sqrt(across @ across)
        return across if length <= c.comply_limit else across * (c.comply_limit / length)

    def _verdict(self, progress: float, forces: list[float], latched: Cause | None = None) -> ToggleResult:
        """How a motion that ran its course ended: ``moved`` past ``moved_fraction`` of the travel; ``blocked``
        (cause ``latched``, when given) short of ``blocked_progress`` after at least ``push_force`` against
        the motion (``forces`` [N], one per tick); else ``failed``."""
        c = self.config
        peak = max(forces)
        if progress >= c.moved_fraction:
            return ToggleResult("moved", "", progress, peak, forces=forces)
        if latched is not None and progress < c.blocked_progress and peak >= c.push_force:
            return ToggleResult("blocked", LATCHED[latched], progress, peak, forces=forces, cause=latched)
        return ToggleResult(
            "failed", f"{INCOMPLETE_TRAVEL}: only {progress:.0%} of the travel covered", progress, peak, forces=forces,
            cause=Cause.INCOMPLETE_TRAVEL,
        )  # fmt: skip

    def _check_grip(self, progress: float) -> None:
        closure = self.robot.gripper_opening()
        self._closures.append(closure)
        if closure >= self.config.empty_grasp_closure or closure > min(self._closures) + self.config.slip_closure_rise:
            raise SlipDetected(f"the handle slipped out of the grasp after {progress:.0%} of the travel")

    def _leaning(self, upright: np.ndarray) -> np.ndarray:
        """``upright`` (a top-down TCP pose, 4x4) turned by ``lean_angle`` about its closing axis (y) so that the
        gripper's upper part leans along :attr:`lean`'s component across that axis; unchanged without a lean,
        or when the lean lies along the closing axis (turning the pads off the handle's faces would not do)."""
        if self.lean is None or self.config.lean_angle == 0.0:
            return upright
        strength = float(np.linalg.norm(self.lean))
        closing = upright[:3, 1]
        across = self.lean - float(self.lean @ closing) * closing
        across[2] = 0.0
        size = float(np.linalg.norm(across))
        if size < 0.5 * strength:
            return upright
        across /= size
        angle = self.config.lean_angle * min(strength, 1.0)
        axis = np.cross((0.0, 0.0, 1.0), across)  # turning +z towards ``across``
        leaning = upright.copy()
        leaning[:3, :3] = Rotation.from_rotvec(axis * angle).as_matrix() @ upright[:3, :3]
        return leaning

    def _pose_along(self, jm: JointModel, fraction: float, at_grasp: np.ndarray, begin: float) -> np.ndarray:
        T = at_grasp.copy()
        T[:3, 3] = jm.grasp_point_at(fraction)
        if jm.joint == "hinge" and abs(jm.axis[2]) > 0.9:  # wheels: the gripper turns with the knob
            turn = Rotation.from_rotvec(jm.axis * (fraction - begin) * jm.travel).as_matrix()
            T[:3, :3] = turn @ at_grasp[:3, :3]
        return T

    def _progress(self, jm: JointModel, sign: float, begin: float) -> float:
        """Measured fraction of the travel covered towards the other state, from the TCP position."""
        return sign * jm.fraction_between(jm.grasp_point_at(begin), self.robot.tcp_pose_in_base()[:3, 3])

    def withdraw(self) -> None:
        """After a stop: back off along the load, open the gripper, move up and go to rest with the force
        guard off (the load that tripped it is what the withdrawal relieves). Backing off first matters for
        a pad pressed on a part: held where it stopped while the gripper opens, a stuck door kept 170 N on
        the wrist for half a second."""
        self.guard = False
        try:
            self._relieve()
        finally:
            self.guard = True
        self._let_go_and_retreat(guarded=False)

    def _relieve(self) -> None:
        """Move up to ``relieve_distance`` along the load, stopping once the load along that way has fallen
        below ``relieve_load``: with the fingers still closed on a handle that jammed, the whole 5 mm carried the
        arm past where the load vanished and pushed the handle the other way (70 N, then 148 N, reversed)."""
        c = self.config
        load = math.sqrt(self.force_in_base @ self.force_in_base)
        if load <= c.relieve_load:
            return
        along = self.force_in_base / load
        start = self.robot.tcp_pose_in_base()
        self.ik.set_joints(self.robot.joint_positions())
        ticks = max(1, round(c.release_time / c.tick))
        for k in range(1, ticks + 1):
            s = k / ticks
            target = start.copy()
            target[:3, 3] += c.relieve_distance * s * s * (3 - 2 * s) * along
            self._tick(target)
            if float(self.force_in_base @ along) < c.relieve_load:
                return

    def _let_go_and_retreat(self, guarded: bool = True) -> None:
        """Open, move up and go to rest; a force stop on the way withdraws unguarded."""
        try:
            self.guard = guarded
            self._retreat_moves()
        except ForceLimitExceeded:
            self.guard = False
            self._retreat_moves()
        finally:
            self.guard = True

    def _retreat_moves(self) -> None:
        """Open gently to the pre-grasp closure (wide enough to let the 12 mm post go; fully open, the ~8 cm
        fingers caught neighbouring parts on the way up), lift, and go to rest."""
        c = self.config
        self._open_gently(c.pregrasp_closure)
        try:
            self.ik.set_joints(self.robot.joint_positions())
            self._lift_clear(c.approach_height)
        except IKFailure:
            pass  # already as high as the arm goes
        self._interpolate_to_rest()

    def _lift_clear(self, height: float) -> None:
        """Lift the open gripper by ``height`` [m], stopping at a light touch (``lift_contact_force``); on one,
        back off, step ``lift_sidestep`` along the pads (the TCP's x: parallel to the handle between them, which
        the step then never pushes), first to the side the load pushed towards, then to the other, and lift
        again. Withdrawing (guard off), or when neither side clears, the lift runs under the full guard. Near the
        base's axis it first moves out from it (:meth:`_out_from_base`)."""
        c = self.config
        bottom = self.robot.tcp_pose_in_base()[2, 3]
        top = bottom + height
        if self.guard:
            limit = self.limit
            self.limit = max(c.lift_contact_force, c.lift_noise_margin * self.filtered_noise_now())
            origin, away = None, np.zeros(3)
            try:
                for side in (0.0, 1.0, -1.0):
                    try:
                        if side:
                            assert origin is not None  # the first try (side 0) ended in a touch
                            self._step_along_pads(origin, side * away)
                        up = self.robot.tcp_pose_in_base()
                        self._rise(up, min(up[2, 3] + c.lift_slow_height, top))
                        self.move_to(up, c.lift_slow_time)
                        self._out_from_base(up, bottom, top)
                        self._rise(up, top)
                        self.move_to(up, c.retreat_time)
                        return
                    except ForceLimitExceeded:
                        if origin is None:  # which way the first touch pushed, before backing off from it
                            away = self.force_in_base.copy()
                        self.guard = False
                        try:
                            self._relieve()
                        finally:
                            self.guard = True
                        if origin is None:
                            origin = self.robot.tcp_pose_in_base()[:3, 3].copy()
            finally:
                self.limit = limit
        up = self.robot.tcp_pose_in_base()
        self._out_from_base(up, bottom, top)
        self._rise(up, top)
        self.move_to(up, c.retreat_time)

    def _out_from_base(self, pose: np.ndarray, bottom: float, top: float) -> None:
        """If ``pose`` (4x4, the lift's target so far; moved in place) stands within ``base_radius`` of the vertical
        axis of the arm's base, rise to ``base_rise`` above ``bottom`` (where the lift began; at most ``top``) [m]
        and move out horizontally to ``base_radius``: the arm reached there folded over its own shoulder."""
        c = self.config
        radius = math.hypot(pose[0, 3], pose[1, 3])
        if radius >= c.base_radius or radius < 1e-6:
            return
        if pose[2, 3] < min(bottom + c.base_rise, top):
            self._rise(pose, min(bottom + c.base_rise, top))
            self.move_to(pose, c.lift_slow_time)
        _out_to_radius(pose, c.base_radius)
        self.move_to(pose, c.retreat_time)

    def _open_gently(self, closure: float) -> None:
        """Ramp the gripper's command open to ``closure`` at ``gentle_release_speed`` (slowed with the motions in
        contact); a filtered force that rises past the lift's light touch (``lift_contact_force``, or
        ``lift_noise_margin`` times the filtered noise) above its value at the start holds the command, and the arm
        backs off along the load before they open on (three times; at a fourth touch the fingers stay where they
        are): a finger opening under the plate of a door standing open over the part presses into it with the
        gripper's whole force."""
        c = self.config
        touch = max(c.lift_contact_force, c.lift_noise_margin * self.filtered_noise_now())
        touch += math.sqrt(self.force_in_base @ self.force_in_base)  # the handle's load, gone once let go
        step = c.gentle_release_speed * c.tick / self.slowdown
        command = self.robot.gripper_opening()
        touches = 0
        while command > closure:
            command = max(closure, command - step)
            self.robot.command_gripper(command)
            self._tick(self.ik.tcp_pose())
            if math.sqrt(self.force_in_base @ self.force_in_base) > touch:
                if touches == 3:  # let go as far as there is room: the lift steps aside from what stops it
                    self.robot.command_gripper(self.robot.gripper_opening())
                    return
                touches += 1
                # the command held, no harder: the finger opens on as the arm backs off, until the load is gone
                guard, self.guard = self.guard, False
                try:
                    self._relieve()
                finally:
                    self.guard = guard

    def _rise(self, pose: np.ndarray, height: float) -> None:
        """Raise ``pose`` (4x4, in place) to ``height`` [m] along the approach axis of a leaning gripper (straight
        up when upright): back the way it came down, its upper part clear of what it leans away from."""
        if self._lean_drift.any():
            pose[:3, 3] += (height - pose[2, 3]) * self._lean_drift
        pose[2, 3] = height

    def _step_along_pads(self, origin: np.ndarray, away: np.ndarray) -> None:
        """Move the TCP to ``lift_sidestep`` from ``origin`` (base frame [m]) along its x axis, on the side of
        ``away`` (a load's direction: it points from what was met), at its present height."""
        pose = self.robot.tcp_pose_in_base()
        along = pose[:3, 0].copy()
        along[2] = 0.0
        along /= np.linalg.norm(along)
        target = pose.copy()
        target[:3, 3] = origin + math.copysign(self.config.lift_sidestep, float(away @ along)) * along
        target[2, 3] = pose[2, 3]
        self.move_to(target, self.config.retreat_time)

    def go_rest(self) -> None:
        """Back to the rest posture by joint interpolation (no IK: always feasible); a force stop on the
        way withdraws upwards first."""
        try:
            self._interpolate_to_rest()
        except ForceLimitExceeded:
            self.withdraw()

    def _interpolate_to_rest(self) -> None:
        """Lift the TCP straight up to ``transit_height``, clear of the box and anything standing on it,
        move it to the transit waypoint, and only from there interpolate the joints to the rest posture
        (folded over the base, out of the overview's view): interpolated from wherever the arm was, the
        joints swept the gripper base into the arm's own link 2 (69-185 N on the wrist)."""
        c = self.config
        try:
            self.ik.set_joints(self.robot.joint_positions())
            via = self.robot.tcp_pose_in_base()
            if via[2, 3] < c.transit_height - 0.01:
                via[2, 3] = c.transit_height
                self.move_to(via, c.lift_time)
            via[:3, 3] = (*c.transit_xy, max(via[2, 3], c.transit_height))
            self.move_to(via, c.lift_time)
        except IKFailure:
            pass  # as far as the arm goes: interpolate from here
        self._joint_move(np.asarray(self.rest_posture), c.rest_time)
        self.robot.wait(c.settle_time)
