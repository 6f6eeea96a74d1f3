"""What an error of a component's perceived pose explains of a toggle's joint load (:mod:`twin.toggle_signals`).

A part perceived a millimetre or half a degree off its true pose is loaded by the pinch across its motion with
forces of 5-20 N and couples of ~1 N·m, whose projection on the perceived joint then reads joint load that is
not there: ~0.5 N per millimetre of a wheel's centre (its squeezed post), ~0.1 N per millimetre of a door's hinge.
:func:`pose_basis` gives, per tick, how the logged joint load changes per unit error of the pose, and the prior
weight of each direction, so that a residual can be reported less the part of it a plausible pose error
explains (:meth:`twin.system_id.PreparedToggle.residuals`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial.transform import Rotation

from puzzlebox.models.toggle_log import ToggleLog
from puzzlebox.twin.toggle_signals import SignalConfig, joint_load


@dataclass(frozen=True)
class PoseErrorConfig:
    """How far a pose error may explain a residual away."""

    sigma: tuple[float, float, float, float] = (0.002, 0.002, 0.002, 0.017)
    """Spread of the perception error of a component's pose, ``(x, y, z)`` [m] and yaw [rad] (1 deg)
    (REALITY_NOTES §4: 0.8-2.3 mm median at 0.3-0.5 m; the wrist camera's close-up look measures a part to
    ~1-2 mm)."""
    load_sigma: float = 0.1
    """Spread of a joint-load residual that the pose's prior is weighed against, per independent sample [N]: the
    running mean makes ``SignalConfig.smooth_ticks`` ticks one."""


def pose_basis(
    log: ToggleLog,
    force: np.ndarray,
    torque: np.ndarray,
    tcp: np.ndarray,
    signals: SignalConfig,
    config: PoseErrorConfig | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(n, k)`` how the joint load of a window's tared wrench changes per unit error of the perceived pose (per
    metre of its x, y and z, per radian of its yaw: the pose is upright, its tilt not perceived), the directions
    that change nothing (a slide's position, a wheel's height and yaw) left out; and ``(k,)`` the prior weight of
    each direction (``load_sigma * sqrt(smooth_ticks) / sigma``)."""
    config = config or PoseErrorConfig()
    base = joint_load(log, force, torque, tcp, signals)
    columns, weights = [], []
    steps = (0.001, 0.001, 0.001, 0.002)  # [m, m, m, rad]
    centre = log.pose[:3, 3]
    for i, step in enumerate(steps):
        if i < 3:
            shift = np.zeros(3)
            shift[i] = step
            axis, origin = log.axis, log.origin + shift
        else:  # a yaw error turns the joint about the vertical through the marker
            R = Rotation.from_euler("z", step).as_matrix()
            axis, origin = R @ log.axis, centre + R @ (log.origin - centre)
        column = (joint_load(replace(log, axis=axis, origin=origin), force, torque, tcp, signals) - base) / step
        if np.abs(column).max() * step > 1e-6:  # a direction that changes the load
            columns.append(column)
            weights.append(config.load_sigma * np.sqrt(max(signals.smooth_ticks, 1)) / config.sigma[i])
    return (np.column_stack(columns) if columns else np.zeros((len(base), 0))), np.array(weights)


__all__ = ["PoseErrorConfig", "pose_basis"]
