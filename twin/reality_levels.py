"""Reality profiles at a *level* of one factor: the knob of ``experiment.py reality``.

A factor is a group of a :class:`~twin.reality.RealityProfile`'s fields (the camera's geometry, the
images, the F/T sensor, the arm, the box's physics, jams). At level 0 the factor is as in ``ideal``, at
1 as in ``realistic``, at 2 as in ``harsh``; between and beyond, each number is interpolated linearly
between the two presets around it (a :class:`~twin.reality.ScaleRange` by its bounds). Every field
outside the factor stays ideal, and the box is placed at random reachable poses at every level (the
issue's protocol), so level 0 is the ideal cell with a placed box.

:func:`force_noise_profile` is the other sweep: the F/T force noise alone at an absolute σ [N] (the
torque noise at the realistic ratio of 3 cm), to find where outcome agreement drops below 99 %.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from puzzlebox.models.placement import PlacementRange
from puzzlebox.twin.errors import ProfileError
from puzzlebox.twin.reality import HARSH, IDEAL, REALISTIC, ForceTorqueReality, RealityProfile, ScaleRange

FACTORS: dict[str, tuple[tuple[str, str], ...]] = {
    "camera-geometry": tuple(
        ("camera", f)
        for f in ("focal_error", "principal_error", "k1", "k2", "p", "mount_translation", "mount_rotation")
    ),
    "image": tuple(
        ("camera", f)
        for f in (
            "noise_sigma",
            "gain",
            "exposure",
            "defocus_sigma",
            "occluder_probability",
            "dropped_frame_probability",
        )
    ),  # fmt: skip
    "force-torque": tuple(("force_torque", f.name) for f in dataclasses.fields(ForceTorqueReality)),
    "arm": tuple(("arm", f) for f in ("encoder_noise", "command_latency", "stall_rate", "stall_duration", "tcp_bias")),
    "physics": tuple(
        ("physics", f)
        for f in (
            "friction_scale",
            "pad_friction",
            "grip_force_scale",
            "joint_damping_scale",
            "joint_friction_scale",
            "mass_scale",
            "latch_compliance_scale",
            "kind_joint_damping_scale",
            "kind_joint_friction_scale",
            "kind_latch_compliance_scale",
        )
    ),  # fmt: skip
    "jams": (("physics", "jam_probability"),),
}
"""Factor name -> the ``(section, field)`` pairs of a profile it sets."""
ALL = "all"
"""Every factor at once."""
MAX_LEVEL = 3.0
"""Highest level [-]: beyond ``harsh`` (2) the harsh-minus-realistic step is extrapolated."""

_NOMINAL: dict[tuple[str, str], float] = {("physics", "pad_friction"): 1.0}
"""What a None means for an interpolated field: the model's own value (``PhysicsReality.pad_friction``)."""
_TORQUE_LEVER = 0.03
"""Torque noise per force noise in :func:`force_noise_profile` [m] (realistic: 3 mN·m / 0.1 N)."""


def factor_names() -> tuple[str, ...]:
    """Every factor :func:`profile_at` knows, ``all`` last."""
    return (*FACTORS, ALL)


def profile_at(factor: str, level: float, cell_seed: int = 0) -> RealityProfile:
    """The profile with ``factor`` (a key of :data:`FACTORS`, or ``all``) at ``level`` (0 ideal, 1
    realistic, 2 harsh, up to :data:`MAX_LEVEL`), everything else ideal, the box placed anywhere reachable.

    Raises:
        ProfileError: an unknown factor (the message lists them) or a level outside ``[0, MAX_LEVEL]``.
    """
    if factor != ALL and factor not in FACTORS:
        raise ProfileError(f"unknown reality factor {factor!r}; known: {list(factor_names())}")
    if not (math.isfinite(level) and 0.0 <= level <= MAX_LEVEL):
        raise ProfileError(f"a factor level is in [0, {MAX_LEVEL:g}] (0 ideal, 1 realistic, 2 harsh), got {level!r}")
    fields = [pair for pairs in FACTORS.values() for pair in pairs] if factor == ALL else list(FACTORS[factor])
    sections: dict[str, dict[str, Any]] = {}
    for section, name in fields:
        sections.setdefault(section, {})[name] = _value_at(section, name, level)
    replaced = {s: dataclasses.replace(getattr(IDEAL, s), **values) for s, values in sections.items()}
    return dataclasses.replace(
        IDEAL, name=f"{factor}@{level:g}", cell_seed=cell_seed, placement=PlacementRange(), **replaced
    )


def force_noise_profile(force_noise: float, cell_seed: int = 0) -> RealityProfile:
    """Ideal but for white F/T noise of ``force_noise`` [N] per axis (and ``force_noise x 3 cm`` [N·m] of
    torque noise), the box placed anywhere reachable."""
    if not (math.isfinite(force_noise) and force_noise >= 0):
        raise ProfileError(f"force noise must be finite and >= 0 [N], got {force_noise!r}")
    ft = ForceTorqueReality(force_noise=force_noise, torque_noise=force_noise * _TORQUE_LEVER)
    return dataclasses.replace(
        IDEAL, name=f"force-noise@{force_noise:g}N", cell_seed=cell_seed, force_torque=ft, placement=PlacementRange()
    )


def _value_at(section: str, name: str, level: float) -> Any:
    ideal, realistic, harsh = (getattr(getattr(p, section), name) for p in (IDEAL, REALISTIC, HARSH))
    low, high, t = (ideal, realistic, level) if level <= 1.0 else (realistic, harsh, level - 1.0)
    if level == 0.0:
        return ideal
    if isinstance(high, ScaleRange) or isinstance(low, ScaleRange):
        a, b = low or ScaleRange(), high or ScaleRange()
        lo, hi = _lerp(a.low, b.low, t), _lerp(a.high, b.high, t)
        return ScaleRange(max(lo, 1e-3), max(hi, lo, 1e-3), b.log)
    if name == "rate_hz":  # a sampling rate is a property of the sensor, not a magnitude of error
        return realistic if level <= 1.0 else harsh
    if low is None or high is None:
        nominal = _NOMINAL.get((section, name))
        if nominal is None:  # a limit (saturation) either exists or does not: the worse preset's
            return high if high is not None else low
        low, high = (nominal if low is None else low), (nominal if high is None else high)
    if isinstance(high, tuple):
        assert isinstance(low, tuple)  # the presets' fields have one type (the nominal ones are floats)
        return tuple(_clip(section, name, _lerp(a, b, t)) for a, b in zip(low, high, strict=True))
    if isinstance(high, int) and not isinstance(high, bool) and isinstance(low, int):
        return max(1, round(_lerp(low, high, t))) if name == "occluder_count" else round(_lerp(low, high, t))
    return _clip(section, name, _lerp(float(low), float(high), t))


def _lerp(a: float, b: float, t: float) -> float:
    if t == 1.0:  # exactly the preset at its own level (0.95 + (0.3 - 0.95) is 0.30000000000000004)
        return b
    return a + (b - a) * t


def _clip(section: str, name: str, value: float) -> float:
    """Keep extrapolated values valid: probabilities in [0, 1], scales and errors positive."""
    if name.endswith("probability"):
        return min(max(value, 0.0), 1.0)
    if name == "focal_error":
        return min(max(value, 0.0), 0.45)
    if name in ("pad_friction", "grip_force_scale"):
        return max(value, 0.05)
    return max(value, 0.0)
