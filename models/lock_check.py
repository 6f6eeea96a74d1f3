"""The mechanism check: does a compiled model alone behave as its spec says?

From every state reachable from all-zero (the spec's semantics, :class:`~models.lock_table.LockTable`), each part
is pushed toward its other state with a bounded generalized force — :data:`SLIDE_FORCE` along a prismatic joint,
:data:`HINGE_TORQUE` about a hinge, what the robot's pinch gives below its force limit — for
:data:`PUSH_TIME`, every other joint held where it stands (its position reset after every step: a held part
cannot be pushed out of the way). A free part must reach :data:`FREE_FRACTION` of its travel toward the other
state (the twin's state threshold); a held part must move less than :data:`HELD_FRACTION`. Only ``mujoco`` runs:
the model is stepped as it is, no latch engaged, no project code in the loop, so what holds a part is its
geometry. The push is a robot's, not a bare force's: at most the effort, and the part never faster than
:data:`SLIDE_SPEED` or :data:`HINGE_SPEED` (the hand's speed): each step, what the part's motion says it was
pushing against plus what brings it to that speed, so a stalled push builds up to the whole effort in ~10 ms.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from puzzlebox.models.lock_mechanisms import paired_rules
from puzzlebox.models.lock_table import LockTable
from puzzlebox.models.spec import PuzzleSpec

__all__ = [
    "FREE_FRACTION",
    "HELD_FRACTION",
    "HINGE_TORQUE",
    "HINGE_SPEED",
    "PUSH_TIME",
    "SLIDE_SPEED",
    "SLIDE_FORCE",
    "LockCheck",
    "Transition",
    "check_locks",
    "reachable_states",
]

SLIDE_FORCE = 25.0
"""Push along a prismatic joint [N]."""
HINGE_TORQUE = 1.5
"""Push about a hinge [N·m]."""
SLIDE_SPEED = 0.2
"""Fastest a push drives a prismatic joint [m/s]: a robot's pinch moves a part at hand speed, not as a bare force
would fling a 30 g plate (at 25 N, 2 m/s within 5 cm, 4 mm a step: a part would pass through a 2.5 mm bolt)."""
HINGE_SPEED = 3.0
"""Fastest a push turns a hinge [rad/s] (0.2 m/s at a door's handle, 7 cm from its hinge)."""
PUSH_TIME = 1.0
"""How long each push lasts [s]."""
FREE_FRACTION = 0.75
"""A free part reaches at least this fraction of its travel toward its other state."""
HELD_FRACTION = 0.5
"""A held part moves less than this fraction of its travel."""
MAX_STATES = 4096
"""Most reachable states checked (all of them up to 12 parts)."""


BAND_OFFSETS = (0.0, 0.1, 0.2)
"""Where the band check rests every part it does not push, as a fraction of its travel from the end stop of its
state (0: at the stop; 0.2: a part counted closed at 20 % of its travel, one counted open at 80 %): inside the twin's
bands (closed below 25 %, open above 75 %), where a mechanism must already behave as the state says."""


@dataclass(frozen=True)
class Transition:
    """One push: ``component`` from ``state`` (bitmask over spec order) toward its other state, every other part
    resting ``offset`` of its travel away from the end stop of its state."""

    state: int
    component: str
    expected_free: bool
    moved: float
    """Largest fraction of the travel the part reached toward its other state."""
    offset: float = 0.0
    """How far from their end stops the other parts rested [fraction of their travel] (:data:`BAND_OFFSETS`)."""

    @property
    def agrees(self) -> bool:
        """Whether the part did what the spec says: reached :data:`FREE_FRACTION` if free, stayed below
        :data:`HELD_FRACTION` if held."""
        return self.moved >= FREE_FRACTION if self.expected_free else self.moved < HELD_FRACTION


@dataclass(frozen=True)
class LockCheck:
    """Every transition of one model, and how many agree with the spec."""

    spec_name: str
    transitions: tuple[Transition, ...]

    @property
    def agreeing(self) -> int:
        return sum(t.agrees for t in self.transitions)

    @property
    def fraction(self) -> float:
        return self.agreeing / len(self.transitions) if self.transitions else 1.0

    def held_moves(self) -> list[float]:
        """How far each held part moved [fraction of its travel]."""
        return [t.moved for t in self.transitions if not t.expected_free]

    def disagreements(self) -> list[Transition]:
        return [t for t in self.transitions if not t.agrees]


def reachable_states(spec: PuzzleSpec, limit: int = MAX_STATES) -> list[int]:
    """States (bitmasks over spec order) reachable from all-zero by allowed toggles, breadth first."""
    table = LockTable.from_spec(spec)
    seen = {0}
    order = [0]
    k = 0
    while k < len(order) and len(order) < limit:
        state = order[k]
        k += 1
        for c in range(len(spec.components)):
            if table.can_move(state, c):
                nxt = state ^ (1 << c)
                if nxt not in seen:
                    seen.add(nxt)
                    order.append(nxt)
    return order[:limit]


def check_locks(
    spec: PuzzleSpec,
    model: mujoco.MjModel,
    joint_names: dict[str, str],
    limit: int = MAX_STATES,
    offsets: tuple[float, ...] = (0.0,),
    batched: bool = True,
) -> LockCheck:
    """Push every part from every reachable state (module docstring) in ``model``, whose joint of each
    component is ``joint_names[component name]``, once per offset in ``offsets``: every other part rests that
    fraction of its travel away from the end stop of its state, toward its other state (0: at its stop; the band
    check, :data:`BAND_OFFSETS`, rests them inside the twin's bands, where a locker counts as in its state without
    standing at its stop); the pushed part starts at its stop. Other joints of the model (a robot's) are held where
    they stand at reset, but for joints that belong to no component and carry a spring (a mechanism's own sprung
    pawls), which move freely. ``batched``: every push at once, as simulations of one ``mujoco.batch.Batch``
    (bit-identical to one ``MjData`` stepped push after push, ``batched=False``)."""
    if not offsets or any(not 0.0 <= p < 1.0 - FREE_FRACTION for p in offsets):
        raise ValueError(f"offsets must lie in [0, {1.0 - FREE_FRACTION:g}) (inside a state's band), got {offsets}")
    table = LockTable.from_spec(spec)
    index = {c.name: k for k, c in enumerate(spec.components)}
    # (A, a, B, b) of every unpaired rule: a one-way latch, whose tooth lets B rest nowhere but at its stop while A
    # is at a and B at b (an interlock's held part may rest anywhere short of where its rod meets the wall)
    one_way = [(index[r.locker], r.locker_state, index[r.locked], r.locked_state) for r in paired_rules(spec)[1]]
    joints = [model.joint(joint_names[c.name]) for c in spec.components]
    qadr = np.array([int(j.qposadr[0]) for j in joints])
    dadr = np.array([int(j.dofadr[0]) for j in joints])
    travel = np.array([float(model.jnt_range[j.id][1]) for j in joints])
    hinge = np.array([model.jnt_type[j.id] == mujoco.mjtJoint.mjJNT_HINGE for j in joints])
    own = {j.id for j in joints}
    held_other = [
        j for j in range(model.njnt) if j not in own and not model.jnt_stiffness[j] > 0
    ]  # robot joints and anything rigid
    other_q = [int(model.jnt_qposadr[j]) for j in held_other]
    other_d = [int(model.jnt_dofadr[j]) for j in held_other]
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)
    inertias = full[dadr, dadr]  # about a fixed axis: the same in every state
    pushes: list[Push] = []
    for state in reachable_states(spec, limit):
        bits = np.array([(state >> k) & 1 for k in range(len(joints))])
        latched = [b for a, sa, b, sb in one_way if bits[a] == sa and bits[b] == sb]
        for offset, c in ((p, c) for p in offsets for c in range(len(joints))):
            rest = np.where(bits == 1, (1.0 - offset) * travel, offset * travel)
            rest[latched] = travel[latched] * bits[latched]
            rest[c] = travel[c] * bits[c]  # the pushed part from its stop
            pushes.append(Push(state, offset, c, rest, int(bits[c])))
    geometry = _Joints(qadr, dadr, travel, hinge, inertias, np.array(other_q, dtype=int), np.array(other_d, dtype=int))
    run = _pushed_batched if batched else _pushed_one_by_one
    bests = run(model, pushes, geometry)
    transitions = [
        Transition(p.state, spec.components[p.part].name, bool(table.can_move(p.state, p.part)), best, p.offset)
        for p, best in zip(pushes, bests, strict=True)
    ]
    return LockCheck(spec.name, tuple(transitions))


@dataclass(frozen=True)
class Push:
    """One push of the check: from ``state`` (bitmask), every part resting at ``rest`` (its joint position [m or
    rad], ``offset`` into its band), part ``part`` pushed toward the other state from ``bit``."""

    state: int
    offset: float
    part: int
    rest: np.ndarray
    bit: int


@dataclass(frozen=True)
class _Joints:
    """The components' joints (addresses, travel [m or rad], hinge or not, inertia about the axis) and the other
    held joints' addresses."""

    qadr: np.ndarray
    dadr: np.ndarray
    travel: np.ndarray
    hinge: np.ndarray
    inertias: np.ndarray
    other_q: np.ndarray
    other_d: np.ndarray


def _pushed_one_by_one(model: mujoco.MjModel, pushes: list[Push], j: _Joints) -> list[float]:
    """How far each push got toward the other state [fraction of the travel], one ``MjData`` stepped at a time."""
    data = mujoco.MjData(model)
    dt = model.opt.timestep
    steps = int(round(PUSH_TIME / model.opt.timestep))
    bests = []
    for p in pushes:
        c = p.part
        mujoco.mj_resetData(model, data)
        data.qpos[j.qadr] = p.rest
        mujoco.mj_forward(model, data)
        hold_q = data.qpos.copy()
        sign = 1.0 if p.bit == 0 else -1.0
        effort = HINGE_TORQUE if j.hinge[c] else SLIDE_FORCE
        speed = HINGE_SPEED if j.hinge[c] else SLIDE_SPEED
        others = np.array([k for k in range(len(j.qadr)) if k != c], dtype=int)
        best = 0.0
        push = v_before = 0.0
        for _ in range(steps):
            data.qfrc_applied[:] = 0.0
            # a hand that pushes with at most ``effort`` and moves no faster than ``speed``: what the part's motion
            # last step says it pushed against, plus what brings it to that speed in this step
            v = sign * data.qvel[j.dadr[c]]
            load = push - j.inertias[c] * (v - v_before) / dt
            push = float(np.clip(load + j.inertias[c] * (speed - v) / dt, 0.0, effort))
            v_before = v
            data.qfrc_applied[j.dadr[c]] = sign * push
            mujoco.mj_step(model, data)
            if len(others):
                data.qpos[j.qadr[others]] = hold_q[j.qadr[others]]
                data.qvel[j.dadr[others]] = 0.0
            if len(j.other_q):
                data.qpos[j.other_q] = hold_q[j.other_q]
                data.qvel[j.other_d] = 0.0
            # how far toward the other state, from where a state's part would stand at its end stop
            moved = sign * (data.qpos[j.qadr[c]] - (j.travel[c] if p.bit else 0.0)) / j.travel[c]
            best = max(best, float(moved))
            if best >= 0.98:
                break
        bests.append(best)
    return bests


def _pushed_batched(model: mujoco.MjModel, pushes: list[Push], j: _Joints) -> list[float]:
    """:func:`_pushed_one_by_one`'s figures, bit for bit, with every push a simulation of one batch: the hand's push
    computed for all at once, the batch stepped on a thread per core; a push that reached 98 % stops there."""
    from mujoco.batch import Batch  # pyright: ignore[reportMissingImports]  (no stub of it in typings/)

    n = len(pushes)
    if n == 0:
        return []
    batch = Batch(model, nsim=n, nthread=0)
    batch.reset(stage=mujoco.mjtStage.mjSTAGE_NONE)
    qpos, qvel, qfrc = batch.bind("qpos"), batch.bind("qvel"), batch.bind("qfrc_applied")
    rows = np.arange(n)
    part = np.array([p.part for p in pushes])
    qpos[:, j.qadr] = np.stack([p.rest for p in pushes])
    batch.forward()
    hold_q = qpos.copy()
    sign = np.array([1.0 if p.bit == 0 else -1.0 for p in pushes])
    effort = np.where(j.hinge[part], HINGE_TORQUE, SLIDE_FORCE)
    speed = np.where(j.hinge[part], HINGE_SPEED, SLIDE_SPEED)
    inertia, dof, q_part = j.inertias[part], j.dadr[part], j.qadr[part]
    stop = np.where(np.array([p.bit for p in pushes]) == 1, j.travel[part], 0.0)
    # every other component joint of each push, held: (n, parts - 1) addresses
    held = np.array([[k for k in range(len(j.qadr)) if k != c] for c in part], dtype=int).reshape(n, -1)
    held_q, held_d = j.qadr[held], j.dadr[held]
    best = np.zeros(n)
    push = np.zeros(n)
    v_before = np.zeros(n)
    running = np.ones(n, dtype=bool)
    dt = model.opt.timestep
    for _ in range(int(round(PUSH_TIME / model.opt.timestep))):
        ids = rows[running]
        qfrc[ids] = 0.0
        v = sign[ids] * qvel[ids, dof[ids]]
        load = push[ids] - inertia[ids] * (v - v_before[ids]) / dt
        push[ids] = np.clip(load + inertia[ids] * (speed[ids] - v) / dt, 0.0, effort[ids])
        v_before[ids] = v
        qfrc[ids, dof[ids]] = sign[ids] * push[ids]
        batch.step(ids)
        if held.shape[1]:
            qpos[ids[:, None], held_q[ids]] = hold_q[ids[:, None], held_q[ids]]
            qvel[ids[:, None], held_d[ids]] = 0.0
        if len(j.other_q):
            qpos[np.ix_(ids, j.other_q)] = hold_q[np.ix_(ids, j.other_q)]
            qvel[np.ix_(ids, j.other_d)] = 0.0
        moved = sign[ids] * (qpos[ids, q_part[ids]] - stop[ids]) / j.travel[part[ids]]
        best[ids] = np.maximum(best[ids], moved)
        running[ids[best[ids] >= 0.98]] = False
        if not running.any():
            break
    return [float(b) for b in best]
