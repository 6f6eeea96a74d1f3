"""The arm's joint encoders and what the arm's own kinematics report from them.

A reading is the true joint position plus Gaussian noise drawn once per reading time (a driver
reports one state per control cycle, so two reads in the same instant agree). The TCP pose and the F/T
sensor's orientation are computed from that reading by the *nominal* kinematics: with a TCP bias in the
cell (the physical gripper offset from where the model puts it, :attr:`~twin.reality.ArmReality.tcp_bias`)
the reported TCP is not the true one, as on a real arm.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np


def _pose(pos: np.ndarray, xmat: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = xmat.reshape(3, 3)
    T[:3, 3] = pos
    return T


class JointEncoders:
    """Encoders of the 7 arm joints and the reported TCP pose (see the module docstring)."""

    def __init__(
        self,
        data: mujoco.MjData,
        arm_qpos: np.ndarray,
        tcp_site: int,
        ft_site: int,
        nominal_model: mujoco.MjModel,
        noise: float,
        exact: bool,
    ) -> None:
        """``exact``: the cell's kinematics are the nominal ones (no TCP bias) and the encoders noiseless;
        the TCP pose and F/T orientation are then read from the simulation itself."""
        self._data = data
        self._arm_qpos = arm_qpos
        self._tcp = tcp_site
        self._ft = ft_site
        self._noise = noise
        self._exact = exact and noise == 0
        self._nominal_model = nominal_model
        self._nominal: mujoco.MjData | None = None  # allocated on first use (never, in exact mode)
        self._nominal_q: np.ndarray | None = None  # the joint positions it holds the kinematics of

    def reset(self, rng: np.random.Generator) -> None:
        self._rng = rng
        self._time = float("nan")
        self._error = np.zeros(len(self._arm_qpos))

    def positions(self) -> np.ndarray:
        """Joint positions as the encoders read them now [rad]."""
        q = self._data.qpos[self._arm_qpos]  # fancy indexing: a copy
        if self._noise == 0:
            return q
        time = float(self._data.time)
        if time != self._time:
            self._time = time
            self._error = self._rng.normal(0.0, self._noise, len(q))
        return q + self._error

    def tcp_pose(self) -> np.ndarray:
        """4x4 TCP pose in the base frame as the nominal kinematics compute it from :meth:`positions` [m]."""
        d = self._data if self._exact else self._kinematics(self.positions())
        return _pose(d.site_xpos[self._tcp], d.site_xmat[self._tcp])

    def ft_rotation(self) -> np.ndarray:
        """3x3 orientation of the F/T sensor frame in the base frame, by the nominal kinematics from
        :meth:`positions` (as :meth:`tcp_pose`, so the two agree)."""
        d = self._data if self._exact else self._kinematics(self.positions())
        return d.site_xmat[self._ft].reshape(3, 3).copy()

    def nominal_tcp_pose(self, q: np.ndarray) -> np.ndarray:
        """The nominal kinematics' TCP pose for joint positions ``q`` [rad] -> [m]."""
        d = self._kinematics(np.asarray(q, dtype=float))
        return _pose(d.site_xpos[self._tcp], d.site_xmat[self._tcp])

    def _kinematics(self, q: np.ndarray) -> mujoco.MjData:
        """The nominal model's data with its kinematics at arm joint positions ``q`` (computed once per ``q``:
        a control tick asks for the TCP and the F/T orientation of the same reading)."""
        if self._nominal is None:
            self._nominal = mujoco.MjData(self._nominal_model)
        if self._nominal_q is None or not (q == self._nominal_q).all():  # np.array_equal: 7 joints each
            self._nominal.qpos[self._arm_qpos] = q
            mujoco.mj_kinematics(self._nominal_model, self._nominal)
            self._nominal_q = q.copy()
        return self._nominal

    def get_state(self) -> dict[str, Any]:
        return {"rng": self._rng.bit_generator.state, "time": self._time, "error": self._error.copy()}

    def set_state(self, state: dict[str, Any]) -> None:
        self._rng.bit_generator.state = state["rng"]
        self._time = state["time"]
        self._error = state["error"].copy()
