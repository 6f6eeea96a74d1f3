"""Reality profiles: each imperfection changes what the robot senses, exactly as specified, and nothing
when it is zero; the ideal profile is the nominal world; profiles load, round-trip and refuse bad keys;
sessions stay pure functions of (spec, seed, profile, commands)."""

from __future__ import annotations

import dataclasses
import json
import types

import cv2
import mujoco
import numpy as np
import pytest

from puzzlebox.models.generator import paper_family
from puzzlebox.models.robot import Robot
from puzzlebox.skills import MarkerDetector
from puzzlebox.twin.errors import ProfileError
from puzzlebox.twin.jams import Jams
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.physics_draws import subtree_bodies
from puzzlebox.twin.reality import (
    PRESETS,
    ArmReality,
    CameraReality,
    ForceTorqueReality,
    PhysicsReality,
    RealityProfile,
    ScaleRange,
    load_profile,
)
from puzzlebox.twin.rendering import RenderConfig, Renderer
from puzzlebox.twin.sensors import cameras
from puzzlebox.twin.servos import Servos
from puzzlebox.twin.session import TwinConfig, TwinSession

SPEC = paper_family("test")[0]  # door-0 is free, the other four are latched
WRIST = "xarm7/gripper/wrist_camera"
TINY = TwinConfig(render=RenderConfig(width=96, height=72))


def profile(**sections) -> RealityProfile:
    return dataclasses.replace(PRESETS["ideal"], name="test", **sections)


def session(reality=None, seed=0, config=None) -> TwinSession:
    return TwinSession(SPEC, seed=seed, config=config, reality=reality)


# -- the profile as a file -----------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(PRESETS))
def test_presets_load_by_name_and_round_trip_through_json(name, tmp_path):
    preset = load_profile(name)
    assert preset.name == name
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(preset.to_dict()))
    assert load_profile(path) == preset
    assert RealityProfile.from_dict(json.loads(json.dumps(preset.to_dict()))) == preset


def test_realistic_and_harsh_place_the_box_and_ideal_does_not():
    assert PRESETS["ideal"].placement is None
    assert PRESETS["realistic"].placement is not None and PRESETS["harsh"].placement is not None


@pytest.mark.parametrize(
    ("data", "names"),
    [
        ({"camera": {"nois_sigma": 2.0}}, ["nois_sigma", "noise_sigma"]),
        ({"physics": {"friction_scale": {"lo": 1.0}}}, ["lo", "low", "high"]),
        ({"forcetorque": {}}, ["forcetorque", "force_torque"]),
    ],
)
def test_an_unknown_key_at_any_level_names_it_and_the_known_keys(tmp_path, data, names):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ProfileError) as error:
        load_profile(path)
    for name in names:
        assert name in str(error.value)


@pytest.mark.parametrize(
    ("data", "key"),
    [
        ({"force_torque": {"force_noise": -0.1}}, "force_noise"),
        ({"camera": {"noise_sigma": -1}}, "noise_sigma"),
        ({"camera": {"dropped_frame_probability": 1.5}}, "dropped_frame_probability"),
        ({"physics": {"jam_probability": -0.2}}, "jam_probability"),
        ({"arm": {"encoder_noise": "loud"}}, "encoder_noise"),
        ({"camera": {"occluder_count": 1000000}}, "occluder_count: must be in 1..20"),  # (was accepted)
        ({"force_torque": {"rate_hz": 100, "delay": 1e6}}, "delay: must be <= 0.5 s"),  # (was accepted)
    ],
)
def test_a_negative_noise_or_a_probability_outside_0_1_is_a_profile_error(tmp_path, data, key):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ProfileError, match=key):
        load_profile(path)


def test_an_unknown_preset_names_the_presets():
    with pytest.raises(ProfileError, match="harsh"):
        load_profile("realisitc")


# -- the robot protocol and the ideal cell ------------------------------------------------------------


def test_the_robot_interface_is_a_robot_and_frames_carry_no_calibration():
    with session(config=TINY) as s:
        assert isinstance(s.robot, Robot)
        frame = s.robot.capture("overview")
        assert frame.rgb.shape == (72, 96, 3) and frame.time == s.time
        assert not hasattr(frame, "K") and not hasattr(frame, "T_base_camera")


def test_ideal_is_the_nominal_world_noiseless_exact_and_calibrated():
    with session() as s, session(reality="ideal") as t:
        robot = s.robot
        assert s.reality == t.reality == PRESETS["ideal"]
        s.advance(0.3)
        t.advance(0.3)
        assert np.array_equal(s.data.qpos, t.data.qpos)
        names, sensordata = s.scene.names, s.data.sensordata
        force, torque = (s.model.sensor(n).adr[0] for n in (names.wrist_force, names.wrist_torque))
        load = -np.concatenate([sensordata[force : force + 3], sensordata[torque : torque + 3]])  # on the flange
        np.testing.assert_array_equal(robot.wrench(), load)  # no noise, bias, drift, delay nor quantisation
        ft = s.model.site(names.ft_site).id
        np.testing.assert_array_equal(robot.ft_rotation_in_base(), s.data.site_xmat[ft].reshape(3, 3))
        np.testing.assert_array_equal(robot.joint_positions(), s.data.qpos[s.arm_qpos])
        tcp = s.data.site(s.scene.names.tcp_site)
        np.testing.assert_array_equal(robot.tcp_pose_in_base()[:3, 3], tcp.xpos)
        nominal = nominal_calibration(s)
        for camera in robot.camera_names:
            truth, calibrated = s.camera_truth(camera), nominal.camera(camera)
            np.testing.assert_array_equal(truth.K, calibrated.K)
            np.testing.assert_array_equal(truth.dist, np.zeros(5))
            np.testing.assert_allclose(truth.pose_in_base(np.eye(4)), calibrated.pose_in_base(np.eye(4)), atol=1e-9)
        for field in ("geom_friction", "dof_damping", "body_mass", "eq_solref", "cam_pos", "cam_fovy", "body_pos"):
            assert np.array_equal(getattr(s.model, field), getattr(s.nominal_model, field)), field


# -- F/T sensor -------------------------------------------------------------------------------------


def wrench_samples(s: TwinSession, n: int) -> np.ndarray:
    return np.array([s.robot.wrench() for _ in range(n)])


def test_force_torque_noise_has_the_profile_sigma_and_zero_noise_repeats_exactly():
    with session(profile(force_torque=ForceTorqueReality(force_noise=0.4, torque_noise=0.02))) as s:
        samples = wrench_samples(s, 3000)
        np.testing.assert_allclose(samples[:, :3].std(axis=0), 0.4, rtol=0.08)
        np.testing.assert_allclose(samples[:, 3:].std(axis=0), 0.02, rtol=0.08)
        np.testing.assert_allclose(samples.mean(axis=0), s.ft.load(), atol=0.05)
    with session() as s:
        samples = wrench_samples(s, 50)
        assert (samples == samples[0]).all()


def test_bias_is_there_at_reset_and_a_tare_removes_it():
    with session(profile(force_torque=ForceTorqueReality(force_bias=2.0, torque_bias=0.05))) as s:
        offset = s.robot.wrench() - s.ft.load()
        assert np.linalg.norm(offset[:3]) == pytest.approx(2.0)
        assert np.linalg.norm(offset[3:]) == pytest.approx(0.05)
        s.robot.tare()
        np.testing.assert_allclose(s.robot.wrench(), 0.0, atol=1e-12)


def test_drift_accumulates_after_a_tare_at_the_profile_rate():
    drifting = profile(force_torque=ForceTorqueReality(force_drift=60.0))  # 1 N/s: large, to see it in 0.5 s
    with session(drifting) as s, session() as ideal:
        for t in (s, ideal):
            t.robot.tare()
            t.advance(0.5)
        drift = s.robot.wrench() - ideal.robot.wrench()  # the same physics: only the drift differs
        assert np.linalg.norm(drift[:3]) == pytest.approx(0.5, rel=1e-6)
        assert not drift[3:].any()


def test_saturation_clips_the_reading_at_the_sensor_range():
    # the gripper's 7.4 N weight against a 2 N range: the axes it loads most saturate
    with session(profile(force_torque=ForceTorqueReality(force_range=(2.0, 2.0, 2.0), torque_range=0.1))) as s:
        load = s.ft.load()
        assert np.abs(load[:3]).max() > 2.0
        limits = np.array([2.0] * 3 + [0.1] * 3)
        np.testing.assert_array_equal(s.robot.wrench(), np.clip(load, -limits, limits))


def test_a_delayed_sensor_reports_the_load_of_delay_ago():
    delayed = profile(force_torque=ForceTorqueReality(rate_hz=100.0, delay=0.05))
    with session(delayed) as s, session() as ideal:
        gripper = s.model.body("xarm7/gripper/xarm_gripper_base_link").id
        readings = {}
        for t in (s, ideal):
            t.advance(0.3)
            t.data.xfrc_applied[gripper, :3] = [0.0, 0.0, 30.0]  # a sudden push
            t.advance(0.03)
            readings[t] = t.robot.wrench()
        # 30 ms after the push the delayed sensor still reads the load before it
        assert np.linalg.norm(readings[ideal][:3] - ideal.ft.load()[:3]) < 1e-9
        assert np.linalg.norm(readings[s][:3] - s.ft.load()[:3]) > 5.0
        s.advance(0.05)
        assert np.linalg.norm(s.robot.wrench()[:3] - s.ft.load()[:3]) < 5.0


# -- arm ----------------------------------------------------------------------------------------------


def test_encoder_noise_has_the_profile_sigma_and_one_reading_per_instant():
    with session(profile(arm=ArmReality(encoder_noise=0.002))) as s:
        assert np.array_equal(s.robot.joint_positions(), s.robot.joint_positions())  # same instant
        errors = []
        for _ in range(300):
            errors.append(s.robot.joint_positions() - s.data.qpos[s.arm_qpos])
            s.step(1)
        errors = np.array(errors)
        assert np.std(errors) == pytest.approx(0.002, rel=0.1)
        assert abs(errors.mean()) < 4 * 0.002 / np.sqrt(errors.size)  # unbiased
        assert abs(np.corrcoef(errors[:-1].ravel(), errors[1:].ravel())[0, 1]) < 0.1  # fresh at each instant


def test_the_reported_tcp_and_ft_orientation_come_from_one_noisy_reading_by_the_nominal_kinematics():
    with session(profile(arm=ArmReality(encoder_noise=0.002, tcp_bias=0.005))) as s, session() as ideal:
        s.advance(0.1)
        ideal.advance(0.1)
        q = s.robot.joint_positions()
        nominal = mujoco.MjData(s.nominal_model)
        nominal.qpos[s.arm_qpos] = q
        mujoco.mj_kinematics(s.nominal_model, nominal)
        tcp, ft = (s.model.site(n).id for n in (s.scene.names.tcp_site, s.scene.names.ft_site))
        T, R = s.robot.tcp_pose_in_base(), s.robot.ft_rotation_in_base()
        np.testing.assert_array_equal(T[:3, 3], nominal.site_xpos[tcp])
        np.testing.assert_array_equal(R, nominal.site_xmat[ft].reshape(3, 3))
        # the same reading: the TCP seen from the sensor frame is the nominal, noiseless one
        relative = lambda r: r.ft_rotation_in_base().T @ r.tcp_pose_in_base()[:3, :3]  # noqa: E731
        np.testing.assert_allclose(relative(s.robot), relative(ideal.robot), atol=1e-12)
        # ...and not the true orientation: the encoder noise tilts it
        error = np.linalg.norm(cv2.Rodrigues(R.T @ s.data.site_xmat[ft].reshape(3, 3))[0])
        assert 1e-4 < error < 0.02


def test_command_latency_delays_a_joint_command():
    late = profile(arm=ArmReality(command_latency=0.05))
    with session(late) as s, session() as ideal:
        for t in (s, ideal):
            target = t.robot.joint_positions() + 0.05
            t.robot.command_joint_positions(target)
            t.advance(0.04)
        assert not np.array_equal(s.data.ctrl[s.arm_actuators], target)  # not yet
        assert np.abs(s.data.qpos[s.arm_qpos] - s.config.home_qpos).max() < 1e-3
        assert np.abs(ideal.data.qpos[ideal.arm_qpos] - ideal.config.home_qpos).max() > 5e-3
        s.advance(0.012)
        np.testing.assert_array_equal(s.data.ctrl[s.arm_actuators], target)


def test_command_latency_rounds_up_to_whole_physics_steps():
    with session() as s:
        steps = {
            latency: Servos(s.data, s.arm_actuators, s.gripper_actuator, ArmReality(command_latency=latency), 0.002)
            for latency in (0.001, 0.005, 0.010, 0.050)
        }
        assert {k: v.latency_steps for k, v in steps.items()} == {0.001: 1, 0.005: 3, 0.010: 5, 0.050: 25}


def test_a_command_sent_during_a_stall_waits_for_its_end():
    stalling = profile(arm=ArmReality(stall_rate=50.0, stall_duration=0.2))
    with session(stalling) as s:
        delays = []
        for _ in range(10):
            s.advance(0.03)
            sent = s.time
            target = np.array(s.config.home_qpos) + 0.01 * len(delays)
            s.robot.command_joint_positions(target)
            while not np.array_equal(s.data.ctrl[s.arm_actuators], target):
                s.step(1)
            delays.append(s.time - sent)
        assert max(delays) > 0.05  # stalled (the stalls take ~90 % of the time here)
        assert max(delays) <= 0.2 + 1e-9  # and never longer than a stall


def test_tcp_bias_moves_the_physical_gripper_not_the_reported_tcp():
    with session(profile(arm=ArmReality(tcp_bias=0.01))) as s, session() as ideal:
        reported = s.robot.tcp_pose_in_base()
        np.testing.assert_allclose(reported, ideal.robot.tcp_pose_in_base(), atol=1e-12)
        true_tcp = s.data.site(s.scene.names.tcp_site).xpos
        assert np.linalg.norm(true_tcp - reported[:3, 3]) == pytest.approx(0.01, rel=1e-9)
        # the wrist camera rides on the gripper: its true pose in the reported TCP frame moves by the bias
        moved = s.camera_truth(WRIST).T_tcp_camera[:3, 3] - nominal_calibration(s).camera(WRIST).T_tcp_camera[:3, 3]
        assert np.linalg.norm(moved) == pytest.approx(0.01, rel=1e-6)


# -- cameras -----------------------------------------------------------------------------------------


def detect(rgb: np.ndarray) -> dict[int, np.ndarray]:
    """Marker corners by id, as the pipeline's detector finds them [px]."""
    return {marker_id: corners for corners, marker_id in MarkerDetector().detect_pixels(rgb)}


@pytest.fixture(scope="module")
def ideal_corners():
    """Marker corners in the ideal overview image [px] and their points on the lid (base frame) [m]."""
    with session() as s:
        found = detect(s.robot.capture("overview").rgb)
        calibration = nominal_calibration(s).camera("overview")
        points = {}
        for c in SPEC.components:
            marker = s.data.geom(s.scene.names.components[c.name].marker)
            top = marker.xpos[2] + s.model.geom_size[marker.id][2]
            rays = np.linalg.solve(calibration.K, np.vstack([found[c.marker].T, np.ones(4)]))
            R, origin = calibration.T_base_camera[:3, :3], calibration.T_base_camera[:3, 3]
            rays = R @ rays
            points[c.marker] = (origin[:, None] + rays * (top - origin[2]) / rays[2]).T
        return found, points, calibration.K


def project(truth, points: np.ndarray) -> np.ndarray:
    T_camera_base = np.linalg.inv(truth.T_base_camera)
    rvec, _ = cv2.Rodrigues(T_camera_base[:3, :3])
    pixels, _ = cv2.projectPoints(points, rvec, T_camera_base[:3, 3], truth.K, truth.dist)
    return pixels.reshape(-1, 2)


def test_intrinsic_error_and_distortion_move_marker_corners_as_cv2_projectpoints_predicts(ideal_corners):
    found0, points, _ = ideal_corners
    lens = CameraReality(focal_error=0.03, principal_error=10.0, k1=0.1, p=0.003)
    with session(profile(camera=lens)) as s:
        truth = s.camera_truth("overview")
        assert truth.dist[0] != 0 and truth.K[0, 0] != nominal_calibration(s).camera("overview").K[0, 0]
        found = detect(s.robot.capture("overview").rgb)
        moved, errors = [], []
        for marker, corners in found0.items():
            moved.append(np.linalg.norm(found[marker] - corners, axis=1).max())
            errors.append(np.linalg.norm(found[marker] - project(truth, points[marker]), axis=1).max())
        assert max(moved) > 5.0  # the lens errors move corners by pixels...
        assert max(errors) < 0.5  # ...to where the true camera model puts them (detection: ~0.3 px)


def test_mounting_error_moves_where_a_known_point_appears(ideal_corners):
    found0, points, _ = ideal_corners
    with session(profile(camera=CameraReality(mount_translation=0.01, mount_rotation=1.0))) as s:
        truth = s.camera_truth("overview")
        offset = truth.T_base_camera[:3, 3] - nominal_calibration(s).camera("overview").T_base_camera[:3, 3]
        assert np.linalg.norm(offset) == pytest.approx(0.01)
        found = detect(s.robot.capture("overview").rgb)
        for marker, corners in found0.items():
            assert np.linalg.norm(found[marker] - corners, axis=1).min() > 3.0
            assert np.linalg.norm(found[marker] - project(truth, points[marker]), axis=1).max() < 0.5


def test_a_cells_lens_is_undistorted_once_and_shared_by_its_sessions(monkeypatch):
    undistort, calls = cameras.undistorted_rays, []
    monkeypatch.setattr(cameras, "undistorted_rays", lambda *args: calls.append(args) or undistort(*args))
    monkeypatch.setattr(cameras, "_rays_cache", {})
    lens = profile(camera=CameraReality(focal_error=0.03, principal_error=10.0, k1=0.1, p=0.003))
    with session(lens, seed=1, config=TINY) as a, session(lens, seed=2, config=TINY) as b:
        assert len(calls) == 2  # one per camera of the cell, for both sessions
        for camera in a.robot.camera_names:
            cam = a.model.camera(camera).id
            assert a.model.cam_fovy[cam] == b.model.cam_fovy[cam]
            assert np.array_equal(a.cameras.lens(camera).map_x, b.cameras.lens(camera).map_x)
    with session(config=TINY) as ideal:
        assert len(calls) == 2  # the ideal lens is the render's pinhole: nothing to undistort
        assert all(ideal.cameras.lens(c).map_x is None for c in ideal.robot.camera_names)


def test_dropped_frames_come_at_about_their_probability():
    with session(profile(camera=CameraReality(dropped_frame_probability=0.3)), config=TINY) as s:
        frames = [s.robot.capture("overview") for _ in range(300)]
        assert sum(f is None for f in frames) / len(frames) == pytest.approx(0.3, abs=0.08)
    with session(config=TINY) as s:
        assert all(s.robot.capture("overview") is not None for _ in range(20))


@pytest.mark.parametrize(
    "effect",
    [
        CameraReality(noise_sigma=4.0),
        CameraReality(gain=ScaleRange(1.2, 1.2)),
        CameraReality(defocus_sigma=1.5),
        CameraReality(occluder_probability=1.0),
    ],
    ids=["noise", "gain", "defocus", "occluders"],
)
def test_each_frame_effect_changes_the_image_as_specified(effect):
    config = TwinConfig(render=RenderConfig(width=160, height=120))
    with session(config=config) as ideal, session(profile(camera=effect), config=config) as s:
        clean = ideal.robot.capture("overview").rgb.astype(float)
        image = s.robot.capture("overview").rgb.astype(float)
        with Renderer(s.model, config.render) as renderer:  # zero effects: the pinhole render itself
            assert np.array_equal(clean, renderer.render(ideal.data, "overview"))
        difference = image - clean
        if effect.noise_sigma:
            inside = (clean > 20) & (clean < 235)  # away from clipping
            assert difference[inside].std() == pytest.approx(4.0, rel=0.1)
        elif not effect.gain.is_identity:
            bright = (clean > 30) & (clean < 200)
            np.testing.assert_allclose(image[bright] / clean[bright], 1.2, atol=0.02)
        elif effect.defocus_sigma:
            gradient = lambda im: np.abs(np.diff(im, axis=1)).mean()  # noqa: E731
            assert gradient(image) < 0.8 * gradient(clean)
        else:
            assert (np.abs(difference).max(axis=2) > 30).sum() > 100


def test_motion_blur_smears_only_a_moving_camera():
    config = TwinConfig(render=RenderConfig(width=160, height=120))
    with session(profile(camera=CameraReality(exposure=0.033)), config=config) as s, session(config=config) as ideal:
        assert np.array_equal(s.robot.capture(WRIST).rgb, ideal.robot.capture(WRIST).rgb)  # at rest: sharp
        for t in (s, ideal):
            t.data.qvel[t.arm_dof[0]] = 3.0  # the base joint turning at 3 rad/s: a ~7 px smear in 33 ms
            mujoco.mj_forward(t.model, t.data)
        frames = [t.robot.capture(WRIST).rgb.astype(float) for t in (s, ideal)]
        sharpness = [np.abs(np.diff(f, axis=0)).mean() + np.abs(np.diff(f, axis=1)).mean() for f in frames]
        assert sharpness[0] < 0.9 * sharpness[1]


# -- physics ------------------------------------------------------------------------------------------


def test_physics_scales_change_the_compiled_model():
    twice = ScaleRange(2.0, 2.0)
    physics = PhysicsReality(
        friction_scale=twice,
        joint_damping_scale=twice,
        joint_friction_scale=twice,
        mass_scale=twice,
        latch_compliance_scale=twice,
        grip_force_scale=0.5,
    )
    with session(profile(physics=physics)) as s:
        m, nominal = s.model, s.nominal_model
        for c in SPEC.components:
            names = s.scene.names.components[c.name]
            handle, joint, body = m.geom(names.handle).id, m.joint(names.joint), m.body(names.body).id
            # friction x2 and half the grip: the pad friction that holds a handle is unchanged (2 x 0.5)
            assert m.geom_friction[handle, 0] == pytest.approx(nominal.geom_friction[handle, 0])
            assert m.dof_damping[joint.dofadr[0]] == 2 * nominal.dof_damping[joint.dofadr[0]]
            assert m.dof_frictionloss[joint.dofadr[0]] == 2 * nominal.dof_frictionloss[joint.dofadr[0]]
            assert m.body_mass[body] == 2 * nominal.body_mass[body]
            latch = m.equality(names.latch).id
            assert m.eq_solref[latch, 0] == 2 * nominal.eq_solref[latch, 0]
        a = s.gripper_actuator  # the fingers still close as the nominal servo closes them
        np.testing.assert_array_equal(m.actuator_forcerange[a], nominal.actuator_forcerange[a])
        np.testing.assert_array_equal(m.actuator_gainprm[a], nominal.actuator_gainprm[a])
    with session(profile(physics=PhysicsReality(pad_friction=0.4))) as s:
        handle = s.model.geom(s.scene.names.components["door-0"].handle).id
        assert s.model.geom_friction[handle, 0] == 0.4


def push_door(s: TwinSession, seconds: float, newtons: float = 5.0) -> None:
    body = s.model.body(s.scene.names.components["door-0"].body).id
    handle = s.data.site(s.scene.names.components["door-0"].handle_site).xpos
    force = np.array([0.0, 0.0, newtons])
    s.data.xfrc_applied[body] = np.concatenate([force, np.cross(handle - s.data.xipos[body], force)])
    s.advance(seconds)
    s.data.xfrc_applied[:] = 0.0


def test_a_jam_holds_a_free_component_for_the_try_and_then_lets_it_go():
    jamming = profile(physics=PhysicsReality(jam_probability=1.0, jam_release_after=0.5))
    with session(jamming) as s, session() as ideal:
        door = SPEC.index_of("door-0")
        for t in (s, ideal):
            push_door(t, 0.1)
        jammed_at = s.component_positions()[door]
        assert s.jams.jammed[door] and s.latches.engaged[door]
        for t in (s, ideal):
            push_door(t, 0.3)
        assert ideal.component_positions()[door] > 0.3  # free: it swings open
        assert abs(s.component_positions()[door] - jammed_at) < np.radians(1)  # held where it jammed
        s.advance(0.6)  # nothing touches its handle: the try ends, the jam is released
        assert not s.jams.jammed[door] and not s.latches.engaged[door]
    with session(profile(physics=PhysicsReality(jam_probability=0.0))) as s:
        assert s.jams is None


def contacts(time: float, *pairs: tuple[int, int]) -> types.SimpleNamespace:
    """A stand-in for ``MjData`` with the given contacts (geom pairs) at ``time``: what :class:`Jams` reads."""
    geom = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    return types.SimpleNamespace(time=time, ncon=len(pairs), contact=types.SimpleNamespace(geom=geom))


@pytest.fixture(scope="module")
def jam_parts():
    """Each component's geoms, gripper bodies, travel, door-0's index, its handle and a gripper geom, a floor geom,
    door-0's plate."""
    with session() as s:
        m, names = s.model, s.scene.names
        parts = [np.flatnonzero(m.geom_bodyid == m.body(names.components[c.name].body).id) for c in SPEC.components]
        handles = np.array([m.geom(names.components[c.name].handle).id for c in SPEC.components])
        gripper = subtree_bodies(m, m.body("xarm7/gripper/xarm_gripper_base_link").id)
        pad = int(np.flatnonzero(np.isin(m.geom_bodyid, gripper))[0])
        floor = int(np.flatnonzero(m.geom_bodyid == 0)[0])
        door = SPEC.index_of("door-0")
        plate = m.geom(f"{names.components['door-0'].body}:plate").id
        return parts, gripper, s.travel.copy(), door, int(handles[door]), pad, floor, m, plate


def test_a_jam_holds_while_the_gripper_touches_the_handle_and_ends_half_a_second_after_it_lets_go(jam_parts):
    parts, gripper, travel, door, handle, pad, floor, model, _ = jam_parts
    jams = Jams(model, parts, gripper, travel, probability=1.0, release_after=0.5)
    held = np.array([c != door for c in range(len(SPEC.components))])  # door-0 free, the others latched
    rest = np.zeros(len(SPEC.components))
    jams.reset(np.random.default_rng(0), rest)
    moved = rest + 0.1  # every component pushed past its start threshold: only the free one starts a try
    assert not jams.update(contacts(0.0, (handle, pad)), rest, held)  # touched at rest: no try
    assert jams.update(contacts(0.125, (handle, pad)), moved, held)  # the try starts: jammed
    assert jams.jammed.tolist() == [c == door for c in range(len(SPEC.components))]
    for t in (0.25, 0.5, 0.75, 1.0):  # held while touched, in either order of the pair, for as long as it lasts
        assert not jams.update(contacts(t, (pad, handle)), moved, held)
        assert jams.jammed[door]
    for t in (1.25, 1.4375):  # let go (the box's own contacts do not count): not yet 0.5 s
        assert not jams.update(contacts(t, (handle, floor)), moved, held)
        assert jams.jammed[door]
    assert jams.update(contacts(1.5, (handle, floor)), moved, held)  # 0.5 s untouched: released
    assert not jams.jammed.any()
    assert not jams.update(contacts(2.0), moved, held)  # where it stands is its new rest: no new try
    assert jams.update(contacts(2.125), moved + 0.1, held) and jams.jammed[door]  # moved on: a new try


def test_a_door_pushed_by_its_plate_is_in_one_try_for_as_long_as_the_push_lasts(jam_parts):
    parts, gripper, travel, door, _, pad, _, model, plate = jam_parts
    jams = Jams(model, parts, gripper, travel, probability=0.5, release_after=0.5)
    held = np.array([c != door for c in range(len(SPEC.components))])
    draws = []
    for seed in range(40):
        jams.reset(np.random.default_rng(seed), np.zeros(len(SPEC.components)))
        for k in range(1, 41):  # a 4 s push on the plate that turns the door on and on
            jams.update(contacts(0.1 * k, (plate, pad)), np.full(len(SPEC.components), 0.05 * k), held)
        draws.append(jams._rng.bit_generator.state["state"]["state"])
        fresh = np.random.default_rng(seed)
        fresh.random()  # exactly one draw: the try that began with the push
        assert draws[-1] == fresh.bit_generator.state["state"]["state"]


def test_a_component_jams_on_about_a_fraction_p_of_its_tries(jam_parts):
    parts, gripper, travel, door, handle, pad, _, model, _ = jam_parts
    jams = Jams(model, parts, gripper, travel, probability=0.5, release_after=0.5)
    held = np.array([c != door for c in range(len(SPEC.components))])
    rest = np.zeros(len(SPEC.components))
    jammed = []
    for seed in range(400):
        jams.reset(np.random.default_rng(seed), rest)
        jams.update(contacts(0.01, (handle, pad)), rest + 0.1, held)
        jammed.append(jams.jammed[door])
    assert np.mean(jammed) == pytest.approx(0.5, abs=0.075)  # 3 sigma of 400 tries


# -- randomness ---------------------------------------------------------------------------------------


def test_cell_errors_come_from_the_cell_seed_and_trial_randomness_from_the_session_seed():
    realistic = load_profile("realistic")
    with session(realistic, seed=1) as a, session(realistic, seed=2) as b:
        other_cell = session(dataclasses.replace(realistic, cell_seed=5), seed=1)
        with other_cell as c:
            for camera in a.robot.camera_names:
                assert np.array_equal(a.camera_truth(camera).K, b.camera_truth(camera).K)
                assert not np.array_equal(a.camera_truth(camera).K, c.camera_truth(camera).K)
            assert np.array_equal(a.cell.tcp_bias, b.cell.tcp_bias)
            assert a.box_pose == c.box_pose != b.box_pose  # placement is per trial
            assert np.array_equal(a.physics_draw.friction, c.physics_draw.friction)
            assert not np.array_equal(a.physics_draw.friction, b.physics_draw.friction)


def test_an_identity_factor_leaves_the_other_physics_draws_of_a_seed_unchanged():
    realistic = load_profile("realistic")
    no_friction = dataclasses.replace(
        realistic, physics=dataclasses.replace(realistic.physics, friction_scale=ScaleRange())
    )
    with session(realistic, seed=2) as a, session(no_friction, seed=2) as b:
        assert not np.all(a.physics_draw.friction == 1) and np.all(b.physics_draw.friction == 1)
        for factor in ("joint_damping", "joint_friction", "mass", "latch_compliance"):
            assert np.array_equal(getattr(a.physics_draw, factor), getattr(b.physics_draw, factor)), factor


def test_extra_captures_leave_the_force_and_encoder_readings_bit_identical():
    def run(captures: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        with session("harsh", seed=4, config=TINY) as s:
            wrenches, joints, qpos = [], [], []
            for k in range(6):
                s.robot.command_joint_positions(np.array(s.config.home_qpos) + 0.02 * k)
                s.robot.wait(0.05)
                for camera in s.robot.camera_names * captures:
                    s.robot.capture(camera)
                wrenches.append(s.robot.wrench())
                joints.append(s.robot.joint_positions())
                qpos.append(s.data.qpos.copy())
            return np.array(wrenches), np.array(joints), np.array(qpos)

    plain, photographed = run(0), run(3)
    for a, b in zip(plain, photographed, strict=True):
        assert np.array_equal(a, b)


def test_placement_puts_the_box_at_a_reachable_pose_drawn_from_the_seed():
    with session("realistic", seed=3) as s, session("realistic", seed=3) as again:
        assert s.box_pose == again.box_pose == s.spec.box.pose
        assert s.box_pose != session().box_pose
        assert s.held_by_rules().tolist() == [False, True, True, True, True]


def test_same_seed_and_profile_give_bit_identical_images_and_readings():
    def run() -> tuple[list, list]:
        with session("harsh", seed=4, config=TINY) as s:
            frames, wrenches = [], []
            for k in range(6):
                s.robot.command_joint_positions(np.array(s.config.home_qpos) + 0.02 * k)
                s.robot.wait(0.05)
                frame = s.robot.capture("overview")
                frames.append(None if frame is None else frame.rgb)
                wrenches.append(s.robot.wrench())
            return frames, wrenches

    (f1, w1), (f2, w2) = run(), run()
    assert all((a is None and b is None) or np.array_equal(a, b) for a, b in zip(f1, f2, strict=True))
    assert np.array_equal(w1, w2)
