"""Parts that meet each other: a generated box whose moving parts strike one another breaks its spec by geometry.

The layout keeps footprints apart on the lid (:mod:`models.generator.layout`), but a door swings up out of its
footprint and its handle with it: an open door's handle may stand in a neighbouring door's sweep, and then the
neighbour stops part way (``random-n8-s49`` of ``generate.py random --components 8 --kinds all``: door-7 stops
at 63 % of its travel when door-0 is open, a transition the spec allows). :func:`meeting_parts` finds such pairs
on the compiled box: each part swept through its travel with each other part at each end of its own, every
other part closed, MuJoCo's contacts between the two parts' own geoms read at every pose. A lock mechanism is
not a part's own geometry here (it is built with ``locks="latch"``: what it blocks, it blocks on purpose).
"""

from __future__ import annotations

import itertools

import mujoco
import numpy as np

from puzzlebox.models.puzzle_box import build_puzzle_box, component_prefixes
from puzzlebox.models.spec import PuzzleSpec

__all__ = ["SWEEP_SAMPLES", "TOUCH_DEPTH", "meeting_parts"]

SWEEP_SAMPLES = 21
"""Poses along a part's travel at which it is checked against another part."""
TOUCH_DEPTH = 0.0002
"""Penetration beyond which two parts meet [m] (MuJoCo's contacts within its margins are not a meeting)."""
NEAR = 0.25
"""Parts whose joint anchors are farther apart than this [m] are not checked (no part reaches that far)."""


def meeting_parts(spec: PuzzleSpec) -> list[tuple[str, str]]:
    """Pairs of components (spec names, in spec order) whose own geometry meets as one moves with the other at
    either end of its travel, every other part closed (module docstring); empty for a box whose parts clear."""
    root = build_puzzle_box(spec, with_markers=False, locks="latch")
    root.compiler.angle = "radian"
    model = mujoco.MjModel.from_xml_string(root.to_xml_string(), assets=root.get_assets())
    data = mujoco.MjData(model)
    prefixes = component_prefixes(spec)
    joints = [model.joint(f"{prefixes[c.name]}:joint") for c in spec.components]
    qadr = [int(j.qposadr[0]) for j in joints]
    travel = [float(model.jnt_range[j.id][1]) for j in joints]
    owner = np.full(model.nbody, -1)  # the component whose joint moves each body
    for k, j in enumerate(joints):
        owner[int(model.jnt_bodyid[j.id])] = k
    for b in range(1, model.nbody):  # children follow their parent (bodies are in tree order)
        if owner[b] < 0:
            owner[b] = owner[model.body_parentid[b]]
    mujoco.mj_forward(model, data)
    anchors = np.array([data.xanchor[j.id] for j in joints])
    meeting: list[tuple[str, str]] = []
    for i, k in itertools.combinations(range(len(joints)), 2):
        if np.linalg.norm(anchors[i] - anchors[k]) > NEAR:
            continue
        if _meet(model, data, owner, qadr, travel, i, k) or _meet(model, data, owner, qadr, travel, k, i):
            meeting.append((spec.components[i].name, spec.components[k].name))
    return meeting


def _meet(model, data, owner, qadr, travel, moving: int, other: int) -> bool:
    """Whether ``moving``, swept through its travel with ``other`` at either end, meets ``other``."""
    for end in (0.0, 1.0):
        for fraction in np.linspace(0.0, 1.0, SWEEP_SAMPLES):
            data.qpos[:] = 0.0
            data.qpos[qadr[other]] = end * travel[other]
            data.qpos[qadr[moving]] = fraction * travel[moving]
            mujoco.mj_kinematics(model, data)
            mujoco.mj_collision(model, data)
            n = data.ncon
            if n == 0:
                continue
            # the contacts as arrays: a Python object per contact cost 90 % of the sweep (0.55 s -> 0.06 s a box)
            owners = owner[model.geom_bodyid[data.contact.geom[:n]]]
            between = ((owners[:, 0] == moving) & (owners[:, 1] == other)) | (
                (owners[:, 0] == other) & (owners[:, 1] == moving)
            )
            if np.any(between & (data.contact.dist[:n] < -TOUCH_DEPTH)):
                return True
    return False
