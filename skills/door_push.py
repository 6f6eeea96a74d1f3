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

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from puzzlebox.models.kinds import HANDLE_HEIGHT, HANDLE_MARGIN, HANDLE_SIZE
from puzzlebox.models.try_outcome import Cause
from puzzlebox.skills.door_judgement import (
    ClosingJudge,
    ClosingLimits,
    ClosingReading,
    SwingJudge,
    SwingLimits,
    SwingReading,
)
from puzzlebox.skills.errors import IKFailure
from puzzlebox.skills.joint_model import GRASP_DEPTH, JointModel, cross
from puzzlebox.skills.kinematics import top_down
from puzzlebox.skills.pacing import Pacing
from puzzlebox.skills.pinch import Pinch, TryArgs
from puzzlebox.skills.settings import DoorPushConfig
from puzzlebox.skills.toggle_result import LATCHED, ToggleResult

PUSHED_IN_VAIN = LATCHED[Cause.LOCKED_PUSHED]


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


@dataclass(frozen=True)
class ClosingSchedule:
    """Where a closing push sends the pads at each tick of its schedule: from ``start`` to ``end`` (fractions of
    the closing travel) over ``ticks``, slow at both ends (smoothstep), so that the pads meet the lid slowly."""

    start: float
    end: float
    ticks: int

    def at(self, k: float) -> float:
        """Where the pads are sent at (schedule) tick ``k``."""
        u = min(1.0, k / self.ticks)
        return self.start + (self.end - self.start) * u * u * (3 - 2 * u)

    def tick_at(self, s: float) -> float:
        """The schedule tick at which the pads are sent to ``s``: :meth:`at`'s inverse."""
        start, end = self.start, self.end
        x = min(max((s - start) / (end - start), 0.0), 1.0) if end > start else 1.0
        return self.ticks * (0.5 - math.sin(math.asin(1.0 - 2.0 * x) / 3.0))  # the smoothstep's inverse

    @staticmethod
    def held_offset(door: DoorPush, gap: float, depth: float, close_x: float) -> float:
        """A command s sends the pads' edge to ``depth`` into the plate, and their progress is measured from where
        they were first, ``gap`` above it: pads that follow the command exactly measure s + this, so pads measured at
        progress q are where the command q - this sends them [fraction of the travel]."""
        held_offset = math.atan2(door.plate_top + gap, close_x) - math.atan2(door.plate_top - depth, close_x)
        held_offset /= door.travel
        return held_offset


class DoorPusher:
    """Pushes doors (see the module docstring): the pad's plan and its reading, moved by the pinch's descent, the
    guarded motion and the retreat."""

    def __init__(self, pinch: Pinch) -> None:
        self.pinch, self.retreat, self.motion, self.watch = pinch, pinch.retreat, pinch.motion, pinch.watch
        self.robot, self.config, self.ik = pinch.robot, pinch.config, pinch.ik

    def push_open(self, jm: JointModel, start: float, args: TryArgs) -> ToggleResult:
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
        door = DoorPush.of(jm, p.plan.height)
        yaw = float(np.arctan2(door.e_x[1], door.e_x[0]) + np.pi / 2)  # the gripper's y axis (closing) = e_x

        def tcp_for(pad_edge: np.ndarray) -> np.ndarray:
            return top_down(pad_edge - p.plan.pad_offset * door.e_x, yaw)

        self.pinch.descend_to(
            tcp_for(door.point_at(start * door.travel, door.contact + np.array([p.plan.gap, 0.0]))), args
        )
        self.watch.phase = "actuating"
        result = self.swing(door, tcp_for, start)
        self.watch.phase = "retreating"
        self.retreat.let_go_and_retreat()
        self.watch.phase = "moving"
        return result

    def push_closed(self, jm: JointModel, start: float, args: TryArgs) -> ToggleResult:
        """Close a door by pushing its plate down with the edges of both finger pads, the fingers straddling
        the handle (they close along the hinge): the pads' outer edge (``pad_half_width`` along the
        gripper's x = the door's ``e_x``) rests on the plate's top face ``close_x`` from the hinge and
        follows it down its arc. Closing, the pad moves into the face, not along it: a door held open
        presses back at once, and no friction is needed to carry a free one. ``start`` is the fraction of
        the closing travel already covered (by a pinch that slipped part-way)."""
        c = self.config
        p = c.push
        door = DoorPush.of(jm, p.plan.height)
        yaw = self.pinch.grasp_yaw(jm)  # fingers along the hinge: the gripper's x is the door's e_x
        on_plate = np.array([p.plan.close_x, door.plate_top - p.plan.depth])

        def tcp_for(edge: np.ndarray) -> np.ndarray:
            return top_down(edge - p.plan.pad_half_width * door.e_x, yaw)

        above_plate = on_plate + np.array([0.0, p.plan.depth + p.plan.gap])
        self.pinch.descend_to(tcp_for(door.point_at((1.0 - start) * door.travel, above_plate)), args)

        self.watch.phase = "actuating"
        lead = p.plan.lead / (door.travel * p.plan.close_x)
        end = 1.0  # closed
        ticks = round(p.plan.close_time * self.watch.slowdown / c.motion.tick)
        contact = max(p.judgement.contact_force, p.judgement.contact_noise_margin * self.watch.filtered_noise_now())
        per_tick = c.motion.tick / (
            self.watch.slowdown * door.travel * p.plan.close_x
        )  # of the travel per tick, for 1 m/s at the pads

        closing = ClosingSchedule(start, end, ticks)
        scheduled, schedule_at = closing.at, closing.tick_at
        held_offset = closing.held_offset(door, p.plan.gap, p.plan.depth, p.plan.close_x)

        judge = ClosingJudge(c.judgement, p.judgement, ClosingLimits(start, contact))
        progress = 0.0
        self.ik.set_joints(self.robot.joint_positions())
        turn_at_start = door.turn_of(self.pad_edge(door, p.plan.pad_half_width))
        result = None
        k = 0
        schedule = 0.0  # the schedule's clock [ticks]: slowed while the pads search for the plate
        while schedule < ticks + round(2 * c.motion.settle_time / c.motion.tick):
            k += 1
            step = 1.0
            pressed_from = judge.pressed_from  # the progress at which the pads first pressed on the plate
            engaged = pressed_from is not None and progress - max(pressed_from, start) >= c.judgement.blocked_progress
            if not engaged:  # searching for the plate, or pressed on it but not yet seen to follow the pads
                nominal = scheduled(schedule + 1.0) - scheduled(schedule)
                speed = p.plan.search_speed if pressed_from is None else p.plan.press_speed
                step = min(1.0, speed * per_tick / nominal) if nominal > 0 else 1.0
            schedule += step
            s = min(scheduled(schedule), max(progress, start) + lead)
            closing_in = max(0.0, 1.0 - k * c.motion.tick / (p.plan.approach_time * self.watch.slowdown)) * (
                p.plan.gap + p.plan.depth
            )
            self.motion.tick(tcp_for(door.point_at((1.0 - s) * door.travel, on_plate + np.array([0.0, closing_in]))))
            turn = door.turn_of(self.pad_edge(door, p.plan.pad_half_width))
            progress = self.pinch.progress = start + (turn_at_start - turn) / door.travel
            angle = (1.0 - max(progress, 0.0)) * door.travel
            opposing = float(self.watch.force_in_base @ door.motion_direction(angle))  # opposing a closing motion
            magnitude = math.sqrt(self.watch.force_in_base @ self.watch.force_in_base)  # np.linalg.norm, bit for bit
            ended = judge.read(ClosingReading(progress, opposing, magnitude))
            if pressed_from is None and judge.pressed_from is not None:
                # the command runs the arm's tracking lag ahead of the pads (~1.5 mm at ``search_speed``): pressed
                # on a plate that does not give, it loads the wrist by the arm's stiffness times that lag whatever
                # is sent next, while the reading is late. Sent back to where the pads are, they press on from
                # there at ``press_speed``.
                schedule = min(schedule, schedule_at(progress - held_offset))
            if ended is True:
                # the plate is on the lid: stop at once. (Easing on to where the pads were, a door that fell
                # shut and was met on the lid at 15 mm/s loaded the wrist by 5-8 N per tick to 71 N.)
                break
            if ended is not False:
                result = Pinch.result_of(ended, judge.forces, judge.trace())
                break
        if result is None:
            result = Pinch.result_of(judge.verdict(progress), judge.forces, judge.trace())
        return self._off_the_plate(door, progress, result)

    def _off_the_plate(self, door: DoorPush, progress: float, result: ToggleResult) -> ToggleResult:
        """Back the pads off a closing push's plate along its normal (the door at ``progress`` of the closing
        travel), let go and retreat; returns ``result``. Held pressed on a latched plate (the command runs ``lead``
        into it) while the gripper opened, a harsh latch's play built 65 N on the wrist."""
        self.back_off(door, (1.0 - max(progress, 0.0)) * door.travel + math.pi / 2)
        self.watch.phase = "retreating"
        self.retreat.let_go_and_retreat()
        self.watch.phase = "moving"
        return result

    def top_up(self, jm: JointModel, args: TryArgs) -> ToggleResult:
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
        door = DoorPush.of(jm, p.plan.height)
        yaw = self.pinch.grasp_yaw(jm)  # fingers along the hinge: the gripper's x is the door's e_x
        free_edge = door.contact[0] + HANDLE_MARGIN - HANDLE_SIZE / 2  # the plate's far edge from the hinge
        x_start = free_edge * math.cos(p.top_up_plan.top_up_from) + p.top_up_plan.top_up_clearance
        x_end = (
            p.top_up_plan.top_up_low / math.tan(door.travel) - p.plan.depth
        )  # where the underside meets the pads at the stop

        def height_at(edge_x: float) -> float:  # the pads' height above the hinge line with their edge at edge_x
            dive = min(max((x_start - edge_x) / p.top_up_plan.top_up_dive, 0.0), 1.0)
            return p.top_up_plan.top_up_height + (p.top_up_plan.top_up_low - p.top_up_plan.top_up_height) * dive

        def tcp_for(edge_x: float) -> np.ndarray:  # the TCP with the pads' inner edge at edge_x from the hinge
            return top_down(
                door.origin + (edge_x + p.plan.pad_half_width) * door.e_x + height_at(edge_x) * door.e_z, yaw
            )

        # beside a door standing at an unknown angle: cautious, whatever the try
        self.pinch.descend_to(tcp_for(x_start), dataclasses.replace(args, cautious=True))
        self.watch.phase = "actuating"
        path = math.hypot(
            x_start - x_end, p.top_up_plan.top_up_height - p.top_up_plan.top_up_low
        )  # (the dive is part of the way)
        ticks = max(1, round(path / p.top_up_plan.top_up_speed * self.watch.slowdown / c.motion.tick))
        stop = min(
            c.judgement.blocked_magnitude,
            p.top_up_plan.top_up_force + p.top_up_plan.top_up_noise_margin * self.watch.filtered_noise_now(),
        )
        forces: list[float] = []
        edge_x = x_start
        self.ik.set_joints(self.robot.joint_positions())
        for k in range(1, ticks + round(c.motion.settle_time / c.motion.tick) + 1):
            self.motion.tick(tcp_for(x_start + (x_end - x_start) * min(k / ticks, 1.0)))  # at a constant speed
            edge_x = float((self.pad_edge(door, -p.plan.pad_half_width) - door.origin) @ door.e_x)
            forces.append(float(-self.watch.force_in_base @ door.e_x))
            magnitude = math.sqrt(self.watch.force_in_base @ self.watch.force_in_base)  # np.linalg.norm, bit for bit
            if magnitude > stop:
                break  # held where it stands, or in its end stop
        progress = math.atan2(height_at(edge_x), max(edge_x, 1e-6)) / door.travel  # the underside's angle there
        result = self.pinch.verdict(progress, forces)
        self.back_off(door, 0.0)  # off the plate (along e_x) before lifting
        self.watch.phase = "retreating"
        self.retreat.let_go_and_retreat()
        self.watch.phase = "moving"
        return result

    def pad_edge(self, door: DoorPush, offset: float) -> np.ndarray:
        """The pushing pad edge, ``offset`` from the TCP along the door's ``e_x``, where the robot measures it [m]."""
        return self.robot.tcp_pose_in_base()[:3, 3] + offset * door.e_x

    def swing(self, door: DoorPush, tcp_for, start: float = 0.0) -> ToggleResult:
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
        x = door.contact[0] - p.plan.depth

        def pressed(k: int) -> np.ndarray:  # the pad's point on the door at tick k: climbing the face at first
            return np.array(
                [
                    x,
                    door.contact[1]
                    + p.plan.climb * min(k * c.motion.tick / (p.plan.climb_time * self.watch.slowdown), 1.0),
                ]
            )

        def climb_turn(k: int) -> float:  # what the climb alone adds to the pad's turn about the hinge [rad]
            return math.atan2(pressed(k)[1], x) - math.atan2(door.contact[1], x)

        lead = p.plan.lead / (door.travel * float(np.hypot(*door.contact)))
        end = 1.0 + p.plan.overtravel
        contact = max(p.judgement.contact_force, p.judgement.contact_noise_margin * self.watch.filtered_noise_now())
        ticks = round(c.actuation.actuate_time * self.watch.slowdown / c.motion.tick)
        pace = (end - start) / ticks  # of the travel per tick, past the slow start
        # the start of the travel, driven slowly as a pinch's; from part-way (a door a pinch lost at its lock's
        # wall stands still there) slower still, closing in too, and at least ``blocked_progress`` past its start
        part_way = start >= c.judgement.blocked_progress  # (where a jam is read, :class:`SwingJudge`)
        slow_span = max(0.0, c.actuation.breakaway_fraction - start, c.judgement.blocked_progress if part_way else 0.0)
        slow_pace = c.actuation.breakaway_pace * (c.actuation.part_way_pace if part_way else 1.0)
        pacing = Pacing(pace, pace * slow_pace, slow_span)  # slow start, then a ramp up
        approach_time = p.plan.approach_time * self.watch.slowdown / (c.actuation.part_way_pace if part_way else 1.0)
        last_tick = pacing.ticks_to(end - start)
        limits = SwingLimits(
            start, contact, p.judgement.held_turn / door.travel, p.judgement.slide_turn / door.travel,
            max(2, round(c.judgement.stall_window * self.watch.slowdown / c.motion.tick)),
        )  # fmt: skip
        judge = SwingJudge(c.judgement, p.judgement, limits)
        progress = 0.0
        self.ik.set_joints(self.robot.joint_positions())
        turn_at_start = door.turn_of(self.pad_edge(door, p.plan.pad_offset))
        for k in range(1, last_tick + 1 + round(2 * c.motion.settle_time / c.motion.tick)):
            paced = pacing.at(k)
            s = min(start + paced, end, max(progress, start) + lead)
            closing_in = max(0.0, 1.0 - k * c.motion.tick / approach_time) * (p.plan.gap + p.plan.depth)
            self.motion.tick(tcp_for(door.point_at(s * door.travel, pressed(k) + np.array([closing_in, 0.0]))))
            pad_edge = self.pad_edge(door, p.plan.pad_offset)
            progress = self.pinch.progress = (
                start + (door.turn_of(pad_edge) - turn_at_start - climb_turn(k)) / door.travel
            )
            angle = max(progress, 0.0) * door.travel
            normal = float(self.watch.force_in_base @ door.face_normal(angle))
            opposing = float(-self.watch.force_in_base @ door.motion_direction(angle))
            magnitude = math.sqrt(self.watch.force_in_base @ self.watch.force_in_base)  # np.linalg.norm, bit for bit
            if s > 1.0 and magnitude > c.actuation.overtravel_force:  # in the end stop: stop here
                end = max(1.0, min(progress, s))
            face = door.angle_from_contact(pad_edge) / door.travel
            ended = judge.read(SwingReading(progress, face, normal, opposing, magnitude))
            if ended is not None:
                self.back_off(door, angle)
                return Pinch.result_of(ended, judge.forces, judge.trace())
        self.back_off(door, max(progress, 0.0) * door.travel)
        return Pinch.result_of(judge.verdict(progress), judge.forces, judge.trace(progress))

    def back_off(self, door: DoorPush, angle: float) -> None:
        """Take the pad off the handle's face (along its normal, :meth:`DoorPush.face_normal` at ``angle``; a
        quarter turn more is the plate's top face) before lifting: pressed on, it would drag the handle up with
        it."""
        c = self.config
        p = c.push
        away = self.robot.tcp_pose_in_base()
        away[:3, 3] += p.plan.gap * door.face_normal(angle)
        self.ik.set_joints(self.robot.joint_positions())
        try:
            self.motion.move_to(away, c.motion.release_time)
        except IKFailure:
            pass  # lifting next


__all__ = ["DoorPush", "DoorPushConfig", "DoorPusher", "PUSHED_IN_VAIN"]
