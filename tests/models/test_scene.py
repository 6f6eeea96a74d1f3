"""Every generated model compiles and steps warning-free (the Menagerie model test), names everything,
exports loadable files, and refuses specs the twin cannot build."""

import itertools
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from puzzlebox.models import Box, Component, Goal, PuzzleSpec, UnknownKindError
from puzzlebox.models.generator import RandomGraphConfig, generate_random, paper_family
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.scene import UnreachableBoxPose, build_scene

SIM_SECONDS = 1.0


def simulate_with_small_random_controls(model: mujoco.MjModel, seed: int) -> mujoco.MjData:
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    low, high = model.actuator_ctrlrange.T
    centre = np.clip(np.zeros(model.nu), low, high)
    steps = round(SIM_SECONDS / model.opt.timestep)
    for k in range(steps):
        if k % 50 == 0:  # a new small target every 0.1 s
            data.ctrl[:] = np.clip(centre + rng.normal(0, 0.05, model.nu) * (high - low), low, high)
        mujoco.mj_step(model, data)
    return data


def assert_no_warnings(data: mujoco.MjData, label: str) -> None:
    counts = data.warning.number
    assert not counts.any(), f"{label}: MuJoCo warnings {[mujoco.mjtWarning(i).name for i in np.flatnonzero(counts)]}"


@pytest.mark.parametrize("spec", paper_family("all"), ids=lambda s: s.name)
def test_every_paper_box_compiles_and_steps_without_warnings(spec):
    model = build_scene(spec).compile()
    data = simulate_with_small_random_controls(model, seed=0)
    assert_no_warnings(data, spec.name)
    assert np.all(np.isfinite(data.qpos))


def test_sixty_random_specs_compile_and_step_without_warnings():
    # 60 covers every size (2-5 parts) with and without markers and second lockers 7-8 times each; 200 took 2 min
    for seed in range(60):
        n = 2 + seed % 4
        spec = generate_random(RandomGraphConfig(n, multi_locker=n >= 4 and seed % 2 == 0), seed)
        model = build_scene(spec, replace_markers_off()).compile() if seed % 2 else build_scene(spec).compile()
        data = simulate_with_small_random_controls(model, seed)
        assert_no_warnings(data, spec.name)


def replace_markers_off():
    from puzzlebox.models.scene import SceneConfig

    return SceneConfig(with_markers=False)


def test_every_body_joint_geom_site_and_sensor_is_named():
    model = build_scene(paper_family("test")[0]).compile()
    kinds = {
        "body": (mujoco.mjtObj.mjOBJ_BODY, model.nbody),
        "joint": (mujoco.mjtObj.mjOBJ_JOINT, model.njnt),
        "geom": (mujoco.mjtObj.mjOBJ_GEOM, model.ngeom),
        "site": (mujoco.mjtObj.mjOBJ_SITE, model.nsite),
        "sensor": (mujoco.mjtObj.mjOBJ_SENSOR, model.nsensor),
    }
    for kind, (obj, count) in kinds.items():
        first = 1 if kind == "body" else 0  # body 0 is MuJoCo's world
        unnamed = [i for i in range(first, count) if not mujoco.mj_id2name(model, obj, i)]
        assert not unnamed, f"unnamed {kind}s: {unnamed}"
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) for i in range(model.ngeom)]
    assert len(set(names)) == len(names)


def test_scene_exports_to_files_plain_mujoco_loads(tmp_path):
    scene = build_scene(paper_family("test")[1])
    path = scene.export(tmp_path)
    model = mujoco.MjModel.from_xml_path(str(path))
    compiled = scene.compile()
    assert (model.nbody, model.njnt, model.ngeom, model.nu, model.neq) == (
        compiled.nbody, compiled.njnt, compiled.ngeom, compiled.nu, compiled.neq)  # fmt: skip
    assert model.body_gravcomp.sum() == compiled.body_gravcomp.sum() > 0


def test_the_exported_scene_rests_in_its_home_keyframe(tmp_path):
    # (without one, plain MuJoCo started the arm at zero, its fingers 40 mm inside the world, falling onto the lid)
    spec = paper_family("test")[0]
    model = mujoco.MjModel.from_xml_path(str(build_scene(spec).export(tmp_path)))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    assert all(c.dist > -0.001 for c in data.contact[: data.ncon])  # nothing interpenetrates by more than 1 mm
    parts = [model.joint(f"box/{c.name}:joint").qposadr[0] for c in spec.components]
    arm = [model.joint(f"xarm7/joint{i}").qposadr[0] for i in range(1, 8)]
    arm_at_home = data.qpos[arm].copy()
    for _ in range(round(2.0 / model.opt.timestep)):  # 2 s, the keyframe's controls held
        mujoco.mj_step(model, data)
    travel = np.array([get_kind(c.kind).travel for c in spec.components])
    assert np.all(np.abs(data.qpos[parts]) < 0.01 * travel)
    assert np.abs(data.qpos[arm] - arm_at_home).max() < 0.01
    assert not any(w.number for w in data.warning)


def test_box_stands_at_its_pose_with_components_at_their_lid_poses():
    spec = paper_family("test")[2]
    spec = replace(spec, box=replace(spec.box, pose=(0.40, 0.10, 0.7)))
    scene = build_scene(spec)
    model = scene.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for c in spec.components:
        lid_point = np.array([c.pose[0], c.pose[1], 0.0, 1.0])
        expected = (scene.T_world_lid @ lid_point)[:3]
        frame = data.site(scene.names.components[c.name].frame_site).xpos
        np.testing.assert_allclose(frame[:2], expected[:2], atol=1e-9)


def test_unknown_kind_is_a_clear_error_listing_known_kinds():
    spec = PuzzleSpec("odd", (Component("trapdoor-1", "trapdoor", (0.0, 0.0, 0.0), 0),), (), Goal("trapdoor-1"),
                      Box((0.3, 0.3, 0.08), (0.45, 0.0, 0.0)))  # fmt: skip
    with pytest.raises(UnknownKindError, match="door"):
        build_scene(spec)


def test_unreachable_box_pose_names_the_components_out_of_reach():
    spec = paper_family("test")[0]
    far = replace(spec, box=replace(spec.box, pose=(1.2, 0.0, 0.0)))
    with pytest.raises(UnreachableBoxPose, match="door-0"):
        build_scene(far)


def _nearest_over(model, data, geom_pairs, joints, values):
    """The least distance [m] between each geom pair (ids) over a grid of joint values, capped at 5 cm:
    ``joints`` lists groups of joint names set together, ``values`` each group's values."""
    addresses = [[model.joint(j).qposadr[0] for j in group] for group in joints]
    nearest = dict.fromkeys(geom_pairs, 0.05)
    for combination in itertools.product(*values):
        for group, value in zip(addresses, combination, strict=True):
            data.qpos[group] = value
        mujoco.mj_forward(model, data)
        for a, b in geom_pairs:
            nearest[(a, b)] = min(nearest[(a, b)], mujoco.mj_geomDistance(model, data, a, b, 0.05, None))
    return nearest


def test_the_contact_pairs_left_out_never_meet_at_any_joint_angle_and_the_ones_that_can_stay():
    """Pairs taken out of the contact test (their bounding spheres overlap at every step, which cost a mesh-mesh
    narrow phase each) must be kept apart by the kinematics over the joints' whole ranges; the upper arm and
    the forearm can fold into each other: that pair stays in."""
    model = build_scene(paper_family("test")[0]).compile()
    data = mujoco.MjData(model)
    geom = {model.geom(i).name: i for i in range(model.ngeom)}

    def excluded(a: str, b: str) -> bool:
        b1, b2 = sorted(int(model.geom_bodyid[geom[g]]) for g in (a, b))
        return (b1 << 16) + b2 in set(model.exclude_signature.tolist())

    links = (("left", "outer", 8), ("left", "inner", 12), ("right", "outer", 13), ("right", "inner", 17))
    fingers = [f"xarm7/gripper/{side}_{part}_knuckle_geom{n}" for side, part, n in links]
    finger_joints = [model.joint(j).name for j in range(model.njnt) if "gripper" in model.joint(j).name]
    cases = [  # (geom pairs, joint groups, values of each group)
        ([("xarm7/base_geom0", "xarm7/link1_geom1")], [["xarm7/joint1"]], [np.linspace(-np.pi, np.pi, 13)]),
        ([("xarm7/base_geom0", "xarm7/link2_geom2")], [["xarm7/joint2"]], [np.radians(np.linspace(-118, 120, 25))]),
        (
            [("xarm7/link6_geom6", f) for f in fingers],
            [["xarm7/joint7"], finger_joints],
            [np.linspace(-np.pi, np.pi, 13), np.linspace(0.0, 0.85, 4)],
        ),  # fmt: skip
        ([(a, b) for a in fingers[:2] for b in fingers[2:]], [finger_joints], [np.linspace(0.0, 0.85, 8)]),
    ]
    for pairs, joints, values in cases:
        assert all(excluded(a, b) for a, b in pairs), pairs
        nearest = _nearest_over(model, data, [(geom[a], geom[b]) for a, b in pairs], joints, values)
        assert min(nearest.values()) > 0.0, nearest
    upper_arm, forearm = "xarm7/link2_geom2", "xarm7/link4_geom4"
    assert not excluded(upper_arm, forearm)
    folded = _nearest_over(
        model, data, [(geom[upper_arm], geom[forearm])], [["xarm7/joint3"], ["xarm7/joint4"]],
        [np.linspace(-np.pi, np.pi, 13), np.radians(np.linspace(-11, 225, 24))],
    )  # fmt: skip
    assert min(folded.values()) < 0.0
