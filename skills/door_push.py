"""Pushing a door: a finger pad against the back of its handle, along the door's arc (and the pads' edges on
its plate to shut it) — the geometry, its configuration and the motions.

A door's handle moves along its own post as the door swings (the post stands on the plate, the plate turns
about the hinge), so fingers that pinch the post lift the door by friction alone: with a weak grip (10 N,
pad mu 0.25: the harsh profile) the pads slid up off the post in 12 of 60 trials. Pushed instead, the post's
back face (the side away from the hinge) takes the pad's normal force, whose lever about the hinge is the
contact's height above it: no friction needed, whatever the grip.

All vectors are in the robot base frame [m]. The *door frame* here has its origin on the hinge axis below
the handle, ``e_x`` from the hinge towards the handle (horizontal when closed), ``e_z = axis x e_x`` (up
when closed); opening turns ``e_x`` towards ``e_z`` by the door angle.
"""

from __future__ import annotations

import collections
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from puzzlebox.models.kinds import HANDLE_HEIGHT, HANDLE_MARGIN, HANDLE_SIZE
from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.errors import IKFailure
from puzzlebox.skills.joint_model import GRASP_DEPTH, JointModel, cross
from puzzlebox.skills.kinematics import ArmKinematics, top_down
from puzzlebox.skills.pacing import Pacing
from puzzlebox.skills.toggle_result import HELD_PART_WAY, LATCHED, ToggleResult

if TYPE_CHECKING:
    from puzzlebox.models.robot import Robot

PUSHED_IN_VAIN = LATCHED[Cause.LOCKED_PUSHED]


@dataclass(frozen=True)
class DoorPushConfig:
    """How a door is pushed (geometry of the xArm gripper's pads, forces, times)."""

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
    contact_force: float = 3.0
    """Normal force on the handle's back face that means the pad is pressing on it [N] (10 sigma of the harsh
    F/T noise; a light free door may turn before it is felt: then no slide test is needed)..."""
    contact_noise_margin: float = 3.0
    """... or this many times the noise of the filtered force (:meth:`Toggler.filtered_noise_now`), if larger:
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
    ``blocked_progress`` of its travel (:meth:`DoorPushing._push_door_closed`) [m/s]: a door held open by its
    locker rests on the lock's pin (it sinks onto it under its own weight), and the pads, pressed into a plate that
    does not give, load the wrist by the arm's stiffness (15-35 N/mm) times their speed while the harsh reading is
    ~60 ms late. Sped up to the schedule's pace as the contact was felt, a door held at 61 deg put 56-104 N true on
    the wrist before the latch was read (hard-chain8-s36004 seed 36101; a door-slide chain, seed 1); at
    ``search_speed`` on, 44 N, most of it the arm's lag behind its command (~1.5 mm at ``search_speed``), which is
    why the command is first sent back to where the pads are; then, at this speed, 28-30 N."""
    end_force: float = 20.0
    """Force magnitude at which a door pushed most of the way closed is taken to lie on the lid and the push
    stops there [N] (pressed on by a TCP a few mm off, the lid put 80-130 N on the wrist)."""
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
    close_by_push: bool = True
    """Shut a door by pushing its plate down (:meth:`DoorPushing._push_door_closed`), not by pinching its
    handle: pinched shut, the handle pivots ~85 deg between the pads against their torsional friction, and
    under the harsh grip it lagged the fingers by 7 deg, the wrist force rising to 33 N and then released
    in a stick-slip jolt of 70 N. Pushed, the pads move into the plate and need no friction."""
    top_up: bool = True
    """Push on to the end stop a door a pinch opened without feeling the stop (:meth:`DoorPushing._top_up_door`)."""
    top_up_from: float = math.radians(50.0)
    """Lowest door angle a top-up push (:meth:`DoorPushing._top_up_door`) is placed for [rad]: a pinch that
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
    """... plus this many times the noise of the filtered force (:meth:`Toggler.filtered_noise_now`, per axis:
    its magnitude over three axes reaches ~5 times it), up to ``blocked_magnitude``."""
    blocked_force: float = 30.0
    """Normal force on a handle's back face that, with little progress, means a latch [N] (a free door
    under the harsh profile's damping and friction took up to 13 N)."""


@dataclass(frozen=True)
class DoorPush:
    """A door as a pusher sees it: the hinge and the contact point on the back face of its handle."""

    origin: np.ndarray
    """The point of the hinge axis below the handle [m]."""
    axis: np.ndarray
    """Unit hinge axis: turning about it by a positive angle opens the door."""
    e_x: np.ndarray
    """Unit vector from the hinge towards the handle, door closed (horizontal)."""
    e_z: np.ndarray
    """``axis x e_x``: the door's normal, door closed (up)."""
    contact: np.ndarray
    """The pushed point of the handle's back face in door coordinates ``(x, z)`` [m]."""
    travel: float
    """The door's travel [rad]."""
    plate_top: float
    """Height of the plate's top face above the hinge axis, in door coordinates [m]."""

    @classmethod
    def of(cls, jm: JointModel, height: float) -> DoorPush:
        """The push geometry of door joint model ``jm``, pushed ``height`` above its plate [m]."""
        r = jm.grasp_point - jm.origin
        r_perp = r - np.dot(r, jm.axis) * jm.axis
        along = r_perp - r_perp[2] * np.array([0.0, 0.0, 1.0])  # the closed plate lies level: e_x is horizontal
        e_x = along / np.linalg.norm(along)
        e_z = cross(jm.axis, e_x)
        origin = jm.origin + np.dot(r, jm.axis) * jm.axis
        plate_top = np.dot(r_perp, e_z) - (HANDLE_HEIGHT - GRASP_DEPTH)  # the grasp point is on the post
        contact = np.array([np.dot(r_perp, e_x) + HANDLE_SIZE / 2, plate_top + height])
        return cls(origin, jm.axis.copy(), e_x, e_z, contact, jm.travel, plate_top)

    def point_at(self, angle: float, door_xz: np.ndarray) -> np.ndarray:
        """Where door point ``door_xz`` (door coordinates) is with the door open by ``angle`` [rad] [m]."""
        c, s = math.cos(angle), math.sin(angle)
        x, z = door_xz
        return self.origin + (x * c - z * s) * self.e_x + (x * s + z * c) * self.e_z

    def face_normal(self, angle: float) -> np.ndarray:
        """Outward normal of the handle's back face with the door open by ``angle`` [rad]."""
        return math.cos(angle) * self.e_x + math.sin(angle) * self.e_z

    def motion_direction(self, angle: float) -> np.ndarray:
        """Unit direction in which the contact point moves as the door opens, at ``angle`` [rad]."""
        p = self.point_at(angle, self.contact) - self.origin
        tangent = cross(self.axis, p)
        return tangent / math.sqrt(tangent @ tangent)

    def turn_of(self, point: np.ndarray) -> float:
        """Angle of ``point`` about the hinge, from ``e_x`` towards ``e_z`` [rad]."""
        d = point - self.origin
        return math.atan2(float(d @ self.e_z), float(d @ self.e_x))

    def angle_from_contact(self, point: np.ndarray) -> float:
        """The door angle [rad] at which the handle's back face passes through ``point`` (a pad edge resting
        on it): the smaller root of ``a cos t + b sin t = x_face``. A pad that slides along a face that does
        not turn (a latched door) measures no angle, however far it slides."""
        d = point - self.origin
        a, b = float(d @ self.e_x), float(d @ self.e_z)
        radius = math.hypot(a, b)
        if radius <= 1e-9:
            return 0.0
        return math.atan2(b, a) - math.acos(max(-1.0, min(1.0, self.contact[0] / radius)))


class PushingConfig(Protocol):
    """What the pushes read of the toggler's config (:class:`skills.primitives.PrimitiveConfig`, which this
    module cannot import: it imports this one)."""

    @property
    def push(self) -> DoorPushConfig: ...
    @property
    def tick(self) -> float: ...
    @property
    def settle_time(self) -> float: ...
    @property
    def actuate_time(self) -> float: ...
    @property
    def release_time(self) -> float: ...
    @property
    def breakaway_fraction(self) -> float: ...
    @property
    def breakaway_pace(self) -> float: ...
    @property
    def moved_fraction(self) -> float: ...
    @property
    def blocked_progress(self) -> float: ...
    @property
    def blocked_force(self) -> float: ...
    @property
    def blocked_magnitude(self) -> float: ...
    @property
    def overtravel_force(self) -> float: ...
    @property
    def stall_force(self) -> float: ...
    @property
    def stall_progress(self) -> float: ...
    @property
    def stall_window(self) -> float: ...


class DoorPushing:
    """The door pushes of :class:`skills.primitives.Toggler` (a mixin: it moves through the toggler's own
    ticks, force guard and retreat, and reads ``config.push``)."""

    # What the pushes use of the toggler, declared for type checkers (Toggler sets and defines them).
    config: PushingConfig
    robot: Robot
    ik: ArmKinematics
    force_in_base: np.ndarray
    slowdown: float
    phase: str
    progress: float
    cautious: bool

    if TYPE_CHECKING:

        def grasp_yaw(self, jm: JointModel) -> float: ...
        def filtered_noise_now(self) -> float: ...
        def move_to(self, target: np.ndarray, duration: float) -> None: ...
        def _tick(self, target: np.ndarray) -> tuple[float, float]: ...
        def _descend_to(self, target: np.ndarray) -> None: ...
        def _let_go_and_retreat(self, guarded: bool = True) -> None: ...
        def _verdict(self, progress: float, forces: list[float], latched: Cause | None = None) -> ToggleResult: ...

    def _push_door_open(self, jm: JointModel, start: float = 0.0) -> ToggleResult:
        """Open a door by pushing the back face of its handle with the inner face of a finger pad (see
        :mod:`skills.door_push`): descend behind the handle, then swing the pad along the door's arc,
        ``depth`` into the face, measuring the door's angle from where the pad rests on the face (the
        command runs at most ``lead`` ahead of it, so on a latched door the pad slides a few mm up the
        face and presses, never over the post). ``start`` is the fraction of the travel at which the door
        stands (a pinch that slipped part-way left it there): the pad descends behind the handle there
        (descending behind the closed pose of a door left at 43 deg, it landed on the raised post at
        60-100 N)."""
        c = self.config
        p = c.push
        door = DoorPush.of(jm, p.height)
        yaw = float(np.arctan2(door.e_x[1], door.e_x[0]) + np.pi / 2)  # the gripper's y axis (closing) = e_x

        def tcp_for(pad_edge: np.ndarray) -> np.ndarray:
            return top_down(pad_edge - p.pad_offset * door.e_x, yaw)

        self._descend_to(tcp_for(door.point_at(start * door.travel, door.contact + np.array([p.gap, 0.0]))))
        self.phase = "actuating"
        result = self._swing_door(door, tcp_for, start)
        self.phase = "retreating"
        self._let_go_and_retreat()
        self.phase = "moving"
        return result

    def _push_door_closed(self, jm: JointModel, start: float = 0.0) -> ToggleResult:
        """Close a door by pushing its plate down with the edges of both finger pads, the fingers straddling
        the handle (they close along the hinge): the pads' outer edge (``pad_half_width`` along the
        gripper's x = the door's ``e_x``) rests on the plate's top face ``close_x`` from the hinge and
        follows it down its arc. Closing, the pad moves into the face, not along it: a door held open
        presses back at once, and no friction is needed to carry a free one. ``start`` is the fraction of
        the closing travel already covered (by a pinch that slipped part-way)."""
        c = self.config
        p = c.push
        door = DoorPush.of(jm, p.height)
        yaw = self.grasp_yaw(jm)  # fingers along the hinge: the gripper's x is the door's e_x
        on_plate = np.array([p.close_x, door.plate_top - p.depth])

        def tcp_for(edge: np.ndarray) -> np.ndarray:
            return top_down(edge - p.pad_half_width * door.e_x, yaw)

        above_plate = on_plate + np.array([0.0, p.depth + p.gap])
        self._descend_to(tcp_for(door.point_at((1.0 - start) * door.travel, above_plate)))

        self.phase = "actuating"
        lead = p.lead / (door.travel * p.close_x)
        end = 1.0  # closed
        ticks = round(p.close_time * self.slowdown / c.tick)
        contact = max(p.contact_force, p.contact_noise_margin * self.filtered_noise_now())
        per_tick = c.tick / (self.slowdown * door.travel * p.close_x)  # of the travel per tick, for 1 m/s at the pads

        def scheduled(k: float) -> float:  # where the pads are sent at (schedule) tick k: slow onto the lid
            u = min(1.0, k / ticks)
            return start + (end - start) * u * u * (3 - 2 * u)

        def schedule_at(s: float) -> float:  # the schedule tick at which the pads are sent to s: scheduled's inverse
            x = min(max((s - start) / (end - start), 0.0), 1.0) if end > start else 1.0
            return ticks * (0.5 - math.sin(math.asin(1.0 - 2.0 * x) / 3.0))  # the smoothstep's inverse

        # A command s sends the pads' edge to ``depth`` into the plate, and their progress is measured from where they
        # were first, ``gap`` above it: pads that follow the command exactly measure s + held_offset, so pads measured
        # at progress q are where the command q - held_offset sends them.
        held_offset = math.atan2(door.plate_top + p.gap, p.close_x) - math.atan2(door.plate_top - p.depth, p.close_x)
        held_offset /= door.travel

        forces: list[float] = []
        progress = 0.0
        pressed_from: float | None = None  # the progress at which the pads first pressed on the plate
        self.ik.set_joints(self.robot.joint_positions())
        turn_at_start = door.turn_of(self._pad_edge(door, p.pad_half_width))
        result = None
        k = 0
        schedule = 0.0  # the schedule's clock [ticks]: slowed while the pads search for the plate
        while schedule < ticks + round(2 * c.settle_time / c.tick):
            k += 1
            step = 1.0
            engaged = pressed_from is not None and progress - max(pressed_from, start) >= c.blocked_progress
            if not engaged:  # searching for the plate, or pressed on it but not yet seen to follow the pads
                nominal = scheduled(schedule + 1.0) - scheduled(schedule)
                speed = p.search_speed if pressed_from is None else p.press_speed
                step = min(1.0, speed * per_tick / nominal) if nominal > 0 else 1.0
            schedule += step
            s = min(scheduled(schedule), max(progress, start) + lead)
            closing_in = max(0.0, 1.0 - k * c.tick / (p.approach_time * self.slowdown)) * (p.gap + p.depth)
            self._tick(tcp_for(door.point_at((1.0 - s) * door.travel, on_plate + np.array([0.0, closing_in]))))
            turn = door.turn_of(self._pad_edge(door, p.pad_half_width))
            progress = self.progress = start + (turn_at_start - turn) / door.travel
            angle = (1.0 - max(progress, 0.0)) * door.travel
            forces.append(float(self.force_in_base @ door.motion_direction(angle)))  # opposing a closing motion
            magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
            if pressed_from is None and forces[-1] > contact:
                pressed_from = progress
                # the command runs the arm's tracking lag ahead of the pads (~1.5 mm at ``search_speed``): pressed
                # on a plate that does not give, it loads the wrist by the arm's stiffness times that lag whatever
                # is sent next, while the reading is late. Sent back to where the pads are, they press on from
                # there at ``press_speed``.
                schedule = min(schedule, schedule_at(progress - held_offset))
            if progress >= c.moved_fraction and magnitude > p.end_force:
                # the plate is on the lid: stop at once. (Easing on to where the pads were, a door that fell
                # shut and was met on the lid at 15 mm/s loaded the wrist by 5-8 N per tick to 71 N.)
                break
            pushed = progress - (start if pressed_from is None else max(pressed_from, start))
            # (a door that fell shut ahead of the pads is first pressed on the lid: closed, not latched)
            short = progress < c.moved_fraction and pushed < c.blocked_progress
            if short and (forces[-1] > c.blocked_force or magnitude > c.blocked_magnitude):
                result = ToggleResult("blocked", PUSHED_IN_VAIN, progress, max(forces),
                                      forces=forces, cause=Cause.LOCKED_PUSHED)  # fmt: skip
                break
        if result is None:
            result = self._verdict(progress, forces, Cause.LOCKED_PUSHED)
        # off the plate along its normal before letting go: held pressed on a latched plate (the command runs
        # ``lead`` into it) while the gripper opened, a harsh latch's play built 65 N on the wrist
        self._back_off(door, (1.0 - max(progress, 0.0)) * door.travel + math.pi / 2)
        self.phase = "retreating"
        self._let_go_and_retreat()
        self.phase = "moving"
        return result

    def _top_up_door(self, jm: JointModel) -> ToggleResult:
        """Push a door the pinch opened on to its end stop, under its plate: a handle that lags the fingers
        leaves the door short of the stop (78 deg under the harsh grip), and a door short of it sinks back
        under its own weight (to 66 deg within 45 s) over its neighbour's handle, onto which the next
        descent then lands (100-130 N). Where the door stands is not known (above ~50 deg its handle hides
        its marker), so the pads, fingers along the hinge, descend beside the plate outside its reach at any
        angle above ``top_up_from``, ``top_up_height`` above the hinge, and their inner edge moves in towards
        the hinge, diving to ``top_up_low`` once over the door's own footprint: it meets the plate's underside
        wherever the door stands and turns it up into its end stop. ``moved`` once the edge passed where the
        underside is at ``moved_fraction`` of the travel (a free door turns under less than 1 N: meeting the
        plate is not felt, so this cannot tell a door that was not there). The edge moves in at a constant
        ``top_up_speed`` and stops where the force passes ``top_up_force`` (and the noise's margin): wherever
        the plate is met it may be held there, or in its stop."""
        c = self.config
        p = c.push
        door = DoorPush.of(jm, p.height)
        yaw = self.grasp_yaw(jm)  # fingers along the hinge: the gripper's x is the door's e_x
        free_edge = door.contact[0] + HANDLE_MARGIN - HANDLE_SIZE / 2  # the plate's far edge from the hinge
        x_start = free_edge * math.cos(p.top_up_from) + p.top_up_clearance
        x_end = p.top_up_low / math.tan(door.travel) - p.depth  # where the underside meets the pads at the stop

        def height_at(edge_x: float) -> float:  # the pads' height above the hinge line with their edge at edge_x
            dive = min(max((x_start - edge_x) / p.top_up_dive, 0.0), 1.0)
            return p.top_up_height + (p.top_up_low - p.top_up_height) * dive

        def tcp_for(edge_x: float) -> np.ndarray:  # the TCP with the pads' inner edge at edge_x from the hinge
            return top_down(door.origin + (edge_x + p.pad_half_width) * door.e_x + height_at(edge_x) * door.e_z, yaw)

        cautious, self.cautious = self.cautious, True  # beside a door standing at an unknown angle
        try:
            self._descend_to(tcp_for(x_start))
        finally:
            self.cautious = cautious
        self.phase = "actuating"
        path = math.hypot(x_start - x_end, p.top_up_height - p.top_up_low)  # (the dive is part of the way)
        ticks = max(1, round(path / p.top_up_speed * self.slowdown / c.tick))
        stop = min(c.blocked_magnitude, p.top_up_force + p.top_up_noise_margin * self.filtered_noise_now())
        forces: list[float] = []
        edge_x = x_start
        self.ik.set_joints(self.robot.joint_positions())
        for k in range(1, ticks + round(c.settle_time / c.tick) + 1):
            self._tick(tcp_for(x_start + (x_end - x_start) * min(k / ticks, 1.0)))  # at a constant speed
            edge_x = float((self._pad_edge(door, -p.pad_half_width) - door.origin) @ door.e_x)
            forces.append(float(-self.force_in_base @ door.e_x))
            magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
            if magnitude > stop:
                break  # held where it stands, or in its end stop
        progress = math.atan2(height_at(edge_x), max(edge_x, 1e-6)) / door.travel  # the underside's angle there
        result = self._verdict(progress, forces)
        self._back_off(door, 0.0)  # off the plate (along e_x) before lifting
        self.phase = "retreating"
        self._let_go_and_retreat()
        self.phase = "moving"
        return result

    def _pad_edge(self, door: DoorPush, offset: float) -> np.ndarray:
        """The pushing pad edge, ``offset`` from the TCP along the door's ``e_x``, where the robot measures it [m]."""
        return self.robot.tcp_pose_in_base()[:3, 3] + offset * door.e_x

    def _swing_door(self, door: DoorPush, tcp_for, start: float = 0.0) -> ToggleResult:
        """Swing the pad along the door's arc from ``start`` (fraction of the travel) up to the end stop;
        decide moved, blocked or failed.

        Progress is the pad's own turn about the hinge since the swing began (well conditioned: a pad on a
        turning face turns with it). On a latched door the pad turns too, sliding up the face, until it
        slips over the post; what tells the two apart is the face: the angle at which the handle's back
        face passes through the pad (:meth:`DoorPush.angle_from_contact`) follows the pad's turn on a door
        that turns and stays put while the pad slides along a face that does not. Its offset (1 mm of
        perception error is ~3 deg here) cancels in its change since the pad first pressed on the face.
        A swing is only as far as the pad last pressed on the face: past it the pad is in the air (over the
        post of a latched door, within the slide test's turn; or past a door that was not where it was
        placed). The start of the travel, up to ``breakaway_fraction``, is swept at ``breakaway_pace`` as a
        pinch's is: at full pace a pad pressed on the post of a wheel told to be a door went from 10 to 65 N in
        40 ms, before the filtered reading (~40 ms late) showed any of it; at that pace it peaked at 40 N."""
        c = self.config
        p = c.push
        x = door.contact[0] - p.depth

        def pressed(k: int) -> np.ndarray:  # the pad's point on the door at tick k: climbing the face at first
            return np.array([x, door.contact[1] + p.climb * min(k * c.tick / (p.climb_time * self.slowdown), 1.0)])

        def climb_turn(k: int) -> float:  # what the climb alone adds to the pad's turn about the hinge [rad]
            return math.atan2(pressed(k)[1], x) - math.atan2(door.contact[1], x)

        lead = p.lead / (door.travel * float(np.hypot(*door.contact)))
        end = 1.0 + p.overtravel
        contact = max(p.contact_force, p.contact_noise_margin * self.filtered_noise_now())
        ticks = round(c.actuate_time * self.slowdown / c.tick)
        pace = (end - start) / ticks  # of the travel per tick, past the slow start
        slow_span = max(0.0, c.breakaway_fraction - start)  # the start of the travel, driven slowly as a pinch's
        pacing = Pacing(pace, pace * c.breakaway_pace, slow_span)  # slow start, then a ramp up
        last_tick = pacing.ticks_to(end - start)
        forces: list[float] = []
        progress = 0.0
        pressed_at: tuple[float, float] | None = None  # (progress, face angle) when the pad first pressed
        last_pressed, last_face = start, 0.0  # progress and face angle when the pad last pressed on the face
        track: collections.deque[tuple[float, float]] = collections.deque()  # (progress, face) pressed, in a row
        self.ik.set_joints(self.robot.joint_positions())
        turn_at_start = door.turn_of(self._pad_edge(door, p.pad_offset))
        for k in range(1, last_tick + 1 + round(2 * c.settle_time / c.tick)):
            paced = pacing.at(k)
            s = min(start + paced, end, max(progress, start) + lead)
            closing_in = max(0.0, 1.0 - k * c.tick / (p.approach_time * self.slowdown)) * (p.gap + p.depth)
            self._tick(tcp_for(door.point_at(s * door.travel, pressed(k) + np.array([closing_in, 0.0]))))
            pad_edge = self._pad_edge(door, p.pad_offset)
            progress = self.progress = start + (door.turn_of(pad_edge) - turn_at_start - climb_turn(k)) / door.travel
            angle = max(progress, 0.0) * door.travel
            normal = float(self.force_in_base @ door.face_normal(angle))
            forces.append(float(-self.force_in_base @ door.motion_direction(angle)))
            magnitude = math.sqrt(self.force_in_base @ self.force_in_base)  # np.linalg.norm, bit for bit
            if s > 1.0 and magnitude > c.overtravel_force:  # in the end stop: stop here
                end = max(1.0, min(progress, s))
            face = door.angle_from_contact(pad_edge) / door.travel
            if normal > contact:
                last_pressed, last_face = progress, face
                if pressed_at is None:
                    pressed_at = (progress, face)
                track.append((progress, face))
            else:
                track.clear()  # (the turn over which the pad slid is measured pressed all the while)
            held = (
                len(track) > 0
                and pressed_at is not None
                and self._held_part_way(track, pressed_at[1], p.held_turn / door.travel, normal)
            )
            if held:
                self._back_off(door, angle)
                return ToggleResult("blocked", f"{HELD_PART_WAY} ({face:.0%} of the travel)", progress, max(forces),
                                    forces=forces, cause=Cause.HELD_PART_WAY, held_at=face)  # fmt: skip
            slid = pressed_at is not None and progress - pressed_at[0] >= p.slide_turn / door.travel
            if slid and pressed_at is not None and face - pressed_at[1] < 0.5 * (progress - pressed_at[0]):
                self._back_off(door, angle)
                if start >= c.blocked_progress:  # a door held part-way open is stuck, not latched: no evidence
                    return ToggleResult("failed", f"Jammed: the door held at {start:.0%} of its travel",
                                        progress, max(forces), forces=forces, cause=Cause.JAMMED)  # fmt: skip
                return ToggleResult("blocked", LATCHED[Cause.LOCKED_PAD_SLID], progress, max(forces),
                                    forces=forces, cause=Cause.LOCKED_PAD_SLID)  # fmt: skip
            if progress < c.blocked_progress and (normal > p.blocked_force or magnitude > c.blocked_magnitude):
                self._back_off(door, angle)
                return ToggleResult("blocked", PUSHED_IN_VAIN, progress, max(forces), forces=forces,
                                    cause=Cause.LOCKED_PUSHED)  # fmt: skip
        self._back_off(door, max(progress, 0.0) * door.travel)
        if last_pressed < c.moved_fraction:
            # the pad lost the face before the door was open: it went over the post (a latched door, inside the
            # slide test's 7 deg: it read "moved" with the door shut) or the door is elsewhere. How far the door
            # went is how far its face turned while pressed.
            at = start + (max(last_face - pressed_at[1], 0.0) if pressed_at is not None else 0.0)
            return self._verdict(at, forces, Cause.LOCKED_PUSHED if start < c.blocked_progress else None)
        return self._verdict(progress, forces)  # a latch was decided on the way: short of it, no evidence

    def _held_part_way(
        self, track: collections.deque[tuple[float, float]], first_face: float, turn: float, normal: float
    ) -> bool:
        """Whether the door stopped part-way against the push (a lock's rod at its wall), the pad pressed on its face
        over ``track`` ((progress, face) per tick, the latest last; ticks older than ``turn`` of the pad's travel
        are dropped): after the face had turned with the pad past ``blocked_progress`` of the travel since it
        first pressed (at ``first_face``), short of ``moved_fraction``, either the pad slid along the face over
        ``turn`` while the face turned less than half as much, or the face stood still (``stall_progress`` over
        ``stall_window``) with ``normal`` [N] on it above ``stall_force`` (the pad, held back by its lead, turns
        slowly along a face that does not give: a door held at 27 % was pressed with 51 N before it had slid 3
        deg). A face that never turned is a latch or a jam, judged by the slide test since the first press."""
        c = self.config
        progress, face = track[-1]
        while len(track) > 1 and track[1][0] <= progress - turn:
            track.popleft()
        begun, face_then = track[0]
        if face_then - first_face < c.blocked_progress or face >= c.moved_fraction:
            return False  # (further, the door is in its end stop: open)
        if progress - begun >= turn and face - face_then < 0.5 * (progress - begun):
            return True
        window = max(2, round(c.stall_window * self.slowdown / c.tick))
        return normal > c.stall_force and len(track) >= window and abs(face - track[-window][1]) < c.stall_progress

    def _back_off(self, door: DoorPush, angle: float) -> None:
        """Take the pad off the handle's face (along its normal, :meth:`DoorPush.face_normal` at ``angle``; a
        quarter turn more is the plate's top face) before lifting: pressed on, it would drag the handle up with
        it."""
        c = self.config
        p = c.push
        away = self.robot.tcp_pose_in_base()
        away[:3, 3] += p.gap * door.face_normal(angle)
        self.ik.set_joints(self.robot.joint_positions())
        try:
            self.move_to(away, c.release_time)
        except IKFailure:
            pass  # lifting next


__all__ = ["DoorPush", "DoorPushConfig", "DoorPushing", "PUSHED_IN_VAIN"]
