"""The differential IK of ``puzzlebox/BoxManipulation-v0``: one damped-least-squares step a control step, on the skills'
robot-only arm model.

An action moves the TCP target at most 1 cm and 0.1 rad, so one linearised step from the posture commanded last
lands within a fraction of a millimetre of it, and what is left is taken up at the next step. The skills' mink QP
(``skills.kinematics.ArmKinematics.step_towards``: a frame task, a posture task and the joint limits) costs
~130 us an iteration, which is the environment's whole overhead budget (a third of the ~0.45 ms of CPU that 25
physics steps of the default box take); the same step in closed form takes 25-50 us:

    dq = J^T (J J^T + damping I)^-1 (e - J z) + z,    z = posture_gain (q_rest - q)

with ``J`` the TCP's 6x7 Jacobian (position and rotation, base frame), ``e`` its position [m] and rotation [rad]
error, the damping keeping the step small near singularities and ``z`` a pull towards the rest posture that the task
leaves free (the redundant arm stays relaxed, as the skills' posture task keeps it); the joints are then clipped to
their ranges. It runs on :class:`~puzzlebox.skills.kinematics.ArmKinematics`'s own model, the arm alone, as a real
controller's URDF: it never sees the box.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np

from puzzlebox.skills.kinematics import TCP_SITE, ArmKinematics


class DifferentialIK:
    """One IK step at a time towards a TCP pointing straight down (see the module docstring). Its arithmetic is
    MuJoCo's own (``mju_*``) on preallocated arrays: what it costs is the calls, ~20 of them.

    Args:
        rest: the posture the redundancy is pulled towards [rad], joints 1..7.
        damping: added to the diagonal of ``J J^T`` (1e-4: felt only where its smallest singular value falls
            towards 1e-2, near a singular posture).
        posture_gain: fraction of the way to ``rest`` asked of the null space each step [-].
    """

    def __init__(self, rest: tuple[float, ...], damping: float = 1e-4, posture_gain: float = 0.02) -> None:
        self.kinematics = ArmKinematics()
        m = self._model = self.kinematics.model
        self._data = self.kinematics.configuration.data
        self._site = m.site(f"xarm7/{TCP_SITE}").id
        arm = list(range(7))
        if list(self.kinematics.arm_qpos) != arm or [int(m.jnt_dofadr[j]) for j in arm] != arm:
            raise ValueError("the IK model must start with the 7 arm joints (qpos and dofs 0..6)")
        self._low, self._high = m.jnt_range[:7, 0].copy(), m.jnt_range[:7, 1].copy()
        self._rest = np.asarray(rest, dtype=float)
        self._damping, self._gain = damping, posture_gain
        self._jac = np.zeros((6, m.nv))
        self._J, self._A = np.zeros((6, 7)), np.zeros((6, 6))
        self._A_diagonal = np.einsum("ii->i", self._A)  # a writable view: the damping added in place
        self._error, self._x = np.zeros(6), np.zeros(6)
        self._z, self._q = np.zeros(7), np.zeros(7)
        self._quat, self._target_quat, self._turn = np.zeros(4), np.zeros(4), np.zeros(3)

    def reset(self, q: np.ndarray, limits: np.ndarray | None = None) -> np.ndarray:
        """Start from arm joints ``q`` [rad], the joints kept within ``limits`` ``(7, 2)`` [rad] (default the
        model's ranges); returns the TCP pose there (4x4, base frame, [m])."""
        if limits is not None:
            self._low, self._high = np.maximum(limits[:, 0], self._low), np.minimum(limits[:, 1], self._high)
        self.kinematics.set_joints(q)
        return self.kinematics.tcp_pose()

    def step(self, position: Sequence[float] | np.ndarray, yaw: float) -> np.ndarray:
        """One step towards the TCP at ``position`` [m] pointing down, turned ``yaw`` [rad] (as
        ``skills.kinematics.top_down``); returns the arm joints [rad] (a new array)."""
        m, d, site = self._model, self._data, self._site
        jac, J, A, error, x, z, q = self._jac, self._J, self._A, self._error, self._x, self._z, self._q
        mujoco.mj_jacSite(m, d, jac[:3], jac[3:], site)
        J[:] = jac[:, :7]
        # top_down(yaw) is a half turn about the horizontal axis at yaw / 2: the quaternion (0, cos, sin, 0)
        self._target_quat[1], self._target_quat[2] = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
        xmat = d.site_xmat[site]
        mujoco.mju_mat2Quat(self._quat, xmat)
        mujoco.mju_subQuat(self._turn, self._target_quat, self._quat)  # in the TCP's frame...
        mujoco.mju_mulMatVec(error[3:], xmat.reshape(3, 3), self._turn)  # ... and in the base frame
        np.subtract(position, d.site_xpos[site], out=error[:3])
        qpos = d.qpos[:7]
        np.subtract(self._rest, qpos, out=z)
        z *= self._gain
        mujoco.mju_mulMatMatT(A, J, J)
        self._A_diagonal += self._damping  # (A.flat[::7]: the same sums through a ~2 us flat iterator)
        mujoco.mju_mulMatVec(x, J, z)
        error -= x
        mujoco.mju_cholFactor(A, 0.0)
        mujoco.mju_cholSolve(x, A, error)
        mujoco.mju_mulMatTVec(q, J, x)
        q += z
        q += qpos
        np.minimum(np.maximum(q, self._low, out=q), self._high, out=qpos)  # np.clip's own overhead was ~3 us
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        return qpos.copy()


__all__ = ["DifferentialIK"]
