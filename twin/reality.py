"""Reality profiles: everything in which a real xArm-7 cell differs from the twin's nominal model.

A :class:`RealityProfile` is applied only inside the twin (DESIGN.md, "Layers"): the robot's pipeline
sees its effects (noisy wrenches, distorted images, a grasp that slips, a component that jams) but
never the profile. It has two kinds of randomness:

- the cell's *fixed* imperfections (camera intrinsic, distortion and mounting errors, the TCP bias, and
  one joint damping, joint friction and latch compliance factor per component kind) are drawn once from
  :attr:`RealityProfile.cell_seed`: a cell is built and calibrated once, its box's hinges, slides and wheel
  bearings have the friction they have, and every trial in it meets the same errors;
- the *per-trial* randomness (sensor noise, F/T bias and drift, physics draws, jams, command stalls,
  the box placement) is drawn from the session's seed. A component's joint damping, joint friction and
  latch compliance are its kind's cell factor times its own per-trial factor.

Presets (:data:`PRESETS`): ``ideal`` (no imperfection: the nominal world), ``realistic`` and ``harsh``,
whose values trace to the rows of ``REALITY_NOTES.md`` (its "Presets" table and sections 1-6) as the
comment beside each value says; "E" marks an estimate with no source. :func:`load_profile` reads a
preset name or a JSON file (:meth:`RealityProfile.to_dict` is that JSON), refusing unknown keys and
out-of-range values with a :class:`~twin.errors.ProfileError` that names the key.

Distributions: a symmetric error "±a" is drawn uniformly in ``[-a, a]``; a magnitude of a vector error
(mounting translation and rotation, TCP bias, F/T bias, drift rate) is exact, in a random direction
drawn uniformly on the sphere, so a profile states how large an error is and only its direction is
random; a :class:`ScaleRange` multiplies a nominal value.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.models.json_input import JsonInputError, read_json
from puzzlebox.models.placement import PlacementRange
from puzzlebox.twin.errors import ProfileError

__all__ = [
    "PRESETS",
    "ArmReality",
    "CameraReality",
    "ForceTorqueReality",
    "PhysicsReality",
    "RealityProfile",
    "ScaleRange",
    "load_profile",
]


def _check(condition: bool, key: str, message: str) -> None:
    if not condition:
        raise ProfileError(f"{key}: {message}")


def _non_negative(obj: Any, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        _check(math.isfinite(value) and value >= 0, name, f"must be finite and >= 0, got {value!r}")


def _probability(obj: Any, *names: str) -> None:
    for name in names:
        value = getattr(obj, name)
        _check(math.isfinite(value) and 0.0 <= value <= 1.0, name, f"is a probability in [0, 1], got {value!r}")


MAX_OCCLUDERS = 20
"""Most occluders a frame may carry (20 of up to 80 px cover most of a 640 x 480 frame; 1e6 was accepted)."""
MAX_FT_DELAY = 0.5
"""Oldest sample an F/T reading may return [s]: 50 times a real xArm's 10 ms (REALITY_NOTES), past any cell's."""


@dataclass(frozen=True)
class ScaleRange:
    """A random multiplier of a nominal value, drawn once per trial (or once per cell, for the cell's fields)."""

    low: float = 1.0
    """Smallest factor [-]."""
    high: float = 1.0
    """Largest factor [-]."""
    log: bool = False
    """Draw log-uniformly (``exp(U(ln low, ln high))``, as OpenAI's damping ×logU(0.3, 3)) instead of uniformly."""

    def __post_init__(self) -> None:
        ok = math.isfinite(self.low) and math.isfinite(self.high) and 0 < self.low <= self.high
        _check(ok, "low/high", f"a scale range needs 0 < low <= high, got ({self.low!r}, {self.high!r})")

    @property
    def is_identity(self) -> bool:
        return self.low == 1.0 and self.high == 1.0

    def draw(self, rng: np.random.Generator, size: int | None = None) -> np.ndarray | float:
        """Factors drawn from this range. Always draws (one uniform per factor, exactly 1 for the identity),
        so what is drawn after it does not depend on whether this range is the identity."""
        if self.log:
            return np.exp(rng.uniform(math.log(self.low), math.log(self.high), size))
        return rng.uniform(self.low, self.high, size)


IDENTITY = ScaleRange()


@dataclass(frozen=True)
class CameraReality:
    """How every camera of the cell differs from its nominal pinhole (each camera draws its own errors)."""

    # -- fixed (cell_seed) ---------------------------------------------------------------------
    focal_error: float = 0.0
    """Largest relative error of fx and fy, each drawn in ``[-a, a]`` [-] (0.005 = 0.5 %)."""
    principal_error: float = 0.0
    """Largest error of cx and cy, each drawn in ``[-a, a]`` [px]."""
    k1: float = 0.0
    """Largest |k1| of the true lens (OpenCV radial distortion), drawn in ``[-a, a]`` [-]."""
    k2: float = 0.0
    """Largest |k2| of the true lens, drawn in ``[-a, a]`` [-]."""
    p: float = 0.0
    """Largest |p1|, |p2| of the true lens (tangential distortion), each drawn in ``[-a, a]`` [-]."""
    mount_translation: float = 0.0
    """Mounting error of the camera: length of its position error [m] (an arm camera's relative to the
    gripper it is fixed to)."""
    mount_rotation: float = 0.0
    """Mounting error of the camera: angle of its orientation error [deg]."""
    # -- per frame (session seed) --------------------------------------------------------------
    noise_sigma: float = 0.0
    """Standard deviation of Gaussian pixel noise [DN] (8-bit digital numbers)."""
    gain: ScaleRange = IDENTITY
    """Exposure/gain change: each frame's brightness multiplied by a factor drawn per frame [-]."""
    exposure: float = 0.0
    """Exposure time [s]: a moving camera smears the image along its motion (motion blur of
    ``exposure x`` the image speed of a point at :attr:`blur_depth`)."""
    blur_depth: float = 0.4
    """Depth at which the motion blur's length is computed [m] (the workspace seen from the cameras)."""
    defocus_sigma: float = 0.0
    """Standard deviation of a Gaussian defocus blur [px]."""
    occluder_probability: float = 0.0
    """Probability that a frame carries occluders (shadows, a cable, a hand) [-]."""
    occluder_count: int = 3
    """Most occluders in a frame that has them (1..count, uniformly) [-]."""
    occluder_size: tuple[float, float] = (20.0, 80.0)
    """Range of an occluder's size (rectangle side or ellipse diameter) [px]."""
    dropped_frame_probability: float = 0.0
    """Probability that a capture delivers no frame (``capture`` returns None) [-]."""

    def __post_init__(self) -> None:
        _non_negative(self, "focal_error", "principal_error", "k1", "k2", "p", "mount_translation")
        _non_negative(self, "mount_rotation", "noise_sigma", "exposure", "blur_depth", "defocus_sigma")
        _probability(self, "occluder_probability", "dropped_frame_probability")
        _check(self.focal_error < 0.5, "focal_error", f"must be < 0.5, got {self.focal_error!r}")
        _check(self.blur_depth > 0, "blur_depth", f"must be > 0, got {self.blur_depth!r}")
        _check(
            1 <= self.occluder_count <= MAX_OCCLUDERS,
            "occluder_count",
            f"must be in 1..{MAX_OCCLUDERS}, got {self.occluder_count!r}",
        )
        low, high = self.occluder_size
        _check(0 < low <= high, "occluder_size", f"needs 0 < low <= high [px], got {self.occluder_size!r}")


@dataclass(frozen=True)
class ForceTorqueReality:
    """How the wrist F/T sensor differs from the ideal load measurement."""

    force_noise: float = 0.0
    """Standard deviation of the force noise of one reading, per axis [N]."""
    torque_noise: float = 0.0
    """Standard deviation of the torque noise of one reading, per axis [N·m]."""
    force_bias: float = 0.0
    """Length of the force offset present at reset (removed by a tare) [N]."""
    torque_bias: float = 0.0
    """Length of the torque offset present at reset (removed by a tare) [N·m]."""
    force_drift: float = 0.0
    """Rate of the slow zero drift of the force, in a random direction drawn per trial [N/min]: it
    accumulates after a tare."""
    torque_drift: float = 0.0
    """Rate of the slow zero drift of the torque [N·m/min]."""
    rate_hz: float = 0.0
    """Rate at which the load is sampled [Hz]; a reading holds the latest sample. 0: continuous."""
    delay: float = 0.0
    """Age of the sample a reading returns [s] (needs ``rate_hz`` > 0)."""
    force_resolution: float = 0.0
    """Quantisation step of a force reading [N]. 0: none."""
    torque_resolution: float = 0.0
    """Quantisation step of a torque reading [N·m]. 0: none."""
    force_range: tuple[float, float, float] | None = None
    """Saturation of the sensor's raw force, ``(|Fx|, |Fy|, |Fz|)`` [N]; None: never saturates."""
    torque_range: float | None = None
    """Saturation of the sensor's raw torque, per axis [N·m]; None: never saturates."""

    def __post_init__(self) -> None:
        _non_negative(self, "force_noise", "torque_noise", "force_bias", "torque_bias", "force_drift")
        _non_negative(self, "torque_drift", "rate_hz", "delay", "force_resolution", "torque_resolution")
        _check(self.delay == 0 or self.rate_hz > 0, "delay", "a delayed sensor needs a sampling rate_hz > 0")
        _check(self.delay <= MAX_FT_DELAY, "delay", f"must be <= {MAX_FT_DELAY} s, got {self.delay!r}")
        if self.force_range is not None:
            _check(
                len(self.force_range) == 3 and all(v > 0 for v in self.force_range),
                "force_range",
                f"needs three positive limits (|Fx|, |Fy|, |Fz|) [N], got {self.force_range!r}",
            )
        if self.torque_range is not None:
            _check(self.torque_range > 0, "torque_range", f"must be > 0 [N·m], got {self.torque_range!r}")


@dataclass(frozen=True)
class ArmReality:
    """How the arm differs from its nominal kinematics and an instantaneous servo interface."""

    encoder_noise: float = 0.0
    """Standard deviation of the joint position readings' noise [rad] (one draw per reading time)."""
    command_latency: float = 0.0
    """Delay before a joint command reaches the servos [s]."""
    stall_rate: float = 0.0
    """Rate of command stalls (the controller stops taking commands for :attr:`stall_duration`) [1/s]."""
    stall_duration: float = 0.0
    """Length of a command stall [s]: a command sent during one is held until it ends, then the held commands
    take effect in order, one per controller cycle (:data:`~twin.servos.CONTROLLER_CYCLE`)."""
    tcp_bias: float = 0.0
    """Length of the offset of the true TCP (the physical gripper) from the one the arm's kinematics
    report, fixed in the flange frame [m] (fixed per cell)."""

    def __post_init__(self) -> None:
        _non_negative(self, "encoder_noise", "command_latency", "stall_rate", "stall_duration", "tcp_bias")


@dataclass(frozen=True)
class PhysicsReality:
    """How the box and the grasp differ from the nominal model (drawn per trial, but for the ``kind_*`` factors:
    per cell)."""

    friction_scale: ScaleRange = IDENTITY
    """Multiplier of the handle/pad contact friction μ, drawn per component [-]."""
    pad_friction: float | None = None
    """Sliding friction μ of the handle/pad contact before :attr:`friction_scale` [-]; None: the
    model's (1.0, chosen to hold the handles, DESIGN.md)."""
    grip_force_scale: float = 1.0
    """Gripper force relative to the model's full-force grip, taken as the datasheet's 30 N [-]. Applied
    as the handle/pad friction it leaves (the holding capacity 2 mu N scales with it), the fingers closing
    as the nominal servo closes them."""
    joint_damping_scale: ScaleRange = IDENTITY
    """Multiplier of each component joint's viscous damping [-]."""
    joint_friction_scale: ScaleRange = IDENTITY
    """Multiplier of each component joint's dry friction (frictionloss) [-]."""
    mass_scale: ScaleRange = IDENTITY
    """Multiplier of each component's mass and inertia [-]."""
    latch_compliance_scale: ScaleRange = IDENTITY
    """Multiplier of each latch constraint's time constant (``solref[0]``): > 1 is a softer latch with play [-]."""
    kind_joint_damping_scale: ScaleRange = IDENTITY
    """Multiplier of the joint damping of every component of a kind, one factor per kind (door, slide, wheel:
    ``models.kinds.KIND_NAMES``) drawn once per cell from ``cell_seed``: how the box's hardware differs from its
    CAD-nominal model systematically, trial after trial. It multiplies :attr:`joint_damping_scale` [-]."""
    kind_joint_friction_scale: ScaleRange = IDENTITY
    """As :attr:`kind_joint_damping_scale`, for the joint dry friction (frictionloss); multiplies
    :attr:`joint_friction_scale` [-]."""
    kind_latch_compliance_scale: ScaleRange = IDENTITY
    """As :attr:`kind_joint_damping_scale`, for the latch time constant (``solref[0]``); multiplies
    :attr:`latch_compliance_scale` [-]."""
    jam_probability: float = 0.0
    """Probability that a free component jams on a try: held where it stands until the gripper has let
    go of its handle for :attr:`jam_release_after` [-]."""
    jam_release_after: float = 0.5
    """Time without gripper contact on a jammed component's handle that ends the try and frees it [s]."""

    def __post_init__(self) -> None:
        _probability(self, "jam_probability")
        _non_negative(self, "jam_release_after")
        _check(
            self.pad_friction is None or (math.isfinite(self.pad_friction) and self.pad_friction > 0),
            "pad_friction",
            f"must be > 0 or null, got {self.pad_friction!r}",
        )
        _check(
            math.isfinite(self.grip_force_scale) and self.grip_force_scale > 0,
            "grip_force_scale",
            f"must be > 0, got {self.grip_force_scale!r}",
        )


MAX_CELL_SEED = 2**32 - 1
"""Largest ``cell_seed`` (a seed of numpy's generators, as every seed of the project)."""


@dataclass(frozen=True)
class RealityProfile:
    """Every way the simulated cell differs from the nominal model (see the module docstring)."""

    name: str = "custom"
    """What the profile is called (for the record)."""
    cell_seed: int = 0
    """Seed of the cell's fixed imperfections (camera errors, TCP bias): one cell, calibrated once."""
    camera: CameraReality = field(default_factory=CameraReality)
    force_torque: ForceTorqueReality = field(default_factory=ForceTorqueReality)
    arm: ArmReality = field(default_factory=ArmReality)
    physics: PhysicsReality = field(default_factory=PhysicsReality)
    placement: PlacementRange | None = None
    """Where the box is placed, drawn per trial among reachable poses; None: the spec's own pose."""

    def __post_init__(self) -> None:
        seed = self.cell_seed
        ok = isinstance(seed, int | np.integer) and not isinstance(seed, bool) and 0 <= seed <= MAX_CELL_SEED
        _check(ok, "cell_seed", f"must be an integer in [0, {MAX_CELL_SEED}], got {seed!r}")

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready dict; :meth:`from_dict` (and :func:`load_profile`, from a file) reads it back to an
        equal profile."""
        return _to_plain(self)

    @classmethod
    def from_dict(cls, data: Any) -> RealityProfile:
        return _from_plain(cls, data, "profile")


def _to_plain(value: Any) -> Any:
    if dataclasses.is_dataclass(value):
        return {f.name: _to_plain(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, tuple):
        return [_to_plain(v) for v in value]
    return value


def _from_plain(cls: type, data: Any, path: str) -> Any:
    known = [f.name for f in dataclasses.fields(cls)]
    if not isinstance(data, dict):
        raise ProfileError(f"{path}: expected an object with keys {known}, got {type(data).__name__}")
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ProfileError(f"{path}: unknown key(s) {unknown}; known keys: {known}")
    hints = typing.get_type_hints(cls)
    values = {name: _convert(hints[name], data[name], f"{path}.{name}") for name in known if name in data}
    try:
        return cls(**values)
    except ProfileError as err:
        raise ProfileError(f"{path}.{err}") from None
    except (TypeError, ValueError) as err:  # e.g. PlacementRange's own checks
        raise ProfileError(f"{path}: {err}") from None


def _convert(hint: Any, value: Any, path: str) -> Any:
    origin = typing.get_origin(hint)
    if origin in (typing.Union, types.UnionType):
        options = [a for a in typing.get_args(hint) if a is not type(None)]
        if value is None:
            if len(options) < len(typing.get_args(hint)):
                return None
            raise ProfileError(f"{path}: may not be null")
        return _convert(options[0], value, path)
    if isinstance(hint, type) and dataclasses.is_dataclass(hint):  # (a hint is a class, never an instance)
        return _from_plain(hint, value, path)
    if origin is tuple:
        args = typing.get_args(hint)
        if not isinstance(value, list | tuple) or len(value) != len(args):
            raise ProfileError(f"{path}: expected a list of {len(args)} numbers, got {value!r}")
        return tuple(_convert(a, v, f"{path}[{i}]") for i, (a, v) in enumerate(zip(args, value, strict=True)))
    if hint is bool:
        if not isinstance(value, bool):
            raise ProfileError(f"{path}: expected true or false, got {value!r}")
        return value
    if hint is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ProfileError(f"{path}: expected an integer, got {value!r}")
        return value
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ProfileError(f"{path}: expected a number, got {value!r}")
        return float(value)
    if hint is str:
        if not isinstance(value, str):
            raise ProfileError(f"{path}: expected a string, got {value!r}")
        return value
    raise ProfileError(f"{path}: cannot read a value of type {hint!r}")  # a field type this reader lacks


IDEAL = RealityProfile(name="ideal")
"""No imperfection at all: the nominal world (zero sensor noise, exact cameras and kinematics)."""

REALISTIC = RealityProfile(
    name="realistic",
    camera=CameraReality(
        focal_error=0.005,  # Presets "intrinsics" ±0.5 % (§3 calibration error, C3/C4)
        principal_error=3.0,  # Presets "intrinsics" ±3 px (§3, C3/C4)
        k1=0.01,  # Presets "distortion (unmodelled)" k1 ±0.01 (§3 k1..p2, C2: ≈1 px at the corners)
        mount_translation=0.003,  # Presets "extrinsic" 3 mm (§3 hand-eye, C7-C9)
        mount_rotation=0.3,  # Presets "extrinsic" 0.3° (§3, C7-C9)
        noise_sigma=2.0,  # Presets "noise, gain" 2 DN (§3 noise σ, E)
        gain=ScaleRange(0.95, 1.05),  # Presets "noise, gain" ×(0.95-1.05) (§3 brightness ±5 %, C6)
        exposure=0.010,  # Presets "exposure" 10 ms (§3 blur: 2 px at 0.1 m/s, 0.3 m, C5)
        dropped_frame_probability=0.01,  # Presets "ArUco corner σ, dropout" 1 % (§4 dropout <1 %, E)
    ),
    force_torque=ForceTorqueReality(
        force_noise=0.1,  # Presets "F/T noise σ" 0.1 N (§1 noise σ UF, E from U1 resolution)
        torque_noise=0.003,  # Presets "F/T noise σ" 3 mN·m (§1, U1)
        force_bias=0.5,  # Presets "F/T bias, drift" 0.5 N (§1 bias after tare, E/F4)
        torque_bias=0.01,  # E: the force bias at ~2 cm lever (no published torque bias)
        force_drift=0.02,  # Presets "F/T bias, drift" 0.02 N/min (§1 zero drift 0.17 N per 10 min, F1)
        torque_drift=0.0012,  # §1 zero drift 12 mN·m per 10 min (F1)
        rate_hz=100.0,  # Presets "F/T rate, delay" 100 Hz (§1 rate, report_type='real', U3)
        delay=0.010,  # Presets "F/T rate, delay" 10 ms (§1)
        force_range=(150.0, 150.0, 200.0),  # §1 UF F/T range ±150 N Fx,Fy; 200 N Fz (U1, U2)
        torque_range=4.0,  # §1 UF F/T range 4 N·m (U1, U2)
    ),
    arm=ArmReality(
        encoder_noise=1e-4,  # E: 0.05 mm at 0.5 m, within §2 repeatability ±0.1 mm (U9)
        command_latency=0.005,  # Presets "command latency" 5 ms (§2 set_servo_angle_j latency 1-3 ms, U11)
        tcp_bias=0.001,  # Presets "TCP bias" 1 mm (§2 absolute TCP error 1-2 mm, U10)
    ),
    physics=PhysicsReality(
        friction_scale=ScaleRange(0.8, 1.2),  # Presets "μ" ×(0.8-1.2) (§5, D1/D2)
        pad_friction=0.4,  # Presets "grip force, pad μ" 0.4 (§5 grasp hold, P1)
        grip_force_scale=0.5,  # Presets "grip force, pad μ" 15 N of the gripper's 30 N max (§5, U14)
        joint_damping_scale=ScaleRange(0.95, 1.05),  # E: trial-to-trial variation of one box (temperature, wear)
        joint_friction_scale=ScaleRange(0.95, 1.05),  # E: trial-to-trial variation of one box (temperature, wear)
        mass_scale=ScaleRange(0.95, 1.05),  # Presets "mass" ×(0.95-1.05) (§5 mass ±5 %, E)
        latch_compliance_scale=ScaleRange(1.0, 1.1),  # E: trial-to-trial variation of one box (temperature, wear)
        # one box's hardware, per kind and per cell: its hinges, slides and bearings differ from the CAD model
        kind_joint_damping_scale=ScaleRange(0.7, 1.5),  # Presets "joint damping" ×(0.7-1.5) (§5, D2)
        kind_joint_friction_scale=ScaleRange(0.7, 1.5),  # E: as the damping (§5 sim joint friction ×0.3-3, P3)
        kind_latch_compliance_scale=ScaleRange(1.0, 2.0),  # E: a plastic latch with some play
        jam_probability=0.02,  # E: an occasional sticky part
    ),
    placement=PlacementRange(),  # issue "reality gap": the box anywhere in the reachable workspace
)
"""The "realistic" column of REALITY_NOTES.md's Presets table, box placed anywhere reachable."""

HARSH = RealityProfile(
    name="harsh",
    camera=CameraReality(
        focal_error=0.03,  # Presets "intrinsics" ±3 % (§3 pessimistic fx −7.5 %, C4)
        principal_error=15.0,  # Presets "intrinsics" ±15 px (§3 pessimistic cx −18 px, C4)
        k1=0.05,  # Presets "distortion (unmodelled)" k1 ±0.05 (§3, C2)
        p=0.003,  # Presets "distortion (unmodelled)" p ±0.003 (§3 |p|≈0.003, C2)
        mount_translation=0.015,  # Presets "extrinsic" 15 mm (§3 pessimistic 10-20 mm, C8/C9)
        mount_rotation=1.5,  # Presets "extrinsic" 1.5° (§3 pessimistic 1-2°, C8/C9)
        noise_sigma=7.0,  # Presets "noise, gain" 7 DN (§3 dim, high gain, E)
        gain=ScaleRange(0.7, 1.3),  # Presets "noise, gain" ×(0.7-1.3) (§3 brightness ±30 %, C6)
        exposure=0.033,  # Presets "exposure" 33 ms (§3 blur 7 px at 33 ms, C5)
        defocus_sigma=0.7,  # E: a slightly soft focus
        occluder_probability=0.2,  # Presets "dropout" 20 % (§4 ~50 % under moving shadows, C12)
        dropped_frame_probability=0.05,  # E: a USB camera that sometimes times out
    ),
    force_torque=ForceTorqueReality(
        force_noise=0.3,  # Presets "F/T noise σ" 0.3 N (§1, U1)
        torque_noise=0.010,  # Presets "F/T noise σ" 10 mN·m (§1, U1)
        force_bias=2.0,  # Presets "F/T bias, drift" 2 N (§1 bias 4 N UR spec, F4)
        torque_bias=0.04,  # E: the force bias at ~2 cm lever
        force_drift=0.1,  # Presets "F/T bias, drift" 0.1 N/min (§1 zero drift pessimistic, F1/F5)
        torque_drift=0.006,  # E: 5x the typical torque drift, as for the force
        rate_hz=100.0,  # Presets "F/T rate, delay" 100 Hz (§1, U3)
        delay=0.030,  # Presets "F/T rate, delay" 30 ms (§1)
        force_resolution=0.15,  # Presets "F/T rate, delay" 0.15 N quantisation (§1 UF resolution Fz, U1)
        torque_resolution=0.005,  # §1 UF resolution 5 mN·m (U1)
        force_range=(150.0, 150.0, 200.0),  # §1 UF F/T range (U1, U2)
        torque_range=4.0,  # §1 UF F/T range (U1, U2)
    ),
    arm=ArmReality(
        encoder_noise=3e-4,  # E: three times the realistic value
        command_latency=0.010,  # Presets "command latency" 10 ms (§2, U11)
        stall_rate=0.1,  # Presets "command latency" stalls 0.1/s (§2 190 ms stall per ~10 s, U11)
        stall_duration=0.190,  # Presets "command latency" 190 ms stalls (§2, U11)
        tcp_bias=0.008,  # Presets "TCP bias" 8 mm (§2 ~10 mm at 90° reorientation, U10)
    ),
    physics=PhysicsReality(
        friction_scale=ScaleRange(0.5, 1.5),  # Presets "μ" ×(0.5-1.5) (§5, D2)
        pad_friction=0.25,  # Presets "grip force, pad μ" 0.25 (§5 grasp hold pessimistic, P1)
        grip_force_scale=1 / 3,  # Presets "grip force, pad μ" 10 N of 30 N (§5, U14)
        joint_damping_scale=ScaleRange(0.3, 3.0, log=True),  # Presets "joint damping" ×logU(0.3,3) (D2)
        joint_friction_scale=ScaleRange(0.3, 3.0, log=True),  # §5 sim joint friction ×0.3-3 (P3, D2)
        mass_scale=ScaleRange(0.5, 1.5),  # Presets "mass" ×(0.5-1.5) (D2)
        latch_compliance_scale=ScaleRange(1.0, 4.0),  # E: a worn latch with play
        jam_probability=0.1,  # E: sticky parts
    ),
    placement=PlacementRange(),
)
"""The "harsh" column of REALITY_NOTES.md's Presets table, box placed anywhere reachable."""

PRESETS: dict[str, RealityProfile] = {"ideal": IDEAL, "realistic": REALISTIC, "harsh": HARSH}
"""The named profiles :func:`load_profile` knows."""


def load_profile(name_or_path: str | Path | RealityProfile | None) -> RealityProfile:
    """A preset by name (:data:`PRESETS`), a profile JSON file (:meth:`RealityProfile.to_dict`'s format),
    a profile itself, or None (``ideal``).

    Raises:
        ProfileError: an unknown preset or missing file, a file that is not JSON, an unknown key at any
            level (the message names it and the known keys), or a value out of range.
    """
    if name_or_path is None:
        return IDEAL
    if isinstance(name_or_path, RealityProfile):
        return name_or_path
    text = str(name_or_path)
    if text in PRESETS:
        return PRESETS[text]
    path = Path(text)
    if not path.is_file():
        raise ProfileError(f"no reality profile {text!r}: not a preset ({sorted(PRESETS)}) nor a JSON file")
    try:
        data = read_json(path)
    except JsonInputError as err:
        raise ProfileError(f"cannot read reality profile {path}: {err}") from None
    if isinstance(data, dict) and "name" not in data:
        data = {**data, "name": path.stem}
    return RealityProfile.from_dict(data)
