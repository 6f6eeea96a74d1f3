"""Spec files as ``generate.py`` reads and writes them: a generated spec written (with its top view if asked),
a file loaded as a puzzle box (not a disassembly scene), several loaded at once with every problem named, and
a file's validation lines; a set of boxes checked to hold each box once and each name for one box."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from puzzlebox.lab.cli import one_line
from puzzlebox.lab.errors import NotABoxSpec, SpecFileError, SpecFilesInvalid
from puzzlebox.lab.inputs import InputError
from puzzlebox.learning.errors import LearningError
from puzzlebox.learning.locker_sets import check_belief_size
from puzzlebox.models import LockTable, PuzzleSpec, SpecError, load_spec, save_spec
from puzzlebox.models.placement import PlacementRange, sample_reachable_pose
from puzzlebox.models.scene import DEFAULT_BOX_POSE, SceneConfig, SceneError, unreachable_handles


def write_spec_file(spec: PuzzleSpec, path: Path, plot: bool) -> list[str]:
    """Write ``spec`` to ``path`` (and, if ``plot``, its top view as a PNG beside it): one line per file written."""
    lines = [f"wrote {save_spec(spec, path)}  ({'-'.join(spec.kinds)})"]
    if plot:
        from puzzlebox.lab.spec_plot import plot_spec  # matplotlib only when asked

        lines.append(f"wrote {plot_spec(spec, path.with_suffix('.png'))}")
    return lines


def load_box_spec(file: str | Path, use: str = "build as MuJoCo models") -> PuzzleSpec:
    """The puzzle-box spec in ``file``: :class:`SpecFileError` if it is unreadable or invalid (its problems on
    one line), :class:`NotABoxSpec` if it is a disassembly scene (only puzzle boxes ``use``, e.g. "export as
    meshes")."""
    try:
        spec = load_spec(file)
    except SpecError as err:
        raise SpecFileError(one_line(err)) from err
    if spec.box is None:
        raise NotABoxSpec(f"{file}: spec {spec.name!r} is a disassembly scene (no box); only puzzle boxes {use}")
    return spec


def load_box_specs(files: list[str]) -> list[tuple[str, PuzzleSpec]]:
    """Every file's puzzle-box spec, each with its file, read before any box is built;
    :class:`SpecFilesInvalid` naming every file that is not one (one line each) if any is not."""
    loaded: list[tuple[str, PuzzleSpec]] = []
    problems: list[str] = []
    for file in files:
        try:
            loaded.append((file, load_box_spec(file)))
        except SpecFileError as err:
            problems.append(str(err))
    if problems:
        raise SpecFilesInvalid(problems)
    return loaded


def validation_lines(file: str) -> tuple[list[str], bool]:
    """The lines ``generate.py validate`` prints for ``file`` (one per problem, or one saying it is valid with its
    size and shortest solution) and whether it is valid."""
    try:
        spec = load_spec(file)
    except SpecError as err:
        return [f"{file}: {problem}" for problem in err.problems], False
    plan = LockTable.from_spec(spec).shortest_solution()
    return [f"{file}: valid ({len(spec.components)} components, shortest solution {len(plan or [])} actions)"], True


def check_distinct_specs(specs: Sequence[PuzzleSpec], paths: Sequence[str]) -> None:
    """Each box once, each name one box (:class:`~puzzlebox.lab.inputs.InputError` naming both files): overlapping
    globs ran the same spec and seed twice, and two boxes of one name were summed as one in every summary."""
    seen: dict[str, tuple[str, str]] = {}  # name -> (its content, its file)
    for spec, path in zip(specs, paths, strict=True):
        content = spec.to_json()
        if spec.name in seen:
            other_content, other = seen[spec.name]
            same = "the same box" if other_content == content else "two different boxes of one name"
            raise InputError(f"--specs gives {same}, {spec.name!r} ({other} and {path}): give each box once, each "
                             "name to one box")  # fmt: skip
        seen[spec.name] = (content, path)


def check_box_reach(specs: Sequence[PuzzleSpec], paths: Sequence[str], placement: PlacementRange | None) -> None:
    """Each box can stand where the twin will place it (:class:`~puzzlebox.lab.inputs.InputError` naming the file):
    at its own pose (``placement`` None) every handle within the arm's reach, or somewhere reachable in ``placement``
    (a reality profile's range; drawn as the runs draw it, from seed 0). Checked at run time only, every run failed
    and left an ``--out`` that a plain rerun refused."""
    scene = SceneConfig()
    for spec, path in zip(specs, paths, strict=True):
        if spec.box is None:
            continue
        if placement is None:
            pose = spec.box.pose if spec.box.pose is not None else DEFAULT_BOX_POSE
            far = unreachable_handles(spec, (pose[0], pose[1], pose[2]), scene)
            if far:
                raise InputError(f"{path}: box pose {list(pose)} puts handles outside the arm's reach "
                                 f"({scene.min_reach:.2f}..{scene.max_reach:.2f} m from its base axis): "
                                 f"{', '.join(far[:2])}{', ...' if len(far) > 2 else ''}")  # fmt: skip
            continue
        try:
            sample_reachable_pose(spec, np.random.default_rng(0), placement, scene)
        except SceneError as err:
            raise InputError(f"{path}: the reality profile's placement holds no reachable pose ({err})") from None


def check_belief_sizes(specs: Sequence[PuzzleSpec], paths: Sequence[str], max_lockers: int | None) -> None:
    """Each box's belief over sets of up to ``max_lockers`` lockers fits
    (:func:`puzzlebox.learning.locker_sets.check_belief_size`; :class:`~puzzlebox.lab.inputs.InputError` naming the
    file): a belief too large ran on without a word. None or 1: the paper's belief, always small."""
    if max_lockers is None or max_lockers <= 1:
        return
    for spec, path in zip(specs, paths, strict=True):
        try:
            check_belief_size(len(spec.components), max_lockers)
        except LearningError as err:
            raise InputError(f"--max-lockers {max_lockers} on {path}: {err}") from None
