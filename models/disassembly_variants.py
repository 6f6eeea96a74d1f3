"""Variants of a measured computer for the disassembly experiment (issue 14): RAM sticks and GPU power cables
added or removed, every pose jittered — the differences the paper's two lab computers show between each other.

A variant is drawn from one seed (:func:`disassembly_variant`): the number of RAM sticks and of GPU cables,
each within its :class:`VariantConfig` range, then Gaussian noise on every position and orientation. A stick
added beside the last one copies that stick's pose one slot further (``ram_pitch`` along the slot row) and its
locks (the panel holds it; it holds the motherboard); a cable added is placed ``cable_offset`` from the GPU in
the GPU's frame (where ``lab-computer-a`` has its cable) and gets that computer's locks (the panel holds it; it
holds the GPU). Removing one drops it and its locks. The variant is validated like any spec (goal reachable).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from puzzlebox.models.spec import PuzzleSpec
from puzzlebox.models.spec_loading import spec_from_dict


@dataclass(frozen=True)
class VariantConfig:
    """What varies between variants; lengths [m], angles [rad]."""

    ram_sticks: tuple[int, int] = (1, 3)
    """Inclusive range of the number of RAM sticks: one more than the lab computers' 1 and 2 (and never none)."""
    gpu_cables: tuple[int, int] = (0, 2)
    """Inclusive range of the number of GPU power cables: one more than the lab computers' 0 and 1."""
    ram_pitch: float = 0.01
    """Distance between neighbouring RAM slots, along the row (lab-computer-b: 1 cm)."""
    cable_offset: tuple[float, float, float] = (0.0, 0.12, 0.0)
    """A first cable's position in the GPU's frame (lab-computer-a's: 12 cm along the card's y, which is -x in
    the scene); each further cable one ``ram_pitch`` beside the previous one."""
    position_sigma: float = 0.005
    """Standard deviation of the jitter of every position, per axis."""
    angle_sigma: float = 0.05
    """Standard deviation of the jitter of every orientation, per axis of a small rotation (about 3 deg)."""

    def __post_init__(self) -> None:
        for name in ("ram_sticks", "gpu_cables"):
            low, high = getattr(self, name)
            if not 0 <= low <= high:
                raise ValueError(f"{name} must be an inclusive range 0 <= low <= high, got {(low, high)}")
        if self.ram_sticks[0] < 1:
            raise ValueError("a variant keeps at least one RAM stick (ram_sticks low >= 1)")
        if self.position_sigma < 0 or self.angle_sigma < 0:
            raise ValueError("position_sigma and angle_sigma must be >= 0")


def disassembly_variant(base: PuzzleSpec, seed: int, config: VariantConfig | None = None) -> PuzzleSpec:
    """A variant of the disassembly scene ``base`` drawn from ``seed`` (named ``<base>-v<seed>``)."""
    config = config or VariantConfig()
    if base.box is not None:
        raise ValueError(f"{base.name} is a puzzle box; variants are of disassembly scenes (no box)")
    rng = np.random.default_rng(seed)
    data = base.to_dict()
    data["name"] = f"{base.name}-v{seed}"
    _set_count(data, "ram", int(rng.integers(config.ram_sticks[0], config.ram_sticks[1] + 1)), config)
    _set_count(data, "gpu_cable", int(rng.integers(config.gpu_cables[0], config.gpu_cables[1] + 1)), config)
    for component in data["components"]:
        x, y, z, roll, pitch, yaw = component["pose"]
        turn = rng.normal(0.0, config.angle_sigma, 3)
        position = np.array([x, y, z]) + rng.normal(0.0, config.position_sigma, 3)
        orientation = [roll, pitch, yaw]
        if np.any(turn):  # composed in the scene frame (a turn of the part about its own centre)
            orientation = (Rotation.from_rotvec(turn) * Rotation.from_euler("xyz", orientation)).as_euler("xyz")
        component["pose"] = [float(v) for v in (*position, *orientation)]
    return spec_from_dict(data, source=data["name"])


def _of_kind(data: dict[str, Any], kind: str) -> list[dict[str, Any]]:
    return [c for c in data["components"] if c["kind"] == kind]


def _set_count(data: dict[str, Any], kind: str, count: int, config: VariantConfig) -> None:
    """Add or remove components of ``kind`` (the last ones first) until there are ``count``."""
    while len(_of_kind(data, kind)) > count:
        gone = _of_kind(data, kind)[-1]["name"]
        data["components"] = [c for c in data["components"] if c["name"] != gone]
        data["locks"] = [lock for lock in data["locks"] if gone not in (lock["locker"], lock["locked"])]
    while len(_of_kind(data, kind)) < count:
        _add(data, kind, config)


def _add(data: dict[str, Any], kind: str, config: VariantConfig) -> None:
    names = {c["name"] for c in data["components"]}
    stem = kind.replace("_", "-")
    number = len(_of_kind(data, kind)) + 1
    while f"{stem}-{number}" in names:
        number += 1
    name = f"{stem}-{number}"
    existing = _of_kind(data, kind)
    if existing:  # one slot further along the row (x in the scene: lab-computer-b's ram-1 -0.17, ram-2 -0.18)
        last = existing[-1]
        pose = list(last["pose"])
        pose[0] -= config.ram_pitch
        locks = [_renamed(lock, last["name"], name) for lock in data["locks"] if last["name"] in _ends(lock)]
    elif kind == "gpu_cable":  # as lab-computer-a's: plugged into the card, behind the panel
        gpu = _of_kind(data, "gpu")
        if not gpu:
            raise ValueError(f"{data['name']}: a GPU cable needs a GPU to plug into")
        pose = _offset(gpu[0]["pose"], config.cable_offset)
        locks = [_held(name, gpu[0]["name"])] + [_held(panel["name"], name) for panel in _of_kind(data, "panel")]
    else:
        raise ValueError(f"{data['name']} has no {kind} to copy")
    data["components"].append({"name": name, "kind": kind, "pose": [float(v) for v in pose]})
    data["locks"].extend(locks)


def _ends(lock: dict[str, Any]) -> tuple[str, str]:
    return lock["locker"], lock["locked"]


def _renamed(lock: dict[str, Any], old: str, new: str) -> dict[str, Any]:
    return {**lock, **{end: new for end in ("locker", "locked") if lock[end] == old}}


def _held(locker: str, locked: str) -> dict[str, Any]:
    """While ``locker`` is in place, ``locked`` cannot be removed."""
    return {"locker": locker, "locker_state": 0, "locked": locked, "locked_state": 0}


def _offset(pose: list[float], offset: tuple[float, float, float]) -> list[float]:
    """``pose`` moved by ``offset`` expressed in its own frame."""
    rotation = Rotation.from_euler("xyz", pose[3:6])
    return [*(np.asarray(pose[:3]) + rotation.apply(offset)), *pose[3:6]]
