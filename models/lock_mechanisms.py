"""Locks made of matter: the lock rules of a puzzle-box spec as mechanisms that block by contact.

SPEC.md: while ``locker`` (A) is in ``locker_state`` a, ``locked`` (B) cannot *leave* ``locked_state`` b.
Two rules "A in a keeps B in b" and "B in 1-b keeps A in 1-a" form a **pair**: together they forbid the one
configuration (A at a, B at 1-b) and both ways into it. A pair becomes a rigid **interlock** of two tubes under
the lid that cross at a point X (lid frame):

- on A, a *wall*: the path X takes through A's moving part while A goes from a to a fraction ``theta`` of its
  travel toward 1-a, so that X lies inside the wall exactly while A is within that fraction of a;
- on B, a *rod*: the path of X through B while B is between a fraction ``delta`` of its travel and 1-b, so
  that X lies inside the rod exactly while B has left b by more than ``delta``.

Both contain X only in the forbidden corner: with A at a, B's rod meets A's wall after B moved ``delta``; with B
at 1-b, A's wall meets B's rod after A moved ``1 - theta``; with A at 1-a or B at b they pass each other with a
clearance. At X the wall runs along A's motion and the rod along B's, so a contact's normal there (across the
tube it touches) does no work on the part it does not block: the locker is not pushed open by a blocked try.
X is searched for (:func:`design_mechanisms`): where the two motions cross at a good angle, the blocking
fractions are small, the tubes stay inside the box and, as far as they can, under the lid.

An **unpaired** rule (random and multi-locker boxes) forbids leaving b but not entering it: a **one-way latch**,
as on a door: on A a sprung pawl whose tooth, while A is at a, stands in the path of a lug on B. In the frame
``(e1, e2, e3)`` at X — e1 along B's motion from b toward 1-b, e2 across it toward A's motion, e3 = e1 x e2 — the
lug (at b) lies just behind X along e1 and the tooth just ahead; the tooth's face toward the lug is flat (B leaving
b meets it square: blocked) and its other face is bevelled (B coming back to b presses it down along -e3, against
its spring, and passes). A leaving a carries the tooth away across B's path (e2). X is chosen where A's motion is
across B's (so B's blocked push does no work on A) and where neither part's lug or tooth meets the other's on any
free move. Rules that no mechanism serves are named as unrealized; the twin enforces them with rule-driven latches
(:mod:`twin.latches`).

Collisions: every mechanism geom has its own contact bit (``contype = conaffinity = 2**k``, ``k`` in 1..31), so
a wall touches only the rod of its own interlock, never the robot, the table or another interlock; the tubes
are capsules (the contact MuJoCo and every engine that reads MJCF handle best). Frames: lid frame (origin at
the lid centre on its top face, x along the length, z up) [m].
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from puzzlebox.models.errors import UnknownKindError
from puzzlebox.models.joint_motion import JointMotion
from puzzlebox.models.kinds.registry import get_kind
from puzzlebox.models.spec import LockRule, PuzzleSpec

__all__ = [
    "GAP",
    "TUBE_RADIUS",
    "Interlock",
    "OneWayLatch",
    "MechanismLayout",
    "UnrealizedRule",
    "design_mechanisms",
    "paired_rules",
]

TUBE_RADIUS = 0.001
"""Radius of a wall's and a rod's capsules [m]."""
GAP = 0.0005
"""Clearance between a wall and a rod wherever they must pass each other [m]."""
MIN_CROSSING_SINE = 0.5
"""Smallest sine of the angle between the two motions at X (30 deg): below it a blocked push would need twice its
own force at the contact, and the tubes would have to be long to clear each other."""
FREE_FROM = 0.75
"""A part counts as having left a state once it moved this fraction of its travel (the twin's open threshold,
``twin.HysteresisConfig``): a locker that far toward 1-a, wherever it rests past that (a door opened by a pinch may
stop short of its end stop), must have freed the part it held."""
IN_STATE = 0.25
"""A part counts as still in a state while within this fraction of its travel from the state's end stop (the twin's
close threshold): a locked part resting anywhere in that band must not be met by its locker, and a locker anywhere
in it must hold its partner. So a held part's rod first meets the wall past this fraction (held part-way)."""
HOLD_MARGIN = 0.08
"""How far past :data:`IN_STATE` a wall still covers X [fraction of the travel]: a locker at the edge of its band
meets the rod with this much of the wall beyond X, not with the wall's end cap."""
MAX_BLOCKING = 0.45
"""Largest fraction of its travel a held part may move before its tube meets the other's (the lock check's held
part moves less than half its travel)."""
SAMPLES = 121
"""Points along each motion's path over [-1.2, 1.2] of its travel (every 2 % of the travel)."""
STEP = 0.02
"""Resolution of the search for ``delta`` and ``1 - theta`` [fraction of the travel]."""
GRID_STEP = 0.008
"""Spacing of the candidate crossing points in plan [m]."""
DEPTHS = (-0.006, -0.012, -0.02, -0.03, -0.045, -0.06)
"""Candidate heights of the crossing point below the lid's top face [m]."""
BOX_MARGIN = 0.004
"""How far inside the box's side walls and above its floor every tube stays [m]."""
BACKING_STEP = 0.0015
"""Spacing of a tube's backing chains [m] (less than a pin's diameter: the slab has no gap)."""
BACKING_CHAINS = 2
"""Backing chains behind each tube's axis: with the pins' 1 mm radius, a slab 5 mm thick (with one, 3.5 mm, a door
flung by a bare 20 N push passed through; each chain's capsules are geoms collided every step)."""
MAX_TRIED = 60
"""Candidate crossing points whose blocking fractions are computed, best first guesses first."""
CHORD_SAGITTA = 0.0002
"""Largest gap between a hinge tube's capsule chain and the arc it follows [m] (the chords lie inside the arc):
added to the clearance the free moves are checked with."""
"""Largest turn of a hinge's tube per capsule [rad] (chord error < 0.25 % of its radius)."""


@dataclass(frozen=True)
class UnrealizedRule:
    """A lock rule no mechanism realizes, and why; the twin enforces it with a latch."""

    rule: LockRule
    reason: str


@dataclass(frozen=True)
class Interlock:
    """A rigid two-way interlock realizing a pair of rules (module docstring).

    Attributes:
        name: ``"<A>-interlocks-<B>"`` (spec names).
        locker: A, the part whose state a holds B (the first rule's locker).
        locked: B.
        locker_state: a.
        locked_state: b.
        rules: the two rules, ``(A in a keeps B in b, B in 1-b keeps A in 1-a)``.
        crossing: X, lid frame [m].
        theta: A's wall covers X while A is within this fraction of its travel from a.
        delta: B's rod covers X once B has left b by this fraction of its travel.
        wall: ``(k, n, 3)`` polylines of the wall's chains in the lid frame with every part in state 0 [m]: its axis
            through X first, then its backing chains.
        rod: ``(k, m, 3)`` polylines of the rod's chains, likewise [m].
        crossing_sine: sine of the angle between the two motions at X.
        exposed: how far the tubes rise above the lid's top face in any of the four corner states [m] (<= 0: the
            mechanism is hidden under the lid).
    """

    name: str
    locker: str
    locked: str
    locker_state: int
    locked_state: int
    rules: tuple[LockRule, LockRule]
    crossing: np.ndarray = field(repr=False, compare=False)
    theta: float
    delta: float
    wall: np.ndarray = field(repr=False, compare=False)
    rod: np.ndarray = field(repr=False, compare=False)
    crossing_sine: float
    exposed: float
    radius: float = TUBE_RADIUS


TOOTH_UNDERCUT = 0.27
"""Slope of the tooth's face [run over rise]: it leans over the lug by 15 degrees, top first, as a ratchet pawl's
face is undercut, so that a lug pressing it draws the pawl onto its stop rather than down its slide (a square face
met by a lug turned a few degrees with its part, or by a tooth's edge, was pressed down: wheel > drawer latches
let the drawer through with the wheel 20 % inside its band)."""
TOOTH_LENGTH = 0.004
"""Length of a one-way latch's tooth along B's motion (e1) [m]."""
TOOTH_HALF_WIDTH = 0.002
"""Half the width of the tooth across B's motion (e2) [m]."""
TOOTH_DEPTH = 0.002
"""How far the tooth reaches below the lug's underside (-e3) [m] (its body, on the pawl's guide)."""
TOOTH_RISE = 0.003
"""How far the tooth stands into the lug's path (+e3) [m]: the pawl retracts this much (plus play) to let it by."""
LUG_LENGTH = 0.004
"""Length of the lug along B's motion (e1) [m]."""
LUG_HALF_WIDTH = 0.0025
"""Half the width of the lug across B's motion (e2) [m]."""
LUG_HEIGHT = 0.004
"""Height of the lug above its underside (e3) [m]."""
LATCH_GAP = 0.001
"""Gap between the lug and the tooth's flat face with A at a and B at b [m]."""
LUG_DIP = 0.0003
"""Lowest a lug may stand below its underside's place at b (along -e3) anywhere in B's band [m]: a locker coming back
over it presses the pawl down by the tooth's rise plus the pawl's 0.5 mm of play at the most."""
LATCH_GAPS = (LATCH_GAP, 2 * LATCH_GAP, 3 * LATCH_GAP)
"""The lug's distances from the tooth's face a latch's design tries, in order [m]: a row of teeth along an arc that
bends toward the lug (a door's, under its hinge line) passes it closer than a straight row, and a lug a little
further off lets it pass; the locked part then moves up to that far before the tooth holds it."""
TOOTH_SPACING = 0.003
"""Largest distance between neighbouring teeth of a latch's row along A's path [m] (a tooth is 4 mm wide)."""
LATCH_CLEARANCE = 0.0007
"""Smallest gap between tooth and lug on every free move [m]."""
MAX_WORK_COSINE = 0.15
"""Largest cosine of A's motion with B's at X for a one-way latch: a blocked push of B (along e1) does work on A
in proportion, and A, resting at a by its friction alone, must not be pushed off."""


@dataclass(frozen=True)
class OneWayLatch:
    """A one-way latch realizing an unpaired rule "A in a keeps B in b" (module docstring).

    Attributes:
        name: ``"<A>-latches-<B>"``.
        locker, locked, locker_state, locked_state: A, B, a, b.
        rule: the rule.
        crossing: X, lid frame [m], with A at a and B at b.
        frame: ``(3, 3)`` columns e1, e2, e3 in the lid frame, with A at a and B at b.
        crossing_cosine: cosine of the angle between A's and B's motions at X.
        tooth_shifts: the tooth is a row of teeth along A's path, one where X's material point of A stands after
            each of these displacements back toward a [fraction of A's travel] (0: the tooth at X): a locker
            anywhere in its state's band (up to :data:`IN_STATE` plus :data:`HOLD_MARGIN` of its travel from a)
            still stands a tooth in the lug's path.
        gap: the lug's distance from the tooth's face with A at a and B at b [m]: :data:`LATCH_GAP`, or a multiple
            of it where A's path bends toward the lug along the row (:data:`LATCH_GAPS`).
    """

    name: str
    locker: str
    locked: str
    locker_state: int
    locked_state: int
    rule: LockRule
    crossing: np.ndarray = field(repr=False, compare=False)
    frame: np.ndarray = field(repr=False, compare=False)
    crossing_cosine: float
    tooth_shifts: tuple[float, ...] = (0.0,)
    gap: float = LATCH_GAP

    def tooth_vertices(self, a: JointMotion) -> list[np.ndarray]:
        """Each tooth of the row as ``(k, 3)`` vertices in the (e1, e2, e3) frame at X with A at a [m], given A's
        motion ``a``: the profile extruded ±:data:`TOOTH_HALF_WIDTH` along e2 and carried back along A's path; each
        ends, toward a, in a ramp at 45 degrees down to its underside, so that A coming back to a over a lug left
        inside its band presses the pawl down and passes, as the lug coming back does over the bevel."""
        direction = 1.0 if self.locker_state == 0 else -1.0
        w = TOOTH_HALF_WIDTH
        # the side of the tooth that meets a lug as A comes back to a: -e2, or +e2 in a mirrored frame (e2 and e3
        # turned over, for a lug whose arc would otherwise dip under the teeth: see _design_latch)
        back = -1.0 if float(direction * a.velocity(self.crossing) @ self.frame[:, 1]) > 0 else 1.0
        profile = self.tooth_profile()
        teeth = []
        for shift in self.tooth_shifts:
            # each tooth ends toward a in the ramp, from the top down to the tooth's underside (the row bends with A's
            # arc, so a lug in its band may meet any tooth's end); every vertex a corner of the hull: the profile's
            # underside at -w would lie on the hull's edges, which a convex hull's triangulation turns into slivers
            local = [(u, -back * w, v) for u, v in profile]
            local += [(u, back * w, v) for u, v in profile if v > -TOOTH_DEPTH]
            local += [(u, back * (w + TOOTH_RISE + TOOTH_DEPTH), -TOOTH_DEPTH) for u in (profile[0, 0], TOOTH_LENGTH)]
            world = self.crossing + np.asarray(local) @ self.frame.T
            carried = a.move(world, -direction * a.travel * shift)
            teeth.append((carried - self.crossing) @ self.frame)
        return teeth

    def tooth_profile(self) -> np.ndarray:
        """``(5, 2)`` the tooth's outline in the (e1, e3) plane [m], counter-clockwise: the face toward the lug, its
        top at e1 = 0 and undercut (:data:`TOOTH_UNDERCUT`) below, bevel at 45 degrees down to the far end, extruded
        ±:data:`TOOTH_HALF_WIDTH` along e2."""
        lt, rise, depth = TOOTH_LENGTH, TOOTH_RISE, TOOTH_DEPTH
        foot = TOOTH_UNDERCUT * (rise + depth)
        return np.array([(foot, -depth), (lt, -depth), (lt, 0.0), (lt - rise, rise), (0.0, rise)])

    def lug_vertices(self) -> np.ndarray:
        """``(8, 3)`` the lug's corners with B at b in the (e1, e2, e3) frame at X [m]: a block :data:`LUG_LENGTH`
        long, ±:data:`LUG_HALF_WIDTH` wide, :data:`LUG_HEIGHT` high from its underside at e3 = 0, its face toward the
        tooth parallel to the tooth's undercut face and ``gap`` from it (faces meet flat, and the lug's push draws
        the pawl onto its stop)."""
        corners = []
        for e3 in (0.0, LUG_HEIGHT):
            front = -self.gap + TOOTH_UNDERCUT * (TOOTH_RISE - e3)
            corners += [(e1, e2, e3) for e1 in (front, front - LUG_LENGTH) for e2 in (-LUG_HALF_WIDTH, LUG_HALF_WIDTH)]
        return np.array(corners)


@dataclass(frozen=True)
class MechanismLayout:
    """A spec's mechanisms: every rule is in exactly one interlock or latch, or in ``unrealized``."""

    interlocks: tuple[Interlock, ...]
    unrealized: tuple[UnrealizedRule, ...]
    latches: tuple[OneWayLatch, ...] = ()

    @property
    def complete(self) -> bool:
        """Whether every rule is realized by a mechanism (the model alone behaves as the spec says)."""
        return not self.unrealized


def paired_rules(spec: PuzzleSpec) -> tuple[list[tuple[LockRule, LockRule]], list[LockRule]]:
    """The spec's rules as pairs ``(A in a keeps B in b, B in 1-b keeps A in 1-a)``, in order of the first rule
    of each pair, and the rules left unpaired, in spec order."""
    remaining = list(spec.locks)
    pairs: list[tuple[LockRule, LockRule]] = []
    unpaired: list[LockRule] = []
    while remaining:
        rule = remaining.pop(0)
        partner = LockRule(rule.locked, 1 - rule.locked_state, rule.locker, 1 - rule.locker_state)
        if partner in remaining:
            remaining.remove(partner)
            pairs.append((rule, partner))
        else:
            unpaired.append(rule)
    return pairs, unpaired


def design_mechanisms(spec: PuzzleSpec) -> MechanismLayout:
    """The mechanisms of a puzzle-box spec (module docstring): an interlock per pair of rules that a crossing
    point serves; every other rule unrealized, with its reason. Deterministic: a pure function of the spec."""
    if spec.box is None:
        raise ValueError(f"spec {spec.name!r} has no box: not a puzzle box")
    by_name = {c.name: c for c in spec.components}
    pairs, unpaired = paired_rules(spec)
    interlocks: list[Interlock] = []
    unrealized: list[UnrealizedRule] = []
    for first, second in pairs:
        try:
            a, b = (_motion(by_name[first.locker]), _motion(by_name[first.locked]))
        except UnknownKindError as error:
            unrealized += [UnrealizedRule(r, f"unknown kind: {error}") for r in (first, second)]
            continue
        designed = _design_interlock(spec, first, second, a, b, by_name)
        if isinstance(designed, str):
            unrealized += [UnrealizedRule(r, designed) for r in (first, second)]
        else:
            interlocks.append(designed)
    latches: list[OneWayLatch] = []
    for rule in unpaired:
        try:
            a, b = (_motion(by_name[rule.locker]), _motion(by_name[rule.locked]))
        except UnknownKindError as error:
            unrealized.append(UnrealizedRule(rule, f"unknown kind: {error}"))
            continue
        latch = _design_latch(spec, rule, a, b, by_name)
        if isinstance(latch, str):
            unrealized.append(UnrealizedRule(rule, latch))
        else:
            latches.append(latch)
    order = {rule: k for k, rule in enumerate(spec.locks)}
    unrealized.sort(key=lambda u: order[u.rule])
    return MechanismLayout(tuple(interlocks), tuple(unrealized), tuple(latches))


def _design_latch(spec, rule: LockRule, a: JointMotion, b: JointMotion, by_name) -> OneWayLatch | str:
    """The best one-way latch for an unpaired rule, or why there is none."""
    dir_a = 1.0 if rule.locker_state == 0 else -1.0
    dir_b = 1.0 if rule.locked_state == 0 else -1.0
    lo, hi, grid = _candidate_grid(spec)
    # the parts at a and b: X in the lid frame with every part closed is where the design state puts it
    va = _velocities(a, grid) * (dir_a * a.travel)
    vb = _velocities(b, grid) * (dir_b * b.travel)
    na, nb = np.linalg.norm(va, axis=1), np.linalg.norm(vb, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        cosine = np.einsum("ij,ij->i", va, vb) / (na * nb)
    keep = (na > 1e-6) & (nb > 1e-6) & (np.abs(cosine) <= MAX_WORK_COSINE)
    if not np.any(keep):
        return "no point under the lid where the locker's motion is across the locked part's"
    margin = LUG_HEIGHT + LUG_LENGTH  # the tooth and the lug lie within this of X
    keep &= grid[:, 2] < -margin  # where they meet, under the lid; a door's tooth may rise through a slot as it opens
    top = np.full(len(grid), -np.inf)
    for t in np.linspace(0.0, 1.0, 11):
        for motion, direction in ((a, dir_a), (b, dir_b)):
            moved = motion.move(grid, direction * motion.travel * t)
            keep &= np.all((moved >= lo + margin) & (moved <= hi - margin), axis=1)
            top = np.maximum(top, moved[:, 2] + margin)
    if not np.any(keep):
        return "no point where the locker's motion is across the locked part's keeps a latch inside the box"
    # prefer long paths (a small blocking fraction for B, a tooth that leaves fast), then nearness, then hidden
    score = LATCH_GAP / nb + 0.01 / na + _distance_cost(grid, by_name, rule) + np.where(top > 0, 0.5 + 200 * top, 0)
    order = np.argsort(np.where(keep, score, np.inf))[: int(keep.sum())]
    # then the most nearly square crossings: a row of teeth passes within LATCH_GAP of the lug only where A's path
    # runs across B's (a cosine of 0.15 carries a tooth 0.7 mm toward the lug over the lug's width)
    squarest = np.argsort(np.where(keep, np.abs(cosine) + 1e-3 * score, np.inf), kind="stable")[: int(keep.sum())]
    tried = order[: MAX_TRIED * 5]
    again = squarest[~np.isin(squarest, tried)][: MAX_TRIED * 5]
    reasons: dict[str, int] = {}
    for gap, k in itertools.product(LATCH_GAPS, np.concatenate([tried, again])):
        x0 = grid[k]  # with every part closed; move it to the design state (A at a, B at b): X is fixed in space,
        # and the grid is a grid of space points, so X = x0 whatever the parts' states
        e1 = vb[k] / nb[k]
        e2 = va[k] - (va[k] @ e1) * e1
        e2 /= np.linalg.norm(e2)
        frame = np.column_stack([e1, e2, np.cross(e1, e2)])
        shifts = _tooth_shifts(a, x0)
        why = _latch_clear(x0, frame, a, b, dir_a, dir_b, lo, hi, shifts, gap)
        if why == LUG_DIPS:  # B's arc carries the lug down the pawl's way: the pawl turned over retracts upward
            mirrored = frame * np.array([1.0, -1.0, -1.0])  # (e1, -e2, -e3): right-handed still
            why = _latch_clear(x0, mirrored, a, b, dir_a, dir_b, lo, hi, shifts, gap)
            frame = mirrored if why is None else frame
        if why is not None:
            reasons[why] = reasons.get(why, 0) + 1
            continue
        return OneWayLatch(
            name=f"{rule.locker}-latches-{rule.locked}",
            locker=rule.locker,
            locked=rule.locked,
            locker_state=rule.locker_state,
            locked_state=rule.locked_state,
            rule=rule,
            crossing=x0,
            frame=frame,
            crossing_cosine=float(cosine[k]),
            tooth_shifts=tuple(shifts),
            gap=gap,
        )
    common = max(reasons, key=reasons.__getitem__) if reasons else "no candidate"
    return f"no point serves a one-way latch (mostly: {common})"


def _tooth_shifts(a: JointMotion, x: np.ndarray) -> np.ndarray:
    """Displacements [fraction of A's travel] of the row of teeth (:attr:`OneWayLatch.tooth_shifts`): from 0 to
    :data:`IN_STATE` plus :data:`HOLD_MARGIN`, neighbours at most :data:`TOOTH_SPACING` apart along A's path."""
    reach = IN_STATE + HOLD_MARGIN
    length = float(np.linalg.norm(_velocities(a, np.asarray(x)[None])[0])) * a.travel * reach
    return np.linspace(0.0, reach, max(1, int(np.ceil(length / TOOTH_SPACING))) + 1)


LUG_DIPS = "the lug dips under the teeth inside its band"
"""Why a latch's frame is refused when B's arc carries the lug down under the teeth (:func:`_latch_clear`)."""


def _latch_clear(x, frame, a, b, dir_a, dir_b, lo, hi, shifts=(0.0,), gap=LATCH_GAP) -> str | None:
    """Why a one-way latch at ``x`` with ``frame``, its row of teeth at ``shifts`` (:func:`_tooth_shifts`) and its lug
    ``gap`` from the tooth's face would meet itself on a free move or leave the box, or None.

    The lug and each tooth are boxes in the (e1, e2, e3) frame, each carried rigidly by its part's motion; a
    rotation of a part is allowed for by widening its box by the turn times its largest half size. The tooth's face
    and the lug's are undercut alike (:data:`TOOTH_UNDERCUT`): sheared along e1 by the same amount at each height,
    they stand as far apart along e1, layer by layer, as the two boxes do."""
    tooth_centre = np.array([TOOTH_LENGTH / 2, 0.0, (TOOTH_RISE - TOOTH_DEPTH) / 2])
    tooth_half = np.array([TOOTH_LENGTH / 2, TOOTH_HALF_WIDTH, (TOOTH_RISE + TOOTH_DEPTH) / 2])
    lug_centre = np.array([-gap - LUG_LENGTH / 2, 0.0, LUG_HEIGHT / 2])
    lug_half = np.array([LUG_LENGTH / 2, LUG_HALF_WIDTH, LUG_HEIGHT / 2])
    ts = np.linspace(0.0, 1.0, 51)
    n = len(ts)
    # B anywhere in its band: its lug, met by a locker coming back to a, presses the pawl down on a tooth's ramp
    # only if it stands no lower than the pawl can retract past the tooth's rise (a lug carried down by B's arc
    # stops the locker instead); first, as it needs B's motion alone
    in_band = ts[ts <= IN_STATE]
    corners = x + (lug_centre + lug_half * np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T) @ frame.T
    lowest = float(((b.move(corners[:, None], dir_b * b.travel * in_band) - x) @ frame[:, 2]).min())
    if lowest < -LUG_DIP:
        return LUG_DIPS
    shifts = np.asarray(shifts, dtype=float)
    # each tooth as A goes from a to 1-a, carried back by its shift first: (teeth, n, 3)
    starts = a.move(x + frame @ tooth_centre, -dir_a * a.travel * shifts)
    tooth_paths = a.move(starts[:, None], dir_a * a.travel * ts)
    lug_path = b.move(x + frame @ lug_centre, dir_b * b.travel * ts)  # B from b to 1-b
    hinge_a = 1.0 if a.joint == "hinge" else 0.0
    # each tooth's turn away from the design frame: it was carried back by its shift, so it stands as designed at X
    turns_a = hinge_a * np.abs(ts[None] - shifts[:, None]) * a.travel
    turn_b = ts * b.travel if b.joint == "hinge" else 0 * ts
    reach_sum = tooth_half + lug_half + LATCH_CLEARANCE
    reach = max(np.linalg.norm(tooth_half), np.linalg.norm(lug_half))
    if (
        np.any(tooth_paths < lo + reach) or np.any(tooth_paths > hi - reach)
        or np.any(lug_path < lo + reach) or np.any(lug_path > hi - reach)
    ):  # fmt: skip
        return "it leaves the box"

    def overlap(tooth_i: np.ndarray, lug_i: np.ndarray) -> bool:  # whether any pair (tooth_i[k], lug_i[k]) overlaps
        d = (lug_path[lug_i][None] - tooth_paths[:, tooth_i]) @ frame  # every tooth, each carried rigidly
        grow = turns_a[:, tooth_i] * tooth_half.max() + (turn_b[lug_i] * lug_half.max())[None]  # its turn widens it
        return bool(np.any(np.all(np.abs(d) < reach_sum + grow[..., None], axis=-1)))

    leaving = np.arange(1, n)
    if overlap(leaving, np.zeros_like(leaving)):
        return "the tooth meets the lug as the locker leaves"
    away = np.flatnonzero(ts >= FREE_FROM)
    if overlap(np.repeat(away, n), np.tile(np.arange(n), len(away))):
        return "the lug meets the tooth with the locker away"
    if overlap(np.arange(n), np.full(n, n - 1)):
        return "the tooth meets the lug with the locked part away"
    return None


def _near(grid: np.ndarray, by_name, rule: LockRule, reach: float = 0.02) -> np.ndarray:
    """Which points of ``grid`` lie, in plan, within ``reach`` [m] of the bounding box of both parts' footprints."""
    feet = [get_kind(by_name[n].kind).footprint_in_lid(tuple(by_name[n].pose)) for n in (rule.locker, rule.locked)]
    both = np.vstack(feet)
    lo, hi = both.min(axis=0) - reach, both.max(axis=0) + reach
    return np.all((grid[:, :2] >= lo) & (grid[:, :2] <= hi), axis=1)


def _distance_cost(grid: np.ndarray, by_name, rule: LockRule) -> np.ndarray:
    """What a crossing point's distance from the two parts costs, in fractions of travel: 1 per 10 cm from the
    midpoint of their frames (short tubes, and mechanisms that stay out of other pairs' way)."""
    mid = (np.asarray(by_name[rule.locker].pose[:2]) + np.asarray(by_name[rule.locked].pose[:2])) / 2
    return np.linalg.norm(grid[:, :2] - mid, axis=1) / 0.1


def _candidate_grid(spec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The box's inner bounds ``lo``, ``hi`` and candidate crossing points ``(n, 3)`` under the whole lid (where
    the parts move decides, not where they lie)."""
    length, width, height = spec.box.size
    lo = np.array([-length / 2 + BOX_MARGIN, -width / 2 + BOX_MARGIN, -height + BOX_MARGIN])
    hi = np.array([length / 2 - BOX_MARGIN, width / 2 - BOX_MARGIN, np.inf])
    # anywhere under the lid: a lever's pivot stands 33 mm above it, and its motion crosses a slide's only far out
    xs = np.arange(lo[0], hi[0] + 1e-9, GRID_STEP)
    ys = np.arange(lo[1], hi[1] + 1e-9, GRID_STEP)
    grid = np.stack(np.meshgrid(xs, ys, np.array(DEPTHS), indexing="ij"), axis=-1).reshape(-1, 3)
    return lo, hi, grid


def _motion(component) -> JointMotion:
    return JointMotion.of(get_kind(component.kind), tuple(component.pose))


@dataclass(frozen=True)
class _Paths:
    """Both motions' paths of one candidate X: ``C_A(t)``, ``C_B(t)`` for ``t`` in ``ts`` and their distances."""

    ts: np.ndarray
    a: np.ndarray
    b: np.ndarray
    distance: np.ndarray


def _paths(
    x: np.ndarray, a: JointMotion, b: JointMotion, dir_a: float, dir_b: float, xb: np.ndarray | None = None
) -> _Paths:
    """The paths of ``x`` through A and of ``xb`` (default ``x``) through B, and their distances."""
    ts = np.linspace(-1.2, 1.2, SAMPLES)
    pa = a.move(x, dir_a * a.travel * ts)
    pb = b.move(x if xb is None else xb, dir_b * b.travel * ts)
    # np.linalg.norm(pa[:, None] - pb[None], axis=-1) with the same operations in the same order (the same bits)
    # without its (n, n, 3) temporaries: a third of a box's mechanism design
    dx, dy, dz = (pa[:, None, k] - pb[None, :, k] for k in range(3))
    distance = np.sqrt(dx * dx + dy * dy + dz * dz)
    return _Paths(ts, pa, pb, distance)


def _index(ts: np.ndarray, t: float) -> int:
    return int(round((t - ts[0]) / (ts[1] - ts[0])))


def _backing(
    x, a: JointMotion, b: JointMotion, dir_a: float, dir_b: float, chains: int = BACKING_CHAINS
) -> tuple[list, list]:
    """Offsets [m] of the wall's and the rod's chains at X, their own axis first: the wall is backed along e1 (B's
    motion), away from the rod's tip, which comes from -e1; the rod along -e2, away from the wall's end, which
    comes from +e2 (A's motion). Thick where a part would have to pass through, thin where it must pass by:
    a part flung at a pin (20 N on a 25 g door: ~1 m/s at X, 2 mm a step) meets 5 mm of steel, not 2."""
    vb = b.velocity(x) * dir_b
    va = a.velocity(x) * dir_a
    e1 = vb / np.linalg.norm(vb)
    e2 = va - (va @ e1) * e1
    e2 /= np.linalg.norm(e2)
    steps = [k * BACKING_STEP for k in range(chains + 1)]
    return [s * e1 for s in steps], [-s * e2 for s in steps]


def _free_edges_clear(paths: _Paths, theta: float, delta: float) -> bool:
    """Whether the free edges of the configuration square are clear for these ``theta`` and ``delta``
    (:func:`_fractions`)."""
    need = 2 * TUBE_RADIUS + GAP + CHORD_SAGITTA
    ts, d = paths.ts, paths.distance
    i_m1, i_p1 = _index(ts, -1.0), _index(ts, 1.0)
    in_b = d[_index(ts, -theta) : i_p1 + 1, i_m1 : _index(ts, IN_STATE - delta) + 1]
    anywhere = d[_index(ts, FREE_FROM - theta) : i_p1 + 1, i_m1 : _index(ts, 1.0 - delta) + 1]
    return bool(in_b.min() >= need and anywhere.min() >= need)


def _fractions(paths: _Paths) -> tuple[float, float] | None:
    """``(theta, delta)``: the largest theta and smallest delta on the :data:`STEP` grid for which the free edges
    of the configuration square are clear (module docstring), or None. The bands decide the range: delta past
    :data:`IN_STATE` (a locked part anywhere in its state's band does not meet the wall) and at most
    :data:`MAX_BLOCKING`; theta short of :data:`FREE_FROM` (a locker past its open threshold has let go), at least
    :data:`HOLD_MARGIN` past :data:`IN_STATE` (a locker anywhere in its state's band holds) and at least
    ``1 - MAX_BLOCKING`` (a part held open by the rod moves back less than that).

    Free edges, with t the displacement (fraction of travel) that carries X through a part: B within IN_STATE of b
    and A anywhere (wall ``t`` in [-theta, 1], rod in [-1, IN_STATE - delta]) and A past :data:`FREE_FROM` and B
    anywhere (wall in [FREE_FROM - theta, 1], rod in [-1, 1 - delta])."""
    need = 2 * TUBE_RADIUS + GAP + CHORD_SAGITTA
    ts, d = paths.ts, paths.distance
    i_m1, i_p1 = _index(ts, -1.0), _index(ts, 1.0)
    deltas = np.arange(IN_STATE + STEP, MAX_BLOCKING + 1e-9, STEP)
    # theta at least HOLD_MARGIN past IN_STATE (a locker in its band holds) and 1 - MAX_BLOCKING (a part held open
    # by the rod moves back less than MAX_BLOCKING)
    thetas = np.arange(FREE_FROM - STEP, max(IN_STATE + HOLD_MARGIN, 1.0 - MAX_BLOCKING) - 1e-9, -STEP)
    for delta in deltas:
        # per wall sample, its nearest rod sample: B in b's band (rod [-1, IN_STATE - delta]) and B anywhere
        # (rod [-1, 1 - delta])
        in_b = d[: i_p1 + 1, i_m1 : _index(ts, IN_STATE - delta) + 1].min(axis=1)
        anywhere = d[: i_p1 + 1, i_m1 : _index(ts, 1.0 - delta) + 1].min(axis=1)
        clear_in_b = np.minimum.accumulate(in_b[::-1])[::-1]  # min over wall samples i..t=1
        clear_anywhere = np.minimum.accumulate(anywhere[::-1])[::-1]
        for theta in thetas:  # largest first: A frees B wherever it rests past FREE_FROM
            if clear_in_b[_index(ts, -theta)] >= need and clear_anywhere[_index(ts, FREE_FROM - theta)] >= need:
                return float(theta), float(delta)
    return None


def _design_interlock(spec, first: LockRule, second: LockRule, a: JointMotion, b: JointMotion, by_name):
    """The best interlock for a pair of rules, or why there is none."""
    dir_a = 1.0 if first.locker_state == 0 else -1.0  # A goes from a toward 1-a
    dir_b = 1.0 if first.locked_state == 0 else -1.0  # B goes from b toward 1-b
    lo, hi, grid = _candidate_grid(spec)
    va = _velocities(a, grid) * (dir_a * a.travel)  # per unit fraction of travel
    vb = _velocities(b, grid) * (dir_b * b.travel)
    na, nb = np.linalg.norm(va, axis=1), np.linalg.norm(vb, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        sine = np.linalg.norm(np.cross(va, vb), axis=1) / (na * nb)
    keep = (na > 1e-6) & (nb > 1e-6) & (sine >= MIN_CROSSING_SINE)
    # the clearance across the motions alone asks at least this much of each part's travel: hopeless beyond
    with np.errstate(divide="ignore", invalid="ignore"):
        keep &= (2 * TUBE_RADIUS + GAP) / (sine * np.minimum(na, nb)) <= (MAX_BLOCKING - IN_STATE) * 1.25
    # every tube lies on X's paths through A and B over a whole travel each way: inside the box?
    top = np.full(len(grid), -np.inf)
    for t in np.linspace(-1.0, 1.0, 9):
        for motion in (a, b):
            moved = motion.move(grid, motion.travel * t)
            keep &= np.all((moved >= lo + TUBE_RADIUS) & (moved <= hi - TUBE_RADIUS), axis=1)
            top = np.maximum(top, moved[:, 2])
    if not np.any(keep):
        return "no point inside the box where the two parts' motions cross at 30 degrees or more"
    # first guess of the blocking fractions from the local geometry (clearance across the motion)
    with np.errstate(divide="ignore", invalid="ignore"):  # (points where a part does not move are not kept)
        guess = (2 * TUBE_RADIUS + GAP) / sine * (1 / na + 1 / nb)
    # near the two parts first (within 2 cm of their footprints), ordered by the guess; then the rest of the lid
    guess = guess + np.where(_near(grid, by_name, first), 0.0, 100.0)
    exposure = np.where(top + TUBE_RADIUS > 0, 0.5 + 200.0 * (top + TUBE_RADIUS), 0.0)
    cost = np.where(keep, guess + exposure, np.inf)
    order = np.argsort(cost, kind="stable")[: int(keep.sum())]
    best = None
    reasons: dict[str, int] = {}
    for k, index in enumerate(order):
        if k >= MAX_TRIED and (best is not None or k >= 40 * MAX_TRIED):
            break
        point = grid[index]
        paths = _paths(point, a, b, dir_a, dir_b)
        fractions = _fractions(paths)
        if fractions is None:
            reasons["the tubes cannot clear each other"] = reasons.get("the tubes cannot clear each other", 0) + 1
            continue
        theta, delta = fractions
        if best is not None and (1 - theta) + delta >= best[0]:
            continue  # its score (below) is at least this: no exposure makes it the best
        wall_ts = _tube_ts(-theta, 0.0, a, _radius(a, point))
        rod_ts = _tube_ts(-1.0, -delta, b, _radius(b, point))
        # the wall and rod with every part closed: X carried back to where the parts stand at state 0
        q0a, q0b = a.q(first.locker_state), b.q(first.locked_state)
        wall0 = a.move(a.move(point, dir_a * a.travel * wall_ts), -q0a)
        rod0 = b.move(b.move(point, dir_b * b.travel * rod_ts), -q0b)
        corners = [np.vstack([a.move(wall0, a.q(sa)), b.move(rod0, b.q(sb))]) for sa in (0, 1) for sb in (0, 1)]
        exposed = float(np.vstack(corners)[:, 2].max() + TUBE_RADIUS)
        score = (1 - theta) + delta + _exposure_cost(exposed)
        if best is None or score < best[0]:
            best = (score, point, theta, delta, wall_ts, rod_ts, float(sine[index]), exposed)
    if best is None:
        common = max(reasons, key=reasons.__getitem__) if reasons else "no candidate"
        return f"no crossing point serves the pair (mostly: {common})"
    _, point, theta, delta, wall_ts, rod_ts, sine, exposed = best
    # each tube a slab: its axis through X and as much backing behind it, away from where the other tube comes
    # from, as the free moves leave room for (none: a plain pin, as thin as the clearance asks)
    for chains in range(BACKING_CHAINS, -1, -1):
        wall_offsets, rod_offsets = _backing(point, a, b, dir_a, dir_b, chains)
        if all(
            _free_edges_clear(_paths(point + ow, a, b, dir_a, dir_b, point + orr), theta, delta)
            for ow in wall_offsets[1:]
            for orr in rod_offsets
        ) and all(
            _free_edges_clear(_paths(point, a, b, dir_a, dir_b, point + orr), theta, delta) for orr in rod_offsets[1:]
        ):
            break
    q0a, q0b = a.q(first.locker_state), b.q(first.locked_state)
    wall0 = np.stack([a.move(a.move(point + o, dir_a * a.travel * wall_ts), -q0a) for o in wall_offsets])
    rod0 = np.stack([b.move(b.move(point + o, dir_b * b.travel * rod_ts), -q0b) for o in rod_offsets])
    return Interlock(
        name=f"{first.locker}-interlocks-{first.locked}",
        locker=first.locker,
        locked=first.locked,
        locker_state=first.locker_state,
        locked_state=first.locked_state,
        rules=(first, second),
        crossing=point,
        theta=theta,
        delta=delta,
        wall=wall0,
        rod=rod0,
        crossing_sine=sine,
        exposed=exposed,
    )


def _velocities(motion: JointMotion, points: np.ndarray) -> np.ndarray:
    """Velocities ``(n, 3)`` of the material points at ``points`` ``(n, 3)`` per unit joint velocity."""
    if motion.joint == "slide":
        return np.broadcast_to(motion.axis, points.shape).copy()
    return np.cross(motion.axis, points - motion.origin)


def _radius(motion: JointMotion, point: np.ndarray) -> float:
    """Distance of ``point`` from a hinge's axis [m] (0 for a slide)."""
    if motion.joint == "slide":
        return 0.0
    v = np.asarray(point) - motion.origin
    return float(np.linalg.norm(v - (v @ motion.axis) * motion.axis))


def _exposure_cost(exposed: float) -> float:
    """What showing a tube above the lid costs, in fractions of travel: 0.5 for showing at all, plus 0.2 per mm."""
    return 0.0 if exposed <= 0 else 0.5 + 200.0 * exposed


def _tube_ts(t0: float, t1: float, motion: JointMotion, radius: float) -> np.ndarray:
    """Displacements (fraction of travel) sampling a tube from ``t0`` to ``t1``: two for a slide (a straight
    capsule); for a hinge, as few chords as keep the chain within :data:`CHORD_SAGITTA` of its arc of ``radius``
    [m] about the hinge (few capsules: each is a geom collided every step)."""
    if motion.joint == "slide":
        return np.array([t0, t1])
    turn = abs(t1 - t0) * motion.travel
    chord_angle = 2 * np.arccos(max(1.0 - CHORD_SAGITTA / max(radius, 1e-6), -1.0))
    n = max(1, int(np.ceil(turn / chord_angle)))
    return np.linspace(t0, t1, n + 1)
