"""The settings of the hand (:class:`skills.primitives.Toggler`), by the phase of a try they govern: how the arm
moves (:class:`MotionConfig`), how the wrist's readings are sensed (:class:`SensingConfig`), the approach and descent
onto a handle (:class:`ApproachConfig`), the grasp (:class:`GraspConfig`), the actuation along the handle's path
(:class:`ActuationConfig`), what the readings mean (:class:`JudgementConfig`), the retreat (:class:`RetreatConfig`),
and a door's pushes (:class:`DoorPushConfig`: :class:`DoorPushPlan`, :class:`DoorPushJudgement`, :class:`TopUpPlan`).

:class:`PrimitiveConfig` holds one of each. A setting is read where it belongs (``config.judgement.blocked_force``)
and changed by its own name (``PrimitiveConfig.of(force_limit=45.0)``, ``config.changed(lean_angle=0.0)``): the
names are unique across the phases. Every setting, its unit, default and reason: ``docs/settings.md``
(``python -m puzzlebox.lab.settings_table``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

from puzzlebox.models.cell_config import CellConfig
from puzzlebox.skills.errors import ConfigError

TARE_SAMPLES = 10
"""Readings a tare averages at low noise (the :class:`models.robot.Robot` protocol's default)."""


@dataclass(frozen=True)
class MotionConfig:
    """How the arm moves: the control tick, the IK, the moves from afar, the compliance of a path in contact and
    what a stopped arm does."""

    tick: float = 0.01
    """Control period [s]."""
    ik_iterations_per_tick: int = 2
    """Most IK iterations per control tick [-] (none once the TCP has settled on its target)."""
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
    """Time of the short moves off a load (backing off after a force stop, a pad off a door's plate before letting
    go), and of a held handle's way back per 10 % of the travel it covered [s]."""
    transit_height: float = 0.35
    """TCP height of the waypoint of a move from afar (``GuardedMotion.travel_to``) [m]: well above the 8 cm box
    and its 3.5 cm handles."""
    transit_xy: tuple[float, float] = (0.42, 0.0)
    """Where that waypoint is, in the base frame [m]: over the middle of the reachable workspace."""
    settle_time: float = 0.6
    """Extra time allowed at the end of a move for the servos to catch up [s]."""
    relieve_load: float = 3.0
    """Filtered force above which a stopped arm backs off along it before letting go [N]."""
    relieve_distance: float = 0.005
    """How far the arm backs off along the load after a force stop, before letting go [m]."""

    def __post_init__(self) -> None:
        if min(self.comply_gain, self.comply_deadband, self.comply_noise_margin, self.comply_limit) < 0.0:
            raise ConfigError(
                "comply_gain [m/(N s)], comply_deadband [N], comply_noise_margin and comply_limit [m] must be >= 0,"
                f" got {self.comply_gain}, {self.comply_deadband}, {self.comply_noise_margin}, {self.comply_limit}"
            )
        if self.comply_return_time < self.tick:
            raise ConfigError(f"comply_return_time must be >= tick [s], got {self.comply_return_time}")


@dataclass(frozen=True)
class SensingConfig:
    """How the wrist's force/torque readings are filtered, tared and guarded."""

    noise_samples: int = 30
    """Raw force samples kept for the noise estimate [ticks]."""
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
    (:attr:`ForceWatch.slowdown`): a force rising against a stop then builds no more during the delay than it
    does with the 5-tick median. At 15 N of noise a 23-tick median at full pace met a door shut on its lid
    with 100 N (random agent)."""
    force_limit: float = 60.0
    """Safety limit on the filtered wrist force, whatever the motion [N]. A toggle needs 8-9 N, a latch is
    felt at 20 N (``blocked_force``); UFACTORY publishes no newton threshold for its collision detection
    (REALITY_NOTES.md §1), so this sits where a latched pull is already decided and far below the
    100-300 N that tore grasps off, and below the F/T range (150 N)."""

    def __post_init__(self) -> None:
        if not 1 <= self.force_filter_samples <= self.force_filter_max_samples:
            raise ConfigError(
                "need 1 <= force_filter_samples <= force_filter_max_samples [ticks], got "
                f"{self.force_filter_samples}, {self.force_filter_max_samples}"
            )
        if self.filtered_noise <= 0.0 or self.tare_noise <= 0.0:
            raise ConfigError(
                f"filtered_noise and tare_noise must be > 0 [N], got {self.filtered_noise}, {self.tare_noise}"
            )
        if self.tare_max_samples < TARE_SAMPLES:
            raise ConfigError(f"tare_max_samples must be >= {TARE_SAMPLES}, got {self.tare_max_samples}")


@dataclass(frozen=True)
class ApproachConfig:
    """How the gripper comes to a handle: the approach from above and the descent onto it."""

    pregrasp_closure: float = 0.6
    """Gripper closure while descending onto a handle: open just enough to clear the 12 mm post, so the
    fingers stay over the part and do not land on a neighbour 1.5 cm away (fully open they span ~8 cm)."""
    approach_height: float = 0.08
    """Pre-grasp height above the grasp point [m]."""
    approach_time: float = 1.5
    """Time of the move from afar to above a handle, and of the move out from the base to there [s]."""
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
    """TCP speed over ``touch_height`` [m/s] (slower by :attr:`ForceWatch.slowdown`): the impact of the touch, one
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
    base_radius: float = 0.22
    """A lift whose TCP stands closer than this to the vertical axis of the arm's base [m] first moves out to it,
    ``base_rise`` above where it let go: the arm folded over its own shoulder to reach there (a drawer pulled
    towards the base, the TCP 0.176 m from its axis), and straight up the gripper's knuckle met link 2 (224 N
    true) 6 cm up, with 1 cm of clearance where it let go; moved out first, never under 6 mm (robot model). An
    approach to above such a part comes in from it at ``base_rise`` (:meth:`Pinch.approach`)."""
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

    def __post_init__(self) -> None:
        if not 0.0 < self.touch_height < self.approach_height or self.touch_speed <= 0.0:
            raise ConfigError(
                "need 0 < touch_height < approach_height [m] and touch_speed > 0 [m/s], got "
                f"{self.touch_height}, {self.approach_height}, {self.touch_speed}"
            )


@dataclass(frozen=True)
class GraspConfig:
    """How the gripper closes on a handle."""

    close_time: float = 0.6
    """Time the closed gripper holds still on a handle while the grip builds, after the closing ramp [s]."""
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

    def __post_init__(self) -> None:
        if self.grasp_centre_force <= 0.0 or self.grasp_centre_limit < 0.0:
            raise ConfigError(
                "need grasp_centre_force > 0 [N] and grasp_centre_limit >= 0 [m], got "
                f"{self.grasp_centre_force}, {self.grasp_centre_limit}"
            )


@dataclass(frozen=True)
class ActuationConfig:
    """How a grasped handle is carried along its path (the pinch's plan)."""

    actuate_time: float = 2.5
    """Time of a pinch's or a push's whole travel at the usual pace [s] (longer by the slowdown and the paces)."""
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
    lead: float = 0.02
    """How far the commanded grasp point may run ahead of the measured one, along the path [m]: a
    pre-planned arc from a slightly wrong perceived hinge would otherwise pull the handle out of the
    fingers; 2 cm still pulls a latched part with more than ``blocked_force``."""
    back_off_force: float = 35.0
    """The force guard's threshold while a held handle is taken back to where it was grasped [N]; above it the arm
    backs off along the load instead: a wheel pulled as a door (a misread kind) was dragged there with 49 N true."""
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
    door_overtravel: float = 0.15
    """How far past the far end of a door's travel the grasp point is driven (fraction of the travel), at half
    the pace of the arc: a handle pivoting between the pads lags the fingers by up to ~15 mm along an 85 deg
    door arc, which left doors at ~74 deg, leaning over their neighbours' handles; the joint's end stop takes
    the rest. Past the travel, a filtered force above ``overtravel_force`` stops the over-travel where the
    handle is. (Under the harsh grip the lag is a fifth of the fingers' turn, fingers at 98 deg leaving a
    door at 78: more over-travel met the end stop with 70 N jolts; a top-up push finishes those doors.)"""
    overtravel_comply: bool = True
    """Yield across the path in the over-travel too (:meth:`GuardedMotion.yield_across`), until the end stop is felt
    (``end_stop_force``), then return to the planned arc: the planned arc's mismatch with the door's true arc grows
    past the travel (a door still rising, near upright), and held on the arc it loaded the grasp with ~32 N
    *across* the motion (2-5 N along it), on which the handle's stick-slip in the pads put one-tick spikes of
    45-48 N true (realistic: paper-test-2 seed 105, hard-chain8-s36004 seed 36100). Yielding,
    the same pinches peaked at 27 and 22 N with the doors in their stops; a door that reaches its stop without
    20 N felt is then topped up (``push.top_up``)."""
    overtravel_force: float = 40.0
    """Filtered force magnitude that ends a door's over-travel [N]: a lagging handle pulled into its end stop
    loads the grasp with 20-30 N; a handle that follows the fingers closely is pushed towards the safety
    limit (47 N at 80 deg, then 60 N, with the box 0.34 m from the base)."""
    careful_pace: float = 0.5
    """Pace of every motion in contact (descent, closing, actuation, pushes) of a careful toggle
    (``toggle(careful=True)``: a part tried as a kind it was not told, whose path may meet a post or a stop where
    none was expected), as a fraction of the usual [-]: a force rising against it builds half as fast during the
    filtered reading's delay."""
    part_way_pace: float = 0.3
    """Pace of a push from part-way (a door that stood past ``blocked_progress``: a pinch lost it, a try left it), as
    a fraction of the usual, while the pad closes in on the face and over its slow start [-]: such a door may stand
    still at its lock's wall, where the pad meets a face that does not give. At the usual pace the true load rose
    19, 26, 32, 47 N in four 10 ms ticks while the filtered reading showed 0-19 N (paper-test-1 seed 87038,
    realistic)."""

    def __post_init__(self) -> None:
        if not (0.0 < self.breakaway_pace <= 1.0 and 0.0 <= self.breakaway_fraction < 1.0):
            raise ConfigError(
                "need 0 < breakaway_pace <= 1 and 0 <= breakaway_fraction < 1, got "
                f"{self.breakaway_pace}, {self.breakaway_fraction}"
            )
        if not (0.0 < self.careful_pace <= 1.0 and 0.0 < self.press_pace <= 1.0):
            raise ConfigError(
                f"need 0 < careful_pace <= 1 and 0 < press_pace <= 1, got {self.careful_pace}, {self.press_pace}"
            )
        if not 0.0 < self.part_way_pace <= 1.0:
            raise ConfigError(f"need 0 < part_way_pace <= 1, got {self.part_way_pace}")


@dataclass(frozen=True)
class JudgementConfig:
    """What the readings of a try mean: moved, held (a lock) or neither."""

    push_force: float = 5.0
    """A part that ends without progress after being pulled with at least this force is latched [N]."""
    blocked_force: float = 20.0
    """Force opposing the motion that, with little progress, means a latch [N]."""
    blocked_progress: float = 0.10
    """Progress (fraction of the travel) below which a large opposing force means a latch."""
    blocked_magnitude: float = 35.0
    """Force magnitude (any direction) that, with little progress, also means a latch [N]: a latched wheel
    or a part pulled along a slightly wrong direction loads the grasp sideways more than along the path."""
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
    stall_progress: float = 0.01
    """Least progress (fraction of the travel) over ``stall_window`` of a part that has not stalled: a free part
    covers ~2 % in that time; a slide met by a pin crept 0.6 % in 0.15 s as the load rose 10 N a tick."""
    stall_window: float = 0.05
    """Time over which a stall is measured [s] (longer by :attr:`ForceWatch.slowdown` with the motions)."""
    end_stop_force: float = 20.0
    """Filtered force magnitude past the travel that tells a pinched door has reached its end stop [N] (a
    lagging handle pressed into it loads the grasp with 20-30 N, one that follows closely 47 N; weak pads
    dragging a door still short of it, 12-15 N): a door not felt there is pushed on (``push.top_up``)."""
    moved_fraction: float = 0.75
    """Progress that counts as reaching the other state (fraction of the travel: the twin's hysteresis threshold)."""
    empty_grasp_closure: float = 0.95
    """Gripper closure at or above which nothing is between the fingers."""
    slip_closure_rise: float = 0.012
    """Rise of the gripper closure within :attr:`slip_window` that means the handle left the fingers [-]:
    a lost handle lets the fingers close 0.02 within ~0.2 s (slowly at a reduced grip force, so
    :attr:`empty_grasp_closure` came seconds late), while a held one creeps steadily, 0.003 per 0.25 s at
    the harsh 10 N grip, up to 0.02 over a whole toggle (a rise over the grasp's closure misread that)."""
    slip_window: float = 0.25
    """Time over which the closure's rise is measured [s]."""


@dataclass(frozen=True)
class RetreatConfig:
    """How the gripper lets go and leaves: the release, the lift clear of the part and the way back to rest."""

    retreat_time: float = 0.8
    """Time of each straight move of the retreat: up off a handle, out from the base, above a part [s]."""
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
    :attr:`ForceWatch.slowdown`: the servo alone snaps the fingers open at ~2/s, and an inner knuckle swinging out
    under the plate of an open door (one the world did not count as standing over the part) met it with 38 N in
    one tick and 93 N before the late, filtered reading passed the guard (paper-test-2, harsh; 34 N ramped)."""
    lift_time: float = 0.8
    """Time to lift the TCP to ``transit_height`` before going to rest [s]."""
    rest_time: float = 1.5
    """Time to return to the rest posture after a toggle [s]: out of the overview camera's view, and
    every toggle starts from the same arm configuration."""


@dataclass(frozen=True)
class DoorPushPlan:
    """Where and how fast a pad pushes a door: the geometry of the xArm gripper's pads on a handle and plate."""

    pad_offset: float = 0.021
    """Inner face of a finger pad from the TCP, along the closing axis, at ``pregrasp_closure`` [m] (the
    xArm gripper's pads are 4 mm thick, 42 mm apart there)."""
    gap: float = 0.006
    """Clearance between the pad and the handle's back face at the end of the descent [m]: the perceived
    handle may be a few mm off; less and the pad could land on the post."""
    approach_time: float = 0.5
    """Time over which the pad closes the gap and presses on [s]: jumped onto the face at once, the impact
    read 31 N, past ``blocked_force``, on a free door."""
    depth: float = 0.003
    """How far past the back face the pad's target is pressed, along the whole push [m]: the preload that
    keeps the pad on the face."""
    pad_half_width: float = 0.015
    """Half the width of a finger pad along the gripper's x (perpendicular to closing) [m]: its edge pushes a
    door closed."""
    close_x: float = 0.075
    """Where on the plate, from the hinge, the pad edges push a door closed [m]: the pads reach back 30 mm
    from there, straddling the handle (64-76 mm); the longer the lever, the softer a door held open feels
    (at 45 mm a jammed door put 170 N on the wrist before the guard could stop the arm)."""
    close_time: float = 4.0
    """Time of a closing push [s] (~30 mm/s at the pads)."""
    search_speed: float = 0.010
    """Speed of the pads along the arc while they search for the plate of a door that may stand below its stop
    [m/s]: a harsh door latched open at 71.5 deg, met at the schedule's ~40 mm/s, put 99 N on the wrist before
    the late reading passed ``blocked_force``; its progress, counted from where the pads began rather than
    where they first pressed, had also passed ``blocked_progress``, so no latch was read. At 15 mm/s one
    latched at 84 deg loaded the pads by 5 N per tick, and the harsh reading (30 ms late) caught it at 62 N.
    A door believed open may stand anywhere: short of its stop it sinks under its own weight (66 deg within
    45 s), a latch holds it wherever it was when engaged, and one that fell shut is only met on the lid; until
    the pads have pressed on the plate, a closing push moves at this speed all the way (searching down to 50
    deg only, the pads met a door fallen shut at ~40 mm/s with 72 N)."""
    press_speed: float = 0.004
    """Speed of the pads along the arc once they press on the plate, until the door has followed them by
    ``blocked_progress`` of its travel (:meth:`DoorPusher.push_closed`) [m/s]: a door held open by its
    locker rests on the lock's pin (it sinks onto it under its own weight), and the pads, pressed into a plate that
    does not give, load the wrist by the arm's stiffness (15-35 N/mm) times their speed while the harsh reading is
    ~60 ms late. Sped up to the schedule's pace as the contact was felt, a door held at 61 deg put 56-104 N true on
    the wrist before the latch was read (hard-chain8-s36004 seed 36101; a door-slide chain, seed 1); at
    ``search_speed`` on, 44 N, most of it the arm's lag behind its command (~1.5 mm at ``search_speed``), which is
    why the command is first sent back to where the pads are; then, at this speed, 28-30 N."""
    height: float = 0.020
    """Height of the pushed point above the door's plate when the push begins [m]: low on the 35 mm post, so
    a pad that slides up a latched door's face (``lead``, plus the TCP's few mm of bias) stays on it."""
    climb: float = 0.008
    """How far the pad climbs the handle's face over the first ``climb_time`` of the push [m]. Sliding up
    the face, its friction lifts the door; held still by friction on a face that must rise as the door turns,
    it pulls the door shut with a lever (~76 mm) that outweighs the push's (~15 mm) once mu > 0.2: at the
    realistic pad mu of 0.16-0.24, free doors locked at 30-50 N."""
    climb_time: float = 1.0
    """Time over which the pad climbs [s] (whether or not the door turns: a lock would hold the pad still)."""
    lead: float = 0.010
    """As the pinch's ``lead``, for a push [m]: the pad slides along a latched face by about this much, not
    over it."""
    overtravel: float = 0.06
    """As the pinch's ``door_overtravel``, for a push (fraction of the travel): a pushed door follows the pad."""
    start_margin: float = 0.035
    """How far behind a door's seen angle a push after a pinch that lost its hold starts (fraction of the
    travel, 3 deg): a door let go part-way open falls back ~1 deg while the arm comes round. Behind the
    handle's true angle the pad sits higher on the post (~1.7 mm per deg, 15 mm of post above it); ahead of
    it, lower, towards the plate, and the other finger onto the raised handle."""


@dataclass(frozen=True)
class DoorPushJudgement:
    """What a push's readings mean: touching, sliding along a held handle, held, at the end stop."""

    contact_force: float = 3.0
    """Normal force on the handle's back face that means the pad is pressing on it [N] (10 sigma of the harsh
    F/T noise; a light free door may turn before it is felt: then no slide test is needed)..."""
    contact_noise_margin: float = 3.0
    """... or this many times the noise of the filtered force (:meth:`ForceWatch.filtered_noise_now`), if larger:
    at 15 N of F/T noise the noise alone passed 3 N before the pads met a door latched open, its push was then
    counted from there and had gone past ``blocked_progress`` when the plate pressed back (64 N)."""
    slide_turn: float = math.radians(7.0)
    """Turn of the pad since it first pressed after which a face that turned less than half as much means
    the pad is sliding along a latched handle [rad] (a jammed door: the pad slid ~12 deg and over the post)."""
    held_turn: float = math.radians(3.0)
    """Turn of the pad, pressed all the while, over which a face that had turned with it and now turns less than
    half as much means the door is held part-way [rad]: a lock's rod meets its wall past the closed band
    (``models.lock_mechanisms``), and a door carried there stood at 25 % while the pad slid 7 deg up its face
    with the load rising 5-22 N, then slipped over the post (read as a push short of the travel, and tried again
    and again)."""
    end_force: float = 20.0
    """Force magnitude at which a door pushed most of the way closed is taken to lie on the lid and the push
    stops there [N] (pressed on by a TCP a few mm off, the lid put 80-130 N on the wrist)."""
    blocked_force: float = 30.0
    """Normal force on a handle's back face that, with little progress, means a latch [N] (a free door
    under the harsh profile's damping and friction took up to 13 N)."""
    jam_force: float = 20.0
    """Normal force on the back face that, with little progress, ends a push from part-way (a door that stood
    past ``blocked_progress``: ``jammed``, no evidence) [N]. The pad meets a door held there (a pinch lost it at
    its lock's wall) with the door already still: the true load rose 0 -> 44 N in three 10 ms ticks while the
    filtered reading (~30 ms late) showed 7 N, and at ``blocked_force`` each push put 45-46 N on the wrist
    (paper-test-1 seed 87038, realistic). A free door pushed on from part-way takes under half of it."""


@dataclass(frozen=True)
class TopUpPlan:
    """The push on up under a door's plate that finishes a door left short of its end stop."""

    top_up_from: float = math.radians(50.0)
    """Lowest door angle a top-up push (:meth:`DoorPusher.top_up`) is placed for [rad]: a pinch that
    carried its fingers past ``moved_fraction`` left the door above it (the handle lags the fingers by up to a
    quarter of their turn)."""
    top_up_height: float = 0.055
    """Height of the TCP above the hinge line during a top-up push [m]: the plate's underside is there at 50
    deg only 9 mm short of its free edge, and the pads pass 15 mm above a neighbouring handle's top."""
    top_up_low: float = 0.045
    """Height above the hinge line the pads dive to as they move in, once their outer edge is over the door's
    own footprint (``top_up_dive`` in from where they descended) [m]: at ``top_up_height`` a door at 49 deg
    has its plate's free edge 6 mm above the pads' lower edge, which then pressed on the edge's end face, along
    the plate into the hinge (90 N); 10 mm lower they meet the edge side-on and turn the door up."""
    top_up_dive: float = 0.015
    """How far in from where they descended the pads reach ``top_up_low`` [m]: their 30 mm are then inside
    the door's closed footprint (81 mm from the hinge), clear of any neighbour."""
    top_up_clearance: float = 0.010
    """Clearance between the pads' edge and the plate's top corner at ``top_up_from`` as the pads descend [m]."""
    top_up_speed: float = 0.010
    """Speed of the pads' edge towards the hinge during a top-up push, constant from outside the plate's reach
    to its end stop [m/s]: wherever the door stands it may be held there (by a lock's latch, a jam) or already
    in its stop, and pressed on, the force builds by the arm's stiffness times this speed every tick while the
    harsh reading is ~60 ms late (F/T delay, the running median, the command latency). Eased in and out over
    4.5 s (20 mm/s at the middle), a door held at 64 deg put 48 N on the wrist and one in its stop 40-50 N
    before the late reading passed ``blocked_magnitude``. At the pads' ``top_up_low`` a damped door turns ~1.5
    times as fast for the same pad speed as at ``top_up_height``, and presses back over a shorter lever (in
    3 s: 61-66 N on harsh doors)."""
    top_up_force: float = 15.0
    """Force magnitude that ends a top-up push wherever the pads are [N]: the plate is held there, or in its
    end stop. A free door at 64 deg turned at ``top_up_speed`` under the harsh profile's draws (damping,
    friction, mass) pressed back with up to 12 N (12 draws). Stopped here, a door held at 56-72 deg or in its
    stop took 18-24 N true under the harsh reading, against 40-50 N at ``blocked_magnitude``..."""
    top_up_noise_margin: float = 5.0
    """... plus this many times the noise of the filtered force (:meth:`ForceWatch.filtered_noise_now`, per axis:
    its magnitude over three axes reaches ~5 times it), up to ``blocked_magnitude``."""


@dataclass(frozen=True)
class DoorPushConfig:
    """How a door is pushed (:mod:`skills.door_push`): the pads' plan, what the readings mean, the top-up, and when."""

    plan: DoorPushPlan = field(default_factory=DoorPushPlan)
    judgement: DoorPushJudgement = field(default_factory=DoorPushJudgement)
    top_up_plan: TopUpPlan = field(default_factory=TopUpPlan)
    close_by_push: bool = True
    """Shut a door by pushing its plate down (:meth:`DoorPusher.push_closed`), not by pinching its
    handle: pinched shut, the handle pivots ~85 deg between the pads against their torsional friction, and
    under the harsh grip it lagged the fingers by 7 deg, the wrist force rising to 33 N and then released
    in a stick-slip jolt of 70 N. Pushed, the pads move into the plate and need no friction."""
    top_up: bool = True
    """Push on to the end stop a door a pinch opened without feeling the stop (:meth:`DoorPusher.top_up`)."""

    def changed(self, **settings: Any) -> DoorPushConfig:
        """This config with the named settings changed, each by its own name whatever its part."""
        return _changed(self, _DOOR_PART_OF, settings)


@dataclass(frozen=True)
class PrimitiveConfig:
    """Timing and thresholds of a toggle, by phase (see the module docstring)."""

    motion: MotionConfig = field(default_factory=MotionConfig)
    sensing: SensingConfig = field(default_factory=SensingConfig)
    approach: ApproachConfig = field(default_factory=ApproachConfig)
    grasp: GraspConfig = field(default_factory=GraspConfig)
    actuation: ActuationConfig = field(default_factory=ActuationConfig)
    judgement: JudgementConfig = field(default_factory=JudgementConfig)
    retreat: RetreatConfig = field(default_factory=RetreatConfig)
    door_push: bool = True
    """Push a door (:mod:`skills.door_push`) when pinching its handle failed for want of a hold
    (:data:`PADS_LOST_HOLD`): a pinched post moves the door by pad friction alone, which a weak grip does not
    give. Not first: with grippy pads (mu above ~0.2) the pad's friction on the pushed face can lock the push
    (realistic profile, pushing first: 98.3 % solved in 5.57 actions against 100 % in 5.18)."""
    push: DoorPushConfig = field(default_factory=DoorPushConfig)
    """How doors are pushed (:mod:`skills.door_push`)."""

    @classmethod
    def of(cls, **settings: Any) -> PrimitiveConfig:
        """The defaults with the named settings changed (each by its own name, whatever its phase:
        ``PrimitiveConfig.of(force_limit=45.0, rest_time=2.0)``)."""
        return cls().changed(**settings)

    @classmethod
    def for_cell(cls, cell: CellConfig, **overrides: Any) -> PrimitiveConfig:
        """The primitives of a cell: its force limit and blocked threshold [N] (the rest as given, or the
        defaults, which are the twin's)."""
        return cls.of(**{"force_limit": cell.force_limit, "blocked_force": cell.blocked_force, **overrides})

    def changed(self, **settings: Any) -> PrimitiveConfig:
        """This config with the named settings changed, each by its own name whatever its phase (a door's push
        settings through ``push=config.push.changed(...)``); :class:`ConfigError` names one that does not exist."""
        return _changed(self, _PHASE_OF, settings)

    def flat(self) -> dict[str, Any]:
        """Every setting by its own name, the door's push settings as ``push.<name>``."""
        out = _flat(self)
        push = out.pop("push")
        return out | {f"push.{name}": value for name, value in _flat(push).items()}

    def __post_init__(self) -> None:
        s, j, a, r, m, ap = self.sensing, self.judgement, self.actuation, self.retreat, self.motion, self.approach
        if not 0.0 < j.blocked_force < j.blocked_magnitude < s.force_limit:
            raise ConfigError(
                "need 0 < blocked_force < blocked_magnitude < force_limit [N], got "
                f"{j.blocked_force}, {j.blocked_magnitude}, {s.force_limit}"
            )
        if not 0.0 < r.lift_contact_force < s.force_limit or min(r.lift_noise_margin, r.lift_sidestep) < 0:
            raise ConfigError(
                "need 0 < lift_contact_force < force_limit [N] and lift_noise_margin, lift_sidestep [m] >= 0, got "
                f"{r.lift_contact_force}, {s.force_limit}, {r.lift_noise_margin}, {r.lift_sidestep}"
            )
        if r.lift_slow_height < 0.0 or r.lift_slow_time < m.tick:
            raise ConfigError(
                f"need lift_slow_height >= 0 [m] and lift_slow_time >= tick [s], got {r.lift_slow_height}, "
                f"{r.lift_slow_time}"
            )
        if r.gentle_release_speed <= 0.0 or min(ap.base_radius, ap.base_rise) < 0.0:
            raise ConfigError(
                "need gentle_release_speed > 0 [1/s] and base_radius, base_rise >= 0 [m], got "
                f"{r.gentle_release_speed}, {ap.base_radius}, {ap.base_rise}"
            )
        if not (0.0 < j.stall_force < s.force_limit and j.stall_progress >= 0.0 and j.stall_window > 0.0):
            raise ConfigError(
                "need 0 < stall_force < force_limit [N], stall_progress >= 0 and stall_window > 0 [s], got "
                f"{j.stall_force}, {j.stall_progress}, {j.stall_window}"
            )
        if not j.blocked_force < a.back_off_force <= s.force_limit:
            raise ConfigError(
                "need blocked_force < back_off_force <= force_limit [N], got "
                f"{j.blocked_force}, {a.back_off_force}, {s.force_limit}"
            )
        if j.press_force <= 0.0 or j.press_noise_margin < 0.0 or not 0.0 <= a.press_angle <= math.pi / 2:
            raise ConfigError(
                "need press_force > 0 [N], press_noise_margin >= 0 and 0 <= press_angle <= pi/2 [rad], got "
                f"{j.press_force}, {j.press_noise_margin}, {a.press_angle}"
            )
        if not 0.0 < ap.cautious_contact_force < s.force_limit:
            raise ConfigError(
                f"need 0 < cautious_contact_force < force_limit [N], got {ap.cautious_contact_force}, {s.force_limit}"
            )


PHASES: tuple[type, ...] = (
    MotionConfig, SensingConfig, ApproachConfig, GraspConfig, ActuationConfig, JudgementConfig, RetreatConfig,
)  # fmt: skip
"""The phase settings of :class:`PrimitiveConfig`, in the order of its fields."""
DOOR_PARTS: tuple[type, ...] = (DoorPushPlan, DoorPushJudgement, TopUpPlan)
"""The parts of :class:`DoorPushConfig`, in the order of its fields."""

_PHASE_OF: dict[str, str] = {
    "tick": "motion",
    "ik_iterations_per_tick": "motion",
    "settle_time": "motion",
    "release_time": "motion",
    "relieve_load": "motion",
    "relieve_distance": "motion",
    "transit_height": "motion",
    "transit_xy": "motion",
    "comply_gain": "motion",
    "comply_deadband": "motion",
    "comply_noise_margin": "motion",
    "comply_limit": "motion",
    "comply_return_time": "motion",
    "force_limit": "sensing",
    "noise_samples": "sensing",
    "force_filter_samples": "sensing",
    "force_filter_max_samples": "sensing",
    "filtered_noise": "sensing",
    "tare_noise": "sensing",
    "tare_max_samples": "sensing",
    "pregrasp_closure": "approach",
    "approach_height": "approach",
    "approach_time": "approach",
    "descend_time": "approach",
    "touch_height": "approach",
    "touch_speed": "approach",
    "cautious_descend_time": "approach",
    "cautious_contact_force": "approach",
    "cautious_noise_margin": "approach",
    "base_radius": "approach",
    "base_rise": "approach",
    "lean_angle": "approach",
    "close_time": "grasp",
    "close_speed": "grasp",
    "grasp_centre_force": "grasp",
    "grasp_centre_limit": "grasp",
    "actuate_time": "actuation",
    "breakaway_fraction": "actuation",
    "breakaway_pace": "actuation",
    "lead": "actuation",
    "door_overtravel": "actuation",
    "overtravel_comply": "actuation",
    "overtravel_force": "actuation",
    "press_pace": "actuation",
    "press_angle": "actuation",
    "back_off_force": "actuation",
    "careful_pace": "actuation",
    "part_way_pace": "actuation",
    "moved_fraction": "judgement",
    "blocked_progress": "judgement",
    "push_force": "judgement",
    "blocked_force": "judgement",
    "blocked_magnitude": "judgement",
    "stall_force": "judgement",
    "stall_progress": "judgement",
    "stall_window": "judgement",
    "press_force": "judgement",
    "press_noise_margin": "judgement",
    "end_stop_force": "judgement",
    "empty_grasp_closure": "judgement",
    "slip_closure_rise": "judgement",
    "slip_window": "judgement",
    "retreat_time": "retreat",
    "gentle_release_speed": "retreat",
    "lift_contact_force": "retreat",
    "lift_noise_margin": "retreat",
    "lift_slow_height": "retreat",
    "lift_slow_time": "retreat",
    "lift_sidestep": "retreat",
    "lift_time": "retreat",
    "rest_time": "retreat",
}
"""Which phase of :class:`PrimitiveConfig` holds each setting."""
_DOOR_PART_OF: dict[str, str] = {
    "pad_offset": "plan",
    "gap": "plan",
    "approach_time": "plan",
    "depth": "plan",
    "pad_half_width": "plan",
    "close_x": "plan",
    "close_time": "plan",
    "search_speed": "plan",
    "press_speed": "plan",
    "height": "plan",
    "climb": "plan",
    "climb_time": "plan",
    "lead": "plan",
    "overtravel": "plan",
    "start_margin": "plan",
    "contact_force": "judgement",
    "contact_noise_margin": "judgement",
    "slide_turn": "judgement",
    "held_turn": "judgement",
    "end_force": "judgement",
    "blocked_force": "judgement",
    "jam_force": "judgement",
    "top_up_from": "top_up_plan",
    "top_up_height": "top_up_plan",
    "top_up_low": "top_up_plan",
    "top_up_dive": "top_up_plan",
    "top_up_clearance": "top_up_plan",
    "top_up_speed": "top_up_plan",
    "top_up_force": "top_up_plan",
    "top_up_noise_margin": "top_up_plan",
}
"""Which part of :class:`DoorPushConfig` holds each of its settings."""


def _changed(config: Any, part_of: dict[str, str], settings: dict[str, Any]) -> Any:
    """``config`` (a composite of frozen parts) with ``settings`` changed, each routed to the part ``part_of`` names
    (its own fields by their names)."""
    own = {f.name for f in dataclasses.fields(config)}
    unknown = sorted(set(settings) - set(part_of) - own)
    if unknown:
        known = sorted({*part_of, *own} - set(part_of.values()))
        raise ConfigError(f"no setting named {unknown} in {type(config).__name__}; the settings are {known}")
    parts: dict[str, dict[str, Any]] = {}
    for name, value in settings.items():
        if name in part_of:
            parts.setdefault(part_of[name], {})[name] = value
    kept = {k: v for k, v in settings.items() if k in own}
    return dataclasses.replace(
        config, **kept, **{p: dataclasses.replace(getattr(config, p), **v) for p, v in parts.items()}
    )


def _flat(config: Any) -> dict[str, Any]:
    """The fields of ``config``, those of its parts (but not of a nested composite) by their own names."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(config):
        value = getattr(config, f.name)
        if f.name == "push" or not dataclasses.is_dataclass(value):
            out[f.name] = value
        else:
            out |= {g.name: getattr(value, g.name) for g in dataclasses.fields(value)}
    return out


__all__ = [
    "ActuationConfig",
    "ApproachConfig",
    "DOOR_PARTS",
    "DoorPushConfig",
    "DoorPushJudgement",
    "DoorPushPlan",
    "GraspConfig",
    "JudgementConfig",
    "MotionConfig",
    "PHASES",
    "PrimitiveConfig",
    "RetreatConfig",
    "SensingConfig",
    "TARE_SAMPLES",
    "TopUpPlan",
]
