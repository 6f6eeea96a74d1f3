"""Latches: lock rules acting on the box's joints by rule, where no mechanism enforces them.

With contact locks (the default, :data:`models.scene.SceneConfig.locks`) the box's mechanisms enforce the rules
they realize by contact (:mod:`models.lock_mechanisms`); the latches hold only the rules no mechanism realizes
(:func:`latched_rules`, each named in one warning) and jammed parts (:mod:`twin.jams`: a fault, not a rule). With
``locks="latch"`` (the ablation) they hold every rule, as before mechanisms existed.

Each component has one joint equality constraint (built inactive, see ``models.puzzle_box``). While a
rule "``locker`` in ``locker_state`` keeps ``locked`` in ``locked_state``" is active — the locker is
in that state and the locked component is in its ``locked_state`` — the locked joint's equality is
engaged at the joint's current position (``eq_data[e, 0] = q``, ``eq_active[e] = 1``), so a robot
pulling on it feels a hard stop through the wrist F/T sensor; it is released as soon as no rule holds
the component any more. DESIGN.md measured this holds a door, slide and wheel to < 0.05 deg, 0.4 mm
and 0.04 deg under a 50 N push, and that narrowing joint ranges instead is 30-60x softer.
"""

from __future__ import annotations

import dataclasses
import warnings

import mujoco
import numpy as np

from puzzlebox.models import LockTable, PuzzleSpec
from puzzlebox.models.mechanism_mjcf import LockMode, mechanism_layout


class UnrealizedLockWarning(UserWarning):
    """A spec's lock rule that no mechanism realizes is enforced by a rule-driven latch."""


def latched_rules(spec: PuzzleSpec, locks: LockMode) -> PuzzleSpec:
    """``spec`` with only the lock rules the latches must enforce: all of them with ``locks="latch"``; with
    ``"contact"``, those no mechanism realizes, named in one :class:`UnrealizedLockWarning`."""
    if locks == "latch" or not spec.locks:
        return spec
    unrealized = mechanism_layout(spec).unrealized
    if unrealized:
        named = "; ".join(
            f"{u.rule.locker} in {u.rule.locker_state} keeps {u.rule.locked} in {u.rule.locked_state} ({u.reason})"
            for u in unrealized
        )
        warnings.warn(
            f"spec {spec.name!r}: {len(unrealized)} lock rule(s) enforced by latches, not mechanisms: {named}",
            UnrealizedLockWarning,
            stacklevel=3,
        )
    return dataclasses.replace(spec, locks=tuple(u.rule for u in unrealized))


class Latches:
    """Engages and releases the box's latch constraints from component states."""

    def __init__(self, model: mujoco.MjModel, spec: PuzzleSpec, latch_names: list[str], joint_qpos: np.ndarray):
        self.model = model
        self.eq_ids = np.array([model.equality(name).id for name in latch_names], dtype=np.int64)
        self.joint_qpos = joint_qpos
        self.table = LockTable.from_spec(spec)  # the symbolic semantics itself: physics and symbols cannot drift
        self.engaged = np.zeros(len(latch_names), dtype=bool)

    def held(self, states: np.ndarray) -> np.ndarray:
        """Which components an active rule holds, for component states ``states`` (0/1 each)."""
        return self.table.held(states)

    def apply(self, data: mujoco.MjData, states: np.ndarray, jammed: np.ndarray | None = None) -> None:
        """Engage newly held components where they stand and release the ones no rule holds (nor a
        jam, :mod:`twin.jams`: a jammed component is held by its latch like a locked one)."""
        held = self.held(states)
        if jammed is not None:
            held |= jammed
        for c in np.flatnonzero(held & ~self.engaged):
            e = self.eq_ids[c]
            self.model.eq_data[e, 0] = data.qpos[self.joint_qpos[c]]
            data.eq_active[e] = 1
        for c in np.flatnonzero(~held & self.engaged):
            data.eq_active[self.eq_ids[c]] = 0
        self.engaged = held

    def targets(self) -> np.ndarray:
        """Latch targets [rad or m] (``eq_data[:, 0]``), for saving a session's state."""
        return self.model.eq_data[self.eq_ids, 0].copy()

    def restore(self, data: mujoco.MjData, targets: np.ndarray) -> None:
        self.model.eq_data[self.eq_ids, 0] = targets
        self.engaged = data.eq_active[self.eq_ids].astype(bool)
