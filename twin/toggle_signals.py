"""What a toggle's wrench is compared on — the same treatment for the logged and the predicted one.

**The joint load** [N]: the generalized force the gripper applies to the component's joint, computed from the
whole wrench on the wrist sensor and the perceived joint (the log's axis and origin), expressed as the equivalent
force at the grasp point along its motion (divided by the grasp point's distance from a hinge's axis; a slide's
is the force along its axis). Positive drives the part the way the toggle moves it. It is the part of the wrench
that does work on the joint: what the joint's damping, friction, latch, inertia and weight answer. The rest of
the wrench does no work on the joint and no joint parameter sets it: the pinched post squeezed when the planned
path misses the true one by the perception error (on a wheel, whose gripper turns with the knob, 15-20 N along
the path against a free knob, with a couple cancelling it), the pads' torsional friction on a door's pivoting
post (~2 N at the handle, with an equal and opposite couple).

Treatment, as the pipeline senses (``skills.primitives``): the wrench comes tared (the caller's zero:
:mod:`twin.toggle_scoring`); the load is computed per tick and passed through a causal running median of
``median_ticks`` (the pipeline's filter), then a causal running mean of ``smooth_ticks`` (the F/T noise averaged
down to the load's slow part); it is compared over the pinch's actuation only, and for a part that moved only
while it moved clear of its ends (:func:`compared_mask`): the first ticks of a grasp are the pads' impact on a
post placed by perception, and a part's end stop is where the real part is, not where perception put the
replay's. Frames: the robot base frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from puzzlebox.models.toggle_log import ToggleLog
from puzzlebox.models.xarm7 import TCP_OFFSET


@dataclass(frozen=True)
class SignalConfig:
    """How wrenches are treated before comparing them."""

    median_ticks: int = 5
    """Length of the causal running median of the joint load [ticks] (the pipeline's ``force_filter_samples``)..."""
    smooth_ticks: int = 20
    """... then of a causal running mean [ticks] (0.2 s): the load's slow part, which the joint's friction and
    damping set; the F/T noise (0.1 N a reading, realistic) reaches a hinge's load ~3 times larger through the
    sensor's ~0.2 m lever about the hinge, and a median of 5 leaves 0.05-0.15 N of it, as much as the effects
    identified."""
    moving_from: float = 0.02
    """A moved part's loads are compared once the robot measured it this fraction of its travel past where the
    actuation began [-] (the grasp's first pull: a post the pads shoved at the grasp, the joint's breakaway)..."""
    moving_to: float = 0.9
    """... until it measured it at this fraction of its travel [-]: its end stop is where the real part is, a few
    mm from where perception put the replay's, and the TCP driven on into it loads the grasp by ~2 N per mm."""


def lever(log: ToggleLog) -> float:
    """Distance of the grasp point from a hinge's axis [m] (1 for a slide: its load is a force already)."""
    if log.joint != "hinge":
        return 1.0
    r = log.grasp_point - log.origin
    return float(np.linalg.norm(r - np.dot(r, log.axis) * log.axis))


def path_length(log: ToggleLog) -> float:
    """Length of the grasp point's path over the whole travel [m]."""
    return log.travel * lever(log) if log.joint == "hinge" else log.travel


def sensor_origin(tcp: np.ndarray) -> np.ndarray:
    """``(n, 3)`` origin of the wrist F/T sensor [m] from TCP poses ``(n, 4, 4)``: ``TCP_OFFSET`` back along the
    approach axis (``models.xarm7``: the sensor's site is the flange's origin, where the gripper is mounted)."""
    return tcp[:, :3, 3] - TCP_OFFSET * tcp[:, :3, 2]


def running_mean(values: np.ndarray, n: int) -> np.ndarray:
    """Causal running mean over ``n`` samples (fewer at the start) of a ``(k,)`` series."""
    if n <= 1:
        return values.copy()
    sums = np.cumsum(np.concatenate([[0.0], values]))
    counts = np.minimum(np.arange(1, len(values) + 1), n)
    return (sums[1:] - sums[np.maximum(np.arange(1, len(values) + 1) - n, 0)]) / counts


def running_median(values: np.ndarray, n: int) -> np.ndarray:
    """Causal running median over ``n`` samples (fewer at the start) of a ``(k,)`` series."""
    if n <= 1:
        return values.copy()
    padded = np.concatenate([np.full(n - 1, np.nan), values])
    windows = np.lib.stride_tricks.sliding_window_view(padded, n)
    return np.nanmedian(windows, axis=1)


def joint_load(
    log: ToggleLog, force: np.ndarray, torque: np.ndarray, tcp: np.ndarray, config: SignalConfig
) -> np.ndarray:
    """``(n,)`` joint load [N] of a window's wrench (load on the flange, base frame, about the sensor's origin;
    tared) with the TCP poses it was read at (see the module docstring)."""
    f, t = force, torque
    # the gripper pushes the part with -f about the sensor origin s (it loads the flange with f)
    if log.joint == "hinge":
        s = sensor_origin(tcp)
        generalized = -(np.cross(s - log.origin, f) + t) @ log.axis / lever(log)
    else:
        generalized = -(f @ log.axis)
    sign = 1.0 if log.opening else -1.0
    return running_mean(running_median(sign * generalized, config.median_ticks), config.smooth_ticks)


def measured_progress(log: ToggleLog, tcp: np.ndarray) -> np.ndarray:
    """``(n,)`` fraction of the travel covered towards the other state, from TCP positions on the perceived joint
    (as ``skills.primitives.Pinch.progress_of`` measures it) [-]."""
    p = tcp[:, :3, 3]
    begin = 0.0 if log.opening else 1.0
    start = _grasp_point_at(log, begin)
    if log.joint == "slide":
        fraction = (p - start) @ log.axis / log.travel
    else:
        a = start - log.origin
        a = a - np.dot(a, log.axis) * log.axis
        b = p - log.origin
        b = b - np.outer(b @ log.axis, log.axis)
        fraction = np.arctan2(np.cross(a, b) @ log.axis, b @ a) / log.travel
    return fraction if log.opening else -fraction


def _grasp_point_at(log: ToggleLog, fraction: float) -> np.ndarray:
    amount = fraction * log.travel
    if log.joint == "slide":
        return log.grasp_point + amount * log.axis
    r, k = log.grasp_point - log.origin, log.axis
    rotated = r * np.cos(amount) + np.cross(k, r) * np.sin(amount) + k * np.dot(k, r) * (1 - np.cos(amount))
    return log.origin + rotated


def compared_mask(log: ToggleLog, window: slice, config: SignalConfig) -> np.ndarray:
    """Which ticks of ``window`` the loads are compared on: the pinch's actuation; for a part the robot felt move,
    only while it measured it between ``moving_from`` and ``moving_to`` of its travel (a latched part's every
    actuation tick: it never got there)."""
    mask = log.in_phase("actuating")[window].copy()
    if log.outcome != "blocked" and mask.any():
        progress = measured_progress(log, log.tcp[window])
        covered = progress - progress[np.argmax(mask)]  # from where the actuation began: the grasp point is off
        mask &= (covered >= config.moving_from) & (progress <= config.moving_to)  # by the perception error
    return mask


__all__ = [
    "SignalConfig",
    "compared_mask",
    "joint_load",
    "lever",
    "measured_progress",
    "path_length",
    "running_mean",
    "running_median",
    "sensor_origin",
]
