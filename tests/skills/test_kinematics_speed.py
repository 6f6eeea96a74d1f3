"""The IK's fast paths compute what mink computes: the velocity QP gives ``mink.solve_ik``'s velocities (joint
limits binding or not), the IK model without meshes has the full model's kinematics, a settled target costs no
iteration, and the force median and cross products are numpy's, bit for bit."""

from __future__ import annotations

import collections

import mink
import mujoco
import numpy as np
from dm_control import mjcf

from puzzlebox.models.xarm7 import build_xarm7
from puzzlebox.skills.force_watch import median_rows
from puzzlebox.skills.joint_model import cross
from puzzlebox.skills.kinematics import ArmKinematics, se3, top_down


def test_the_velocity_qp_gives_mink_solve_iks_velocities_with_and_without_binding_limits():
    ik = ArmKinematics()
    limit = ik.limits[0]
    rng = np.random.default_rng(0)
    bound = 0
    for i in range(200):
        q = limit.lower + (limit.upper - limit.lower) * rng.uniform(0, 1, len(limit.lower))
        if i % 2:  # some joints at a limit, the target far: the limits bind
            q = np.where(rng.random(len(q)) < 0.3, np.where(rng.random(len(q)) < 0.5, limit.upper, limit.lower), q)
        ik.configuration.update(q)
        target = top_down(np.array([rng.uniform(0.2, 0.7), rng.uniform(-0.4, 0.4), rng.uniform(0.05, 0.5)]), i)
        ik.tcp.set_target(mink.SE3.from_matrix(target))
        expected = mink.solve_ik(ik.configuration, [ik.tcp, ik.posture], 0.01, "daqp", damping=1e-3, limits=ik.limits)
        scale = max(1.0, np.abs(expected).max())
        np.testing.assert_allclose(ik._qp.velocity(0.01), expected, rtol=0, atol=1e-9 * scale)
        unconstrained = np.linalg.solve(*_objective(ik))
        bound += not np.allclose(unconstrained, expected * 0.01)
    assert bound > 20  # the daqp path was exercised


def _objective(ik: ArmKinematics) -> tuple[np.ndarray, np.ndarray]:
    from mink.solve_ik import _compute_qp_objective

    H, c = _compute_qp_objective(ik.configuration, [ik.tcp, ik.posture], ik.config.damping)
    return H, -c


def test_the_ik_model_without_meshes_has_the_kinematics_and_jacobians_of_the_full_one():
    root = mjcf.RootElement(model="ik")
    root.attach(build_xarm7())
    full = mujoco.MjModel.from_xml_string(root.to_xml_string(), root.get_assets())
    lean = ArmKinematics().model
    assert lean.ngeom == 0 and full.ngeom > 0
    np.testing.assert_array_equal(lean.body_mass, full.body_mass)
    a, b = mujoco.MjData(full), mujoco.MjData(lean)
    site = full.site("xarm7/gripper/tcp").id
    rng = np.random.default_rng(1)
    for _ in range(50):
        a.qpos[:] = b.qpos[:] = full.jnt_range[:, 0] + np.ptp(full.jnt_range, axis=1) * rng.random(full.nq)
        jacobians = []
        for m, d in ((full, a), (lean, b)):
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            jac = np.zeros((6, m.nv))
            mujoco.mj_jacSite(m, d, jac[:3], jac[3:], site)
            jacobians.append(jac)
        np.testing.assert_array_equal(a.site_xpos, b.site_xpos)
        np.testing.assert_array_equal(a.site_xmat, b.site_xmat)
        np.testing.assert_array_equal(*jacobians)


def test_a_settled_target_costs_no_iteration_and_a_moved_one_is_tracked():
    ik = ArmKinematics()
    ik.set_joints(np.array([0.0, -0.247, 0.0, 0.909, 0.0, 1.156, 0.0]))
    here = ik.tcp_pose()
    q, position_error, _ = ik.step_towards(here, iterations=2)
    np.testing.assert_array_equal(q, ik.joints)
    assert position_error < ik.config.settled_position
    assert np.array_equal(ik.step_towards(here, iterations=2)[0], q)  # held: the joints stay exactly
    there = here.copy()
    there[0, 3] += 0.001
    q2, position_error, _ = ik.step_towards(there, iterations=2)
    assert not np.array_equal(q2, q) and position_error < 1e-4


def test_the_target_pose_is_minks_from_matrix():
    rng = np.random.default_rng(2)
    for i in range(200):
        T = top_down(rng.normal(size=3), rng.uniform(-np.pi, np.pi))
        if i % 2:
            T[:3, :3] = T[:3, :3] @ mink.SO3.exp(rng.normal(size=3)).as_matrix()
        np.testing.assert_array_equal(se3(T).wxyz_xyz, mink.SE3.from_matrix(T).wxyz_xyz)


def test_the_force_median_and_cross_products_are_numpys_bit_for_bit():
    rng = np.random.default_rng(3)
    for n in range(1, 7):
        for _ in range(300):
            rows = collections.deque(rng.normal(size=(n, 3)) * rng.uniform(0, 100), maxlen=5)
            np.testing.assert_array_equal(median_rows(rows), np.median(rows, axis=0))
    for a, b in rng.normal(size=(2000, 2, 3)) * 10:
        np.testing.assert_array_equal(cross(a, b), np.cross(a, b))
