"""Chains: the paper's puzzle family generalised to any kind sequence and length.

Chain rules for k = 0..N-2 (PAPER_NOTES.md): ``L[k, 0, k+1, 0]`` (k closed keeps k+1 closed) and
``L[k+1, 1, k, 1]`` (k+1 open keeps k open). The goal is the last component open; the optimal
solution opens the components in chain order (N actions).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from puzzlebox.models.errors import GeneratorError
from puzzlebox.models.generator.layout import Layout, LayoutConfig
from puzzlebox.models.kinds import registered_kinds, registry_family
from puzzlebox.models.reach import MAX_REACH, MIN_REACH, fitting_box_pose
from puzzlebox.models.spec import Box, Component, Goal, LockRule, PuzzleSpec, file_precision

MAX_LAYOUT_ATTEMPTS = 200


@dataclass(frozen=True)
class BoxConfig:
    """The box a generated puzzle sits in."""

    height: float = 0.08
    """Box height [m]."""
    pose: tuple[float, float, float] | None = (0.45, 0.0, 0.0)
    """Box centre on the table in the robot base frame ``[x, y, yaw]`` [m, m, rad]; None = twin default."""
    lid_size: tuple[float, float] | None = None
    """Lid (length, width) [m]; None = the smallest that holds the layout with its margin."""
    layout: LayoutConfig = field(default_factory=LayoutConfig)
    fit_reach: bool = True
    """Stand the box where the robot reaches every handle: at :attr:`pose` if it does, else at the
    nearest pose that does (:func:`models.reach.fitting_box_pose`); a layout no pose fits is drawn again,
    and more than :data:`MAX_REACHABLE_COMPONENTS` components are refused. False: keep :attr:`pose`
    whatever it leaves out of reach (a box for the symbolic simulator only)."""
    realizable: bool = True
    """Draw again until every lock rule is a mechanism that blocks by contact (:mod:`models.lock_mechanisms`) and
    no part strikes another as it moves (:mod:`models.part_clearance`), so that the model alone behaves as the
    spec says; False keeps the first layout drawn (a rule no mechanism serves
    is then held by a latch in the twin)."""


MAX_REACHABLE_COMPONENTS = 28
"""Most components a generated box holds with every handle within the robot's reach: the fraction of
random layouts some pose fits falls from 20/20 at 16 components to 16/20 at 20, 2/20 at 28 and 0/20 at 32
(seeds 0-19), with handles allowed 0.20-0.62 m from the base axis."""


def realizable(spec: PuzzleSpec, box: BoxConfig) -> bool:
    """Whether ``spec`` is acceptable under ``box.realizable``: every lock rule a mechanism and no two parts that
    strike each other as they move (:mod:`models.part_clearance`), or not asked."""
    if not box.realizable:
        return True
    # the design search and the sweep only when generating
    from puzzlebox.models.lock_mechanisms import design_mechanisms
    from puzzlebox.models.part_clearance import meeting_parts

    return design_mechanisms(spec).complete and not meeting_parts(spec)


def check_reach_size(num_components: int, box: BoxConfig) -> None:
    """Refuse a box too large for the robot's reach, unless ``box.fit_reach`` is off."""
    if box.fit_reach and box.pose is not None and num_components > MAX_REACHABLE_COMPONENTS:
        raise GeneratorError(
            f"{num_components} components do not fit the robot's reach (every handle within "
            f"{MIN_REACH:.2f}-{MAX_REACH:.2f} m of the base; at most {MAX_REACHABLE_COMPONENTS} do): for a box "
            "the symbolic simulator alone will use, turn reach fitting off (generate.py --anywhere)"
        )


def fit_to_reach(spec: PuzzleSpec, box: BoxConfig) -> PuzzleSpec | None:
    """``spec`` with its box moved where every handle is within reach (see :attr:`BoxConfig.fit_reach`);
    None when no pose fits; ``spec`` unchanged when fitting is off or the box has no pose."""
    if not box.fit_reach or spec.box is None or spec.box.pose is None:
        return spec
    pose = fitting_box_pose(spec, start=spec.box.pose)
    if pose is None:
        return None
    return replace(spec, box=replace(spec.box, pose=file_precision(pose)))


def check_chain_kinds(kinds: Sequence[str]) -> None:
    """Raise :class:`GeneratorError` unless ``kinds`` is a chain of registered kinds whose neighbours may lock
    each other (:func:`models.kinds.registry_family`: for the paper's kinds, the paper's pairs)."""
    if len(kinds) < 2:
        raise GeneratorError(f"a chain needs at least 2 components, got {len(kinds)}")
    unknown = [k for k in kinds if k not in registered_kinds()]
    if unknown:
        raise GeneratorError(f"unknown kinds {unknown}; known kinds: {sorted(registered_kinds())}")
    family = registry_family()
    for k in range(len(kinds) - 1):
        if not family.may_neighbour(kinds[k], kinds[k + 1]):
            allowed = sorted("-".join(sorted(p)) for p in family.neighbours)
            raise GeneratorError(
                f"kinds {kinds[k]!r} and {kinds[k + 1]!r} at positions {k} and {k + 1} cannot lock each "
                f"other; neighbours must be one of {allowed}"
            )


def chain_layout(kinds: Sequence[str], rng: np.random.Generator, layout_config: LayoutConfig) -> Layout:
    """Place a chain, each component attached to its predecessor; retries a layout that boxes itself in."""
    for _ in range(MAX_LAYOUT_ATTEMPTS):
        layout = Layout(layout_config)
        layout.place_first(kinds[0])
        if all(layout.attach(k - 1, kinds[k], rng) for k in range(1, len(kinds))):
            layout.turn_lengthwise()
            return layout
    raise GeneratorError(f"no layout found for the chain {list(kinds)} in {MAX_LAYOUT_ATTEMPTS} attempts")


def chain_rules(length: int) -> list[tuple[int, int, int, int]]:
    """The paper's chain rules ``(locker, locker_state, locked, locked_state)`` by chain position."""
    rules = []
    for k in range(length - 1):
        rules += [(k, 0, k + 1, 0), (k + 1, 1, k, 1)]
    return rules


def assemble(
    name: str,
    kinds: Sequence[str],
    layout: Layout,
    locks_by_index: Sequence[tuple[int, int, int, int]],
    goal: int,
    box: BoxConfig,
) -> PuzzleSpec:
    """Turn a layout and index-based lock rules into a spec (names ``<kind>-<index>``, markers = index)."""
    names = [f"{kind}-{i}" for i, kind in enumerate(kinds)]
    lid = box.lid_size if box.lid_size is not None else layout.lid_size()
    components = tuple(
        Component(name=names[i], kind=kinds[i], pose=file_precision(pose), marker=i)
        for i, pose in enumerate(layout.poses_in_lid(box.lid_size))
    )
    locks = tuple(LockRule(names[a], sa, names[b], sb) for a, sa, b, sb in locks_by_index)
    return PuzzleSpec(
        name=name,
        components=components,
        locks=locks,
        goal=Goal(names[goal], 1),
        box=Box(
            size=file_precision((lid[0], lid[1], box.height)),  # type: ignore[arg-type]
            pose=file_precision(box.pose) if box.pose is not None else None,  # type: ignore[arg-type]
        ),
    )


def generate_chain(
    kinds: Sequence[str], seed: int, name: str | None = None, box: BoxConfig | None = None
) -> PuzzleSpec:
    """A chain puzzle of the given kinds; a pure function of its arguments.

    Args:
        kinds: kind of each component in chain order, e.g. ``["door", "slide", "wheel"]``.
        seed: seeds the layout's turns.
        name: spec name; default ``chain-<kinds>-s<seed>``.
        box: the box; default :class:`BoxConfig` (lid sized to the layout).
    """
    kinds = list(kinds)
    check_chain_kinds(kinds)
    box = box or BoxConfig()
    check_reach_size(len(kinds), box)
    rng = np.random.default_rng(seed)
    rules = chain_rules(len(kinds))
    name = name or f"chain-{'-'.join(kinds)}-s{seed}"
    for _ in range(MAX_LAYOUT_ATTEMPTS):
        spec = fit_to_reach(
            assemble(name, kinds, chain_layout(kinds, rng, box.layout), rules, len(kinds) - 1, box), box
        )
        if spec is not None and realizable(spec, box):
            return spec
    raise GeneratorError(
        f"no layout of the chain {kinds} fits the robot's reach{' with every lock a mechanism' * box.realizable} in "
        f"{MAX_LAYOUT_ATTEMPTS} attempts"
    )
