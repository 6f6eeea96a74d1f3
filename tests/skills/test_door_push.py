"""The geometry of pushing a door: where its points go as it turns, and how far it turned read back from a pad
resting on its handle's back face — exactly when the pad is on the face, and not at all when the pad only
slides along a face that does not turn (a latched door)."""

import math

import numpy as np
import pytest

from puzzlebox.models.kinds import HANDLE_SIZE
from puzzlebox.skills.door_push import DoorPush
from puzzlebox.skills.joint_model import joint_model


def _door(yaw: float = 0.7, at=(0.45, -0.1, 0.08)) -> DoorPush:
    T = np.eye(4)
    c, s = math.cos(yaw), math.sin(yaw)
    T[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    T[:3, 3] = at
    return DoorPush.of(joint_model("door", T), height=0.016)


def test_the_door_frame_is_level_and_right_handed_with_the_handle_ahead_of_the_hinge():
    door = _door()
    assert door.e_x[2] == pytest.approx(0.0, abs=1e-12) and door.e_z[2] == pytest.approx(1.0)
    assert np.cross(door.axis, door.e_x) == pytest.approx(door.e_z)
    # the marker frame's x is the door's: the back face of the handle is 35 + 35 + 6 mm from the hinge
    assert door.contact[0] == pytest.approx(0.035 + 0.035 + HANDLE_SIZE / 2, abs=1e-9)
    assert door.contact[1] == pytest.approx(door.plate_top + 0.016)


@pytest.mark.parametrize("degrees", [0.0, 5.0, 30.0, 60.0, 85.0])
def test_a_pad_on_the_back_face_reads_the_door_angle(degrees):
    door = _door()
    angle = math.radians(degrees)
    for height in (0.005, 0.02, 0.03):  # anywhere up the face
        on_face = door.point_at(angle, np.array([door.contact[0], height]))
        assert door.angle_from_contact(on_face) == pytest.approx(angle, abs=1e-9)


def test_a_pad_sliding_along_a_face_that_does_not_turn_reads_no_turn_while_its_own_turn_grows():
    door = _door()
    low, high = (door.point_at(0.0, np.array([door.contact[0], z])) for z in (0.01, 0.03))
    assert door.angle_from_contact(low) == pytest.approx(door.angle_from_contact(high), abs=1e-9)
    assert door.turn_of(high) - door.turn_of(low) > math.radians(10)


def test_points_turn_rigidly_about_the_hinge():
    door = _door()
    p = np.array([0.05, 0.01])
    for angle in (0.3, 1.2):
        moved = door.point_at(angle, p)
        assert np.linalg.norm(moved - door.origin) == pytest.approx(np.hypot(*p))
        assert door.turn_of(moved) - door.turn_of(door.point_at(0.0, p)) == pytest.approx(angle)
        tangent = door.motion_direction(angle)
        assert tangent @ door.face_normal(angle) < 0  # opening, the back face runs away from a pad behind it


@pytest.mark.parametrize("kind", ["door", "slide", "wheel"])
def test_how_far_a_part_stands_open_is_read_back_from_any_point_it_carries(kind):
    """``JointModel.fraction_between``: what a look at a door's marker tells of where the door stands (its
    marker is not on the handle, and it rises as the door turns), exact for every kind and any point off the
    axis."""
    T = np.eye(4)
    T[:3, :3] = [[math.cos(0.7), -math.sin(0.7), 0], [math.sin(0.7), math.cos(0.7), 0], [0, 0, 1]]
    T[:3, 3] = (0.45, -0.1, 0.08)
    jm = joint_model(kind, T)
    marker = T[:3, 3] + (0.02, 0.01, 0.0)  # off a wheel's axis (its marker is on it)
    for fraction in (0.0, 0.2, 0.5, 1.0):
        amount = fraction * jm.travel
        if jm.joint == "slide":
            carried = marker + amount * jm.axis
        else:  # Rodrigues about the hinge
            r, k = marker - jm.origin, jm.axis
            carried = jm.origin + r * math.cos(amount) + np.cross(k, r) * math.sin(amount)
            carried += k * (k @ r) * (1 - math.cos(amount))
        assert jm.fraction_between(marker, carried) == pytest.approx(fraction, abs=1e-9)
        assert jm.fraction_between(carried, marker) == pytest.approx(-fraction, abs=1e-9)
