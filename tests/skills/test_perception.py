"""Perception recovers every kind and pose from the twin's overview image within tolerance, derives
joint models whose grasp points sit on the handles, and never invents a missing marker."""

from dataclasses import replace

import numpy as np
import pytest

from puzzlebox.models.generator import paper_family
from puzzlebox.skills import (
    MarkerDetector,
    MarkersNotFound,
    UnknownMarker,
    joint_model,
    kind_of,
    lid_height,
    select_markers,
    upright_pose,
)
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.session import TwinSession


def overview_calibration(session: TwinSession):
    return nominal_calibration(session).camera("overview")


POSITION_TOLERANCE = 0.005  # [m] (issue: perceived positions within 5 mm)
YAW_TOLERANCE = np.radians(2.0)


def frame_truth(session: TwinSession, name: str) -> tuple[np.ndarray, float]:
    site = session.data.site(session.scene.names.components[name].frame_site)
    R = site.xmat.reshape(3, 3)
    return site.xpos.copy(), float(np.arctan2(R[1, 0], R[0, 0]))


@pytest.fixture(params=[None, (0.38, 0.10, 1.0), (0.47, -0.08, -2.4)], ids=["default", "turned", "turned-back"])
def session(request):
    spec = paper_family("test")[0]
    if request.param is not None:
        spec = replace(spec, box=replace(spec.box, pose=request.param))
    with TwinSession(spec, seed=0) as twin:
        yield twin


def test_every_marker_gives_its_kind_and_pose_in_the_base_frame(session):
    spec = session.spec
    marker_map = {c.marker: c.kind for c in spec.components}  # the cell's marker map
    detections = select_markers(
        MarkerDetector().detect(session.robot.capture("overview"), overview_calibration(session)),
        set(marker_map),
        ("overview",),
    )
    for c in spec.components:
        detection = detections[c.marker]
        position, yaw = frame_truth(session, c.name)
        assert kind_of(marker_map, c.marker) == c.kind
        assert np.linalg.norm(detection.T_base_marker[:3, 3] - position) < POSITION_TOLERANCE, c.name
        yaw_error = (detection.planar_pose[2] - yaw + np.pi) % (2 * np.pi) - np.pi
        assert abs(yaw_error) < YAW_TOLERANCE, c.name


def test_joint_models_put_the_grasp_point_on_the_handle_and_the_axis_on_the_joint(session):
    spec = session.spec
    detections = select_markers(
        MarkerDetector().detect(session.robot.capture("overview"), overview_calibration(session)),
        {c.marker for c in spec.components},
        ("o",),
    )
    model = session.model
    height = lid_height(detections)
    for c in spec.components:
        names = session.scene.names.components[c.name]
        jm = joint_model(c.kind, upright_pose(detections[c.marker].planar_pose, height))
        handle_top = session.data.site(names.handle_site).xpos
        np.testing.assert_allclose(jm.grasp_point[:2], handle_top[:2], atol=POSITION_TOLERANCE)
        assert -0.025 < jm.grasp_point[2] - handle_top[2] < 0.0  # below the top, on the post
        joint = model.joint(names.joint)
        axis_truth = session.data.xaxis[joint.id]
        assert np.dot(jm.axis, axis_truth) > np.cos(np.radians(2)), c.name
        if jm.joint == "hinge":  # the perceived axis passes through the true one
            offset = jm.origin - session.data.xanchor[joint.id]
            assert np.linalg.norm(offset - np.dot(offset, axis_truth) * axis_truth) < POSITION_TOLERANCE


@pytest.mark.parametrize("fraction", [0.5, 1.0])
def test_moving_along_the_joint_model_follows_the_real_grasp_point(fraction):
    import mujoco

    spec = paper_family("test")[0]
    with TwinSession(spec, seed=0) as session:
        detections = select_markers(
            MarkerDetector().detect(session.robot.capture("overview"), overview_calibration(session)),
            {c.marker for c in spec.components},
            ("o",),
        )
        height = lid_height(detections)
        for c in spec.components:
            jm = joint_model(c.kind, upright_pose(detections[c.marker].planar_pose, height))
            names = session.scene.names.components[c.name]
            body = session.model.body(names.body).id
            x0, R0 = session.data.xpos[body].copy(), session.data.xmat[body].reshape(3, 3).copy()
            in_body = R0.T @ (jm.grasp_point - x0)  # the grasp point, carried by the part
            qadr = session.model.joint(names.joint).qposadr[0]
            session.data.qpos[qadr] = fraction * jm.travel  # evaluation only: pose the part by hand
            mujoco.mj_forward(session.model, session.data)
            truth = session.data.xpos[body] + session.data.xmat[body].reshape(3, 3) @ in_body
            assert np.linalg.norm(jm.grasp_point_at(fraction) - truth) < POSITION_TOLERANCE, c.name


def test_a_hidden_marker_is_reported_missing_never_invented():
    spec = paper_family("test")[1]
    with TwinSession(spec, seed=0) as session:
        detections = MarkerDetector().detect(session.robot.capture("overview"), overview_calibration(session))
        expected = {c.marker for c in spec.components} | {42}  # the map lists one more component
        with pytest.raises(MarkersNotFound, match=r"missing marker ids \[42\]"):
            select_markers(detections, expected, ("overview",))
    with pytest.raises(UnknownMarker, match="known ids"):
        kind_of({0: "door"}, 7)


def test_a_duplicated_marker_id_is_refused():
    spec = paper_family("test")[2]
    spec = replace(spec, components=(spec.components[0], replace(spec.components[1], marker=spec.components[0].marker),
                                     *spec.components[2:]))  # fmt: skip
    with TwinSession(spec, seed=0) as session:
        detections = MarkerDetector().detect(session.robot.capture("overview"), overview_calibration(session))
        with pytest.raises(MarkersNotFound, match="more than once"):
            select_markers(detections, {c.marker for c in spec.components}, ("overview",))
