"""Where an open door may stand: the floor space its flap and handle can overhang, so that a descent beside it
is made slowly and stopped at a light touch.

A door opened by a pinch or a push stands somewhere between ``moved_fraction`` of its travel and its end stop;
above ~50 deg its own handle hides its marker, so no look tells where. Short of the stop (weak pads leave harsh
doors at 75-78 deg, and a jam may hold one there) its flap leans over the neighbour beside its hinge line: the
fingers descending onto that neighbour's handle met the flap's edge at 6 cm/s and put 70-150 N on the wrist
before the filtered, 30 ms late F/T reading passed the safety limit.

All vectors are in the robot base frame [m]; door coordinates as in :mod:`skills.door_push` (``x`` from the
hinge towards the handle, ``z`` the closed door's normal).
"""

from __future__ import annotations

import math

import numpy as np

from puzzlebox.models.kinds import DOOR_HALF, HANDLE_HEIGHT, HANDLE_MARGIN, HANDLE_SIZE
from puzzlebox.models.puzzle_box import PLATE_THICKNESS
from puzzlebox.skills.door_push import DoorPush
from puzzlebox.skills.joint_model import JointModel

SAMPLED_ANGLES = 9
"""Door angles sampled between the lowest and the end stop (the footprint's ends move monotonically but the
handle's corner does not)."""


def door_overhang(door: JointModel, from_fraction: float) -> tuple[float, float]:
    """The interval of door coordinate ``x`` (horizontal, from the hinge along the closed door's ``e_x``) [m]
    that the flap and handle of ``door`` cover from above, standing anywhere between ``from_fraction`` of its
    travel and its end stop. Along the hinge it covers the flap's width, ``DOOR_HALF`` either side of the
    handle."""
    return _overhang(DoorPush.of(door, 0.0), door.travel, from_fraction)


def near_open_door(door: JointModel, from_fraction: float, point: np.ndarray, radius: float) -> bool:
    """Whether ``point`` [m] comes within ``radius`` [m], horizontally, of the floor space ``door`` may
    overhang standing between ``from_fraction`` of its travel and its end stop (:func:`door_overhang`)."""
    push = DoorPush.of(door, 0.0)
    low, high = _overhang(push, door.travel, from_fraction)
    d = point - push.origin
    u, v = float(d @ push.e_x), abs(float(d @ push.axis))
    du = max(low - u, 0.0, u - high)
    dv = max(v - DOOR_HALF, 0.0)
    return math.hypot(du, dv) < radius


def lean_away(doors: list[JointModel], start: np.ndarray, end: np.ndarray) -> np.ndarray | None:
    """The horizontal unit vector (base frame) in which a gripper holding a handle that moves from ``start`` to
    ``end`` [m] should lean to keep its upper part away from ``doors`` that may stand open over it
    (:func:`near_open_door`): across each door's hinge line, away from its flap's closed footprint (a door at
    its stop stands beside its hinge line, its post reaching out past it over the neighbour). None when there
    are no doors or they stand on opposite sides (leaning from one would lean into the other). A door the
    handle passes only beside, along its hinge line (off the flap's width at both ends), is not leant from:
    its flap stands up across that way, and leaning over the hinge line brought the knuckles onto the standing
    plate's edge."""
    total = np.zeros(3)
    for door in doors:
        push = DoorPush.of(door, 0.0)
        along = sorted(float((p - push.origin) @ push.axis) for p in (start, end))
        if along[0] > DOOR_HALF or along[1] < -DOOR_HALF:
            continue
        point = start
        across = push.e_x.copy()
        across[2] = 0.0
        across /= np.linalg.norm(across)
        middle = (push.contact[0] + HANDLE_MARGIN - HANDLE_SIZE / 2) / 2  # of the closed flap, from the hinge
        total += across if float((point - push.origin) @ push.e_x) > middle else -across
    size = float(np.linalg.norm(total))
    return total / size if size > 0.5 else None


def _overhang(push: DoorPush, travel: float, from_fraction: float) -> tuple[float, float]:
    free_edge = push.contact[0] + HANDLE_MARGIN - HANDLE_SIZE / 2
    handle_back = push.contact[0]
    handle_front = handle_back - HANDLE_SIZE
    top = push.plate_top + HANDLE_HEIGHT
    bottom = push.plate_top - PLATE_THICKNESS
    corners = ((0.0, bottom), (0.0, push.plate_top), (free_edge, bottom), (free_edge, push.plate_top),
               (handle_front, top), (handle_back, top))  # fmt: skip
    low, high = math.inf, -math.inf
    for angle in np.linspace(from_fraction * travel, travel, SAMPLED_ANGLES):
        c, s = math.cos(angle), math.sin(angle)
        for x, z in corners:
            low, high = min(low, x * c - z * s), max(high, x * c - z * s)
    return low, high


__all__ = ["door_overhang", "near_open_door"]
