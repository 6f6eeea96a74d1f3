"""Where an open door may overhang: every point of the twin's own door (flap and handle geoms) stands inside the
footprint the pipeline predicts from the marker pose alone, at every angle from the lowest it allows to the end
stop, and the footprint is tight where it matters (the handle leans back over the hinge line at the stop)."""

import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from puzzlebox.models.kinds import DOOR_HALF
from puzzlebox.models.puzzle_box import build_puzzle_box
from puzzlebox.models.spec_loading import spec_from_dict
from puzzlebox.skills.door_clearance import door_overhang, lean_away, near_open_door
from puzzlebox.skills.door_push import DoorPush
from puzzlebox.skills.joint_model import joint_model


@pytest.fixture(scope="module")
def box():
    spec = spec_from_dict(
        {
            "format": "puzzlebox-spec/1",
            "name": "one-door",
            "box": {"size": [0.3, 0.3, 0.08], "pose": [0.45, 0.0, 0.0]},
            "components": [{"name": "door", "kind": "door", "pose": [0.02, -0.03, 0.9], "marker": 3}],
            "locks": [],
            "goal": {"component": "door", "state": 1},
        }
    )
    model = mujoco.MjModel.from_xml_string(build_puzzle_box(spec, with_markers=False).to_xml_string())
    return model, mujoco.MjData(model)


def _frame(model, data) -> np.ndarray:
    site = model.site("door:frame").id
    T = np.eye(4)
    T[:3, :3] = data.site_xmat[site].reshape(3, 3)
    T[:3, 3] = data.site_xpos[site]
    return T


def _corners(model, data, geom_name: str) -> np.ndarray:
    g = model.geom(geom_name).id
    half = model.geom_size[g]
    signs = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)])
    return data.geom_xpos[g] + (signs * half) @ data.geom_xmat[g].reshape(3, 3).T


@pytest.mark.parametrize("from_fraction", [0.1, 0.6])
def test_the_doors_flap_and_handle_stay_inside_the_predicted_overhang_at_every_angle(box, from_fraction):
    model, data = box
    data.qpos[0] = 0.0
    mujoco.mj_forward(model, data)
    door = joint_model("door", _frame(model, data))  # the marker pose, door closed: all a robot knows
    push = DoorPush.of(door, 0.0)
    low, high = door_overhang(door, from_fraction)
    for angle in np.linspace(from_fraction * door.travel, door.travel, 23):
        data.qpos[0] = angle
        mujoco.mj_forward(model, data)
        for geom in ("door:plate", "door:handle"):
            d = _corners(model, data, geom) - push.origin
            u, v = d @ push.e_x, d @ push.axis
            assert low - 1e-6 <= u.min() and u.max() <= high + 1e-6, (geom, math.degrees(angle))
            assert np.abs(v).max() <= DOOR_HALF + 1e-6
    data.qpos[0] = door.travel  # at its end stop the handle's back corner leans ~35 mm back over the hinge line
    mujoco.mj_forward(model, data)
    u_handle = (_corners(model, data, "door:handle") - push.origin) @ push.e_x
    assert u_handle.min() == pytest.approx(low, abs=0.002) and low < -0.03


def test_a_grasp_point_beside_the_hinge_line_is_near_and_one_clear_of_the_flap_is_not(box):
    model, data = box
    data.qpos[0] = 0.0
    mujoco.mj_forward(model, data)
    door = joint_model("door", _frame(model, data))
    push = DoorPush.of(door, 0.0)
    low, high = door_overhang(door, 0.6)
    beside = push.origin + (DOOR_HALF + 0.02) * push.axis  # 20 mm past the flap's side, over the hinge line
    assert near_open_door(door, 0.6, beside, 0.03) and not near_open_door(door, 0.6, beside, 0.015)
    ahead = push.origin + (high + 0.05) * push.e_x  # 50 mm beyond the highest the free edge can reach
    assert not near_open_door(door, 0.6, ahead, 0.045)
    assert near_open_door(door, 0.1, ahead, 0.045)  # a door that may stand at 8.5 deg reaches far out


def test_a_gripper_leans_away_from_the_hinge_line_of_a_door_beside_it_and_stays_upright_between_two(box):
    """The lean points from the door across its hinge line towards the part (where its post reaches out at the
    stop); a handle that passes the door only along its hinge line, or sits between two doors' hinge lines, gets
    no lean."""
    model, data = box
    data.qpos[0] = 0.0
    mujoco.mj_forward(model, data)
    door = joint_model("door", _frame(model, data))
    push = DoorPush.of(door, 0.0)
    beyond_hinge = push.origin - 0.04 * push.e_x  # a neighbour's handle 4 cm past the hinge line
    lean = lean_away([door], beyond_hinge, beyond_hinge + 0.05 * push.axis)
    assert lean is not None and lean @ -push.e_x == pytest.approx(1.0) and lean[2] == 0.0
    beyond_edge = push.origin + 0.13 * push.e_x  # past the free edge: away the other way
    assert lean_away([door], beyond_edge, beyond_edge) @ push.e_x == pytest.approx(1.0)
    # a handle moving along the hinge axis that reaches the flap's width only at its end still leans
    start = beyond_hinge - (DOOR_HALF + 0.03) * push.axis
    assert lean_away([door], start, start + 0.05 * push.axis) is not None
    # one that stays off the flap's width along the hinge line does not: the flap stands up across that way
    assert lean_away([door], start, start + 0.01 * push.axis) is None
    # a mirror-image door across the handle: leaning from one would lean into the other
    mirrored = replace(door, axis=-door.axis, origin=2 * beyond_hinge - door.origin,
                       grasp_point=2 * beyond_hinge - door.grasp_point)  # fmt: skip
    assert lean_away([door, mirrored], beyond_hinge, beyond_hinge) is None
    assert lean_away([], beyond_hinge, beyond_hinge) is None
