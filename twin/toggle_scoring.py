"""A logged toggle made ready to be scored against the nominal twin, and its prediction errors.

:func:`prepare` replays each logged pinch once in the nominal twin (:class:`~twin.toggle_replay.ToggleReplay`),
zeroes the logged and the replayed wrench alike, and computes the logged joint load
(:mod:`twin.toggle_signals`); a :class:`PreparedToggle` then replays the toggle under any factors of its kind and
gives the residual joint load (what :func:`twin.system_id.fit_kind` minimises). :func:`toggle_errors` scores a
prediction: the RMS joint-load error [N]; the same less what an error of the part's perceived pose may explain
(:mod:`twin.pose_error`) [N]; the RMS error of the whole force vector [N] over the same ticks; and — when the log
carries the world's true joint trajectory for evaluation (``truth["joint"]``, which nothing here fits on) — the
RMS error of the predicted part motion along the grasp point's path [m].

Zero: the logged wrench is tared as the sensor tares, by an offset fixed in the sensor's frame (the pipeline's
tare, before the descent), and turns with the sensor: logged = R (w - b) with R the sensor's orientation. The
replay is tared alike, by the offset ``b`` in the sensor frame that best explains the logged wrench over the free
descent onto the handle (~200 readings: the median of ``R^T (replayed - logged)``), so both are compared with the
same offset, turned with the sensor at every tick. (An offset held fixed in the base frame instead, as a tare is
not, reads ~0.2 N of a sensor-frame offset across the motion as the gripper turns 85 degrees with a wheel: in the
ideal world, 0.076 N of a wheel's 0.076 N of joint-load error.) The pipeline's own tare averages 10 readings, so
its noise (0.03 N realistic) a hinge's ~0.2 m lever from the sensor turns into ~0.1 N of joint load: the replay's
offset, from ~200 readings, is taken from the data instead of from that tare.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from puzzlebox.models.toggle_log import ToggleLog
from puzzlebox.twin.pose_error import PoseErrorConfig, pose_basis
from puzzlebox.twin.toggle_replay import NOMINAL, KindScales, ReplayConfig, ReplayError, ToggleReplay
from puzzlebox.twin.toggle_signals import SignalConfig, compared_mask, joint_load, path_length


@dataclass
class PreparedToggle:
    """A log ready to be scored: its replay, its logged joint load and the ticks compared."""

    log: ToggleLog
    replay: ToggleReplay
    logged_load: np.ndarray
    """``(n,)`` logged joint load over the replay's window [N]."""
    logged_force: np.ndarray
    """``(n, 3)`` logged force, tared like the load [N]."""
    mask: np.ndarray
    """``(n,)`` ticks compared."""
    signals: SignalConfig
    zero: tuple[np.ndarray, np.ndarray]
    """The replayed wrench's tare ``(force [N], torque [N·m])``, in the sensor frame (see the module docstring)."""
    basis: np.ndarray
    """``(m, k)`` on the compared ticks: how the logged joint load changes per unit error of the perceived pose
    (:func:`~twin.pose_error.pose_basis`)."""
    basis_weights: np.ndarray
    """``(k,)`` the prior's weight of each column of :attr:`basis`."""

    def predict(self, scales: KindScales = NOMINAL) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The replay's ``(joint load [N], tared force [N], joint position)`` under ``scales``, over the window up
        to its last compared tick (nothing after it is compared: the replay stops there)."""
        out = self.replay.run(scales, ticks=int(np.flatnonzero(self.mask)[-1]) + 1)
        force, torque = out.tared(self.zero)
        return joint_load(self.log, force, torque, out.tcp, self.signals), force, out.joint

    def residuals(self, scales: KindScales, load: np.ndarray | None = None, pose: bool = False) -> np.ndarray:
        """Predicted (``load``, else replayed under ``scales``) minus logged joint load on the compared ticks [N];
        ``pose``: less the part of it an error of the perceived pose explains (:attr:`basis`)."""
        if load is None:
            load = self.predict(scales)[0]
        m = self.mask[: len(load)]
        r = load[m] - self.logged_load[: len(load)][m]
        if pose and self.basis.shape[1]:
            G, w = self.basis, self.basis_weights
            r = r - G @ np.linalg.solve(G.T @ G + np.diag(w**2), G.T @ r)  # the pose error that best explains r
        return r


def prepare(
    logs: Sequence[ToggleLog],
    replay: ReplayConfig | None = None,
    signals: SignalConfig | None = None,
    pose: PoseErrorConfig | None = None,
) -> tuple[list[PreparedToggle], list[str]]:
    """The logs that can be scored (a pinch that moved a part or felt it latched, with ticks to compare), and why
    each other one cannot. ``pose``: the prior of what an error of each toggle's perceived pose may explain
    (:attr:`PreparedToggle.basis`)."""
    replay = replay or ReplayConfig()
    signals = signals or SignalConfig()
    ready, skipped = [], []
    for log in logs:
        if log.outcome not in ("moved", "blocked"):
            skipped.append(f"{log.component}: outcome {log.outcome} ({log.reason})")
            continue
        try:
            r = ToggleReplay(log, replay)
        except ReplayError as err:
            skipped.append(str(err))
            continue
        w = r.window
        mask = compared_mask(log, w, signals)
        if not mask.any():
            skipped.append(f"{log.component}: no tick to compare")
            continue
        out = r.run()  # nominal: it also simulates (and keeps) the free descent
        free = slice(0, r.descent)  # the replay's tare: what best explains the log over the free descent
        R = out.rotation[free]
        zero = (
            np.median(np.einsum("kji,kj->ki", R, out.force[free] - log.force[w][free]), axis=0),
            np.median(np.einsum("kji,kj->ki", R, out.torque[free] - log.torque[w][free]), axis=0),
        )
        force, torque = log.force[w], log.torque[w]
        load = joint_load(log, force, torque, log.tcp[w], signals)
        basis, weights = pose_basis(log, force, torque, log.tcp[w], signals, pose)
        ready.append(PreparedToggle(log, r, load, force, mask, signals, zero, basis[mask], weights))
    return ready, skipped


@dataclass(frozen=True)
class ToggleErrors:
    """How well the nominal twin predicts one toggle under given factors."""

    component: str
    kind: str
    outcome: str
    context: dict[str, Any]
    ticks: int
    load_rms: float
    """RMS joint-load error [N]."""
    pose_load_rms: float
    """RMS joint-load error less what an error of the perceived pose explains [N]."""
    force_rms: float
    """RMS length of the force vector's error over the same ticks [N]."""
    motion_rms: float | None
    """RMS error of the part's motion along the grasp point's path against the world's (evaluation-only truth) [m];
    None without it."""
    mean_logged_load: float
    mean_predicted_load: float

    def to_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def toggle_errors(toggle: PreparedToggle, scales: KindScales = NOMINAL) -> ToggleErrors:
    """Score the prediction of ``toggle`` under ``scales`` (see the module docstring)."""
    load, force, joint = toggle.predict(scales)
    n = len(load)
    m, log = toggle.mask[:n], toggle.log
    logged_load, logged_force = toggle.logged_load[:n], toggle.logged_force[:n]
    motion = None
    truth = (log.truth or {}).get("joint")
    if truth is not None:
        true_joint = np.asarray(truth, dtype=float)[toggle.replay.window][:n]
        along = path_length(log) / log.travel  # metres of path per unit of joint
        motion = float(np.sqrt(np.mean(((joint - true_joint)[m] * along) ** 2)))
    return ToggleErrors(
        log.component, log.kind, log.outcome, dict(log.context), int(m.sum()),
        float(np.sqrt(np.mean((load - logged_load)[m] ** 2))),
        float(np.sqrt(np.mean(toggle.residuals(scales, load, pose=True) ** 2))),
        float(np.sqrt(np.mean(np.sum((force - logged_force)[m] ** 2, axis=1)))),
        motion, float(logged_load[m].mean()), float(load[m].mean()),
    )  # fmt: skip


def pooled_rms(errors: Sequence[ToggleErrors], attribute: str) -> float | None:
    """RMS over every compared tick of ``errors`` (each toggle's RMS weighted by its ticks) of one error."""
    pairs = [(getattr(e, attribute), e.ticks) for e in errors if getattr(e, attribute) is not None]
    if not pairs:
        return None
    return float(math.sqrt(sum(v * v * n for v, n in pairs) / sum(n for _, n in pairs)))


__all__ = ["PreparedToggle", "ToggleErrors", "pooled_rms", "prepare", "toggle_errors"]
