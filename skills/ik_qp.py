"""One differential-IK step of :class:`skills.kinematics.ArmKinematics` — mink's ``solve_ik`` for exactly its
problem (a FrameTask, a PostureTask, a ConfigurationLimit, daqp) without the per-call generality.

A toggle runs ~15 000 IK iterations (two per 10 ms control tick); through ``mink.solve_ik`` half of each
iteration's ~0.2 ms went to assembling the general QP (stacked task residuals, ``qpsolvers.Problem``, the
limit rows built afresh). Here the same quadratic program is built from the tasks' own residuals and
solved in closed form: its Hessian is positive definite (the posture task and the damping), so the
unconstrained minimiser is *the* QP solution whenever it lies within the joint-limit bounds — nearly always,
the arm working far from its limits. Only otherwise is daqp called, on the same bounds mink gives it.
"""

from __future__ import annotations

import daqp
import mink
import mujoco
import numpy as np

from puzzlebox.skills.errors import IKFailure


class VelocityQP:
    """The QP of one IK iteration on a hinge/slide-only robot model (see the module docstring)."""

    def __init__(
        self,
        configuration: mink.Configuration,
        frame: mink.FrameTask,
        posture: mink.PostureTask,
        limit: mink.ConfigurationLimit,
        damping: float,
    ) -> None:
        model = configuration.model
        kinds = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
        if model.nq != model.nv or not np.isin(model.jnt_type, kinds).all():
            raise ValueError("VelocityQP needs a model of hinge and slide joints only (q and v then coincide)")
        self._configuration, self._frame, self._posture = configuration, frame, posture
        self._nv = model.nv
        self._damping = damping
        self._limited = np.asarray(limit.indices, dtype=np.int64)
        self._lower, self._upper = limit.lower[self._limited], limit.upper[self._limited]
        self._limit_gain = limit.gain
        self._rows = np.eye(model.nv)[self._limited]  # the limit rows for daqp: blower <= dq[limited] <= bupper
        self._sense = np.zeros(len(self._limited), dtype=np.intc)

    def velocity(self, dt: float) -> np.ndarray:
        """The joint velocity [rad/s] that ``mink.solve_ik(configuration, [frame, posture], dt, "daqp",
        damping, limits=[limit])`` returns, up to rounding.

        Raises:
            IKFailure: if daqp finds no solution (it never should: the bounds always contain ``dq = 0``).
        """
        q = self._configuration.data.qpos
        W, e, mu = self._frame.compute_qp_residual(self._configuration)
        posture = self._posture
        assert posture.target_q is not None  # ArmKinematics set it
        cost = posture.cost
        # hinge/slide joints: q ⊖ q* is a plain difference (mink's mj_differentiatePos)
        weighted_posture_error = cost * (-posture.gain * (q - posture.target_q))
        mu += posture.lm_damping * float(weighted_posture_error @ weighted_posture_error)
        H = W.T @ W
        H.flat[:: self._nv + 1] += cost * cost + self._damping + mu
        c = -(e @ W) - weighted_posture_error * cost
        q_limited = q[self._limited]
        low = -self._limit_gain * (q_limited - self._lower)
        high = self._limit_gain * (self._upper - q_limited)
        dq = np.linalg.solve(H, -c)
        inside = dq[self._limited]
        if not ((inside >= low).all() and (inside <= high).all()):
            dq, _, exitflag, _ = daqp.solve(H, c, self._rows, high, low, self._sense)
            if exitflag <= 0:
                raise IKFailure(f"the IK quadratic program has no solution (daqp exit flag {exitflag})")
        return dq / dt


__all__ = ["VelocityQP"]
