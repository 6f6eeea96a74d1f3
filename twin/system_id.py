"""System identification: the nominal twin's per-kind joint damping, joint friction and latch compliance fitted to
logged toggles (:class:`models.toggle_log.ToggleLog`), so that it predicts what the world did.

Each logged toggle is replayed in the nominal twin (:class:`~twin.toggle_replay.ToggleReplay`: the pipeline's own
commands, the part where the robot perceived it), and its predicted wrench compared with the logged one as the
joint load (:mod:`twin.toggle_signals`: the generalized force on the part's joint, in newtons at the grasp point,
zeroed, median-filtered and averaged alike: :mod:`twin.toggle_scoring`). :func:`fit_kind` minimises, with
:func:`scipy.optimize.least_squares`, the sum over a kind's training toggles and their compared ticks of the
squared joint-load error, over the kind's factors ``(damping, friction, latch)`` in log scale within
``[low, high]``, plus a weak prior ``prior_weight * ln(factor)`` per factor that holds a factor the data do not
inform at the nominal 1. A latch's compliance is fitted only on kinds with latched toggles, and even there hardly
informed: the latch is ~100 times stiffer than the pinched handle in series with it. A kind's factors act on its
toggles only, so each kind is fitted alone.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from puzzlebox.twin.toggle_replay import KindScales
from puzzlebox.twin.toggle_scoring import PreparedToggle

PARAMETERS = ("damping", "friction", "latch")
"""The factors of a kind, in the order of :meth:`KindScales.as_array`."""


@dataclass(frozen=True)
class FitConfig:
    """How a kind's factors are fitted."""

    low: float = 0.2
    """Smallest factor allowed [-]."""
    high: float = 5.0
    """Largest factor allowed [-]."""
    prior_weight: float = 0.3
    """Residual a factor of ``e`` (1 in log scale) adds to the joint-load residuals [N]: weak beside thousands of
    ticks, decisive for a factor the data leave free."""
    diff_step: float = 0.05
    """Finite-difference step of the Jacobian, in log scale [-] (a 5 % change: contact makes the replay's
    response to a much smaller one noisy)."""
    max_nfev: int = 20
    """Most evaluations of the residuals per kind (each replays every toggle of the kind), Jacobians aside."""
    tolerance: float = 1e-3
    """``xtol`` and ``ftol`` of the solver [-]: a factor to 0.1 %, the cost to 0.1 % (the replay's own
    repeatability under contact is coarser)."""
    pose: bool = False
    """Fit the residuals less what an error of each toggle's perceived pose explains
    (:attr:`~twin.toggle_scoring.PreparedToggle.basis`) instead of the raw ones: on a wheel, whose squeezed post
    loads its joint by ~0.5 N per millimetre of error in its perceived centre, that explains away the friction and
    damping too."""

    def __post_init__(self) -> None:
        if not 0 < self.low < 1 < self.high or self.prior_weight < 0 or self.diff_step <= 0 or self.max_nfev < 1:
            raise ValueError(f"invalid fit config {self}")
        if not 0 < self.tolerance < 1:
            raise ValueError(f"invalid fit config {self}")


@dataclass
class KindFit:
    """The outcome of fitting one kind."""

    kind: str
    scales: KindScales
    fitted: tuple[str, ...]
    """Which factors were free (a latch only with latched toggles to inform it)."""
    toggles: int
    ticks: int
    rms_before: float
    """RMS joint-load error on the training toggles at the nominal factors [N]."""
    rms_after: float
    """... at the fitted ones [N]."""
    nfev: int
    wall_time_s: float
    message: str
    jacobian_sensitivity: dict[str, float] = field(default_factory=dict)
    """RMS change of the training residuals per unit change of each free factor's log at the optimum [N]: ~0 is a
    factor the data do not inform."""

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind, "factors": dict(zip(PARAMETERS, self.scales.as_array().tolist(), strict=True)),
            "fitted": list(self.fitted), "toggles": self.toggles, "ticks": self.ticks,
            "rms_before_n": self.rms_before, "rms_after_n": self.rms_after, "nfev": self.nfev,
            "wall_time_s": self.wall_time_s, "message": self.message, "sensitivity_n": self.jacobian_sensitivity,
        }  # fmt: skip


def fit_kind(kind: str, toggles: Sequence[PreparedToggle], config: FitConfig | None = None) -> KindFit:
    """Fit ``kind``'s factors to its ``toggles`` (see the module docstring).

    Raises:
        ValueError: no toggle of ``kind`` among ``toggles``.
    """
    config = config or FitConfig()
    mine = [t for t in toggles if t.log.kind == kind]
    if not mine:
        raise ValueError(f"no toggle of kind {kind!r} to fit (kinds given: {sorted({t.log.kind for t in toggles})})")
    start = time.perf_counter()
    free = [p for p in PARAMETERS if p != "latch" or any(t.replay.latched for t in mine)]
    weight = config.prior_weight

    def scales_of(x: np.ndarray) -> KindScales:
        values: dict[str, float] = dict.fromkeys(PARAMETERS, 1.0)
        values.update({p: float(math.exp(v)) for p, v in zip(free, x, strict=True)})
        return KindScales(**values)

    def residuals(x: np.ndarray) -> np.ndarray:
        data = [t.residuals(scales_of(x), pose=config.pose) for t in mine]
        return np.concatenate([*data, weight * x])

    x0 = np.zeros(len(free))
    before = residuals(x0)[: -len(free)]
    bounds = (np.full(len(free), math.log(config.low)), np.full(len(free), math.log(config.high)))
    result = least_squares(
        residuals, x0, bounds=bounds, diff_step=config.diff_step, max_nfev=config.max_nfev, x_scale=1.0,
        xtol=config.tolerance, ftol=config.tolerance,
    )  # fmt: skip
    after = result.fun[: -len(free)]
    jac = result.jac[: -len(free)]
    sensitivity = {p: float(np.sqrt(np.mean(jac[:, i] ** 2))) for i, p in enumerate(free)}
    return KindFit(
        kind, scales_of(result.x), tuple(free), len(mine), len(before),
        float(np.sqrt(np.mean(before**2))), float(np.sqrt(np.mean(after**2))), int(result.nfev),
        time.perf_counter() - start, str(result.message), sensitivity,
    )  # fmt: skip


__all__ = ["PARAMETERS", "FitConfig", "KindFit", "fit_kind"]
