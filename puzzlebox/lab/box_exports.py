"""A puzzle box exported for other tools, as ``generate.py mjcf`` and ``mesh`` write it: the MuJoCo scene (or the
box alone) with the lock rules no mechanism realizes named, and the box's meshes with the lock features that have
no room to be shown named. Each export yields the lines the command prints, each as soon as it holds."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from puzzlebox.lab.cli import one_line
from puzzlebox.lab.errors import BoxBuildError
from puzzlebox.lab.spec_files import load_box_spec
from puzzlebox.models import LockRule, ModelsError, PuzzleSpec
from puzzlebox.models.mechanism_mjcf import LockMode, mechanism_layout


def rule_text(rule: LockRule) -> str:
    """A lock rule as one phrase: ``A=1 holds B=0``."""
    return f"{rule.locker}={rule.locker_state} holds {rule.locked}={rule.locked_state}"


def latch_only(spec: PuzzleSpec, locks: str) -> list[tuple[LockRule, str]]:
    """The rules of ``spec`` no mechanism realizes with ``locks`` (every rule with ``latch``), each with why."""
    if locks == "latch":
        return [(rule, "--locks latch: no mechanism") for rule in spec.locks]
    return [(u.rule, u.reason) for u in mechanism_layout(spec).unrealized]


def export_mjcf(file: str, out: str, box_only: bool, locks: LockMode) -> Iterator[str]:
    """Write the MuJoCo model of the box in ``file`` to the directory ``out``: ``scene.xml`` (table, robot, box)
    or with ``box_only`` ``box.xml`` (the box alone, lid frame at the origin), and their assets. Yields what was
    written and, if any, the rules the model alone does not hold (:class:`BoxBuildError` if it cannot be built)."""
    spec = load_box_spec(file)
    try:
        if box_only:
            from puzzlebox.models.box_export import export_box  # MuJoCo only when asked

            path = export_box(spec, out, locks=locks)
        else:
            from puzzlebox.models.scene import SceneConfig, build_scene

            path = build_scene(spec, SceneConfig(locks=locks)).export(out)
    except ModelsError as err:  # an unknown kind, a box pose out of the robot's reach
        raise BoxBuildError(f"{file}: {one_line(err)}") from err
    yield f"wrote {path} and its assets ({len(list(Path(out).iterdir())) - 1} files)"
    unrealized = latch_only(spec, locks)
    if unrealized:  # a rule the model alone does not hold: say so
        rules = "; ".join(f"{rule_text(rule)} ({reason})" for rule, reason in unrealized)
        yield f"{len(unrealized)} rule(s) enforced by latches only in the twin: {rules}"


def export_box_meshes(file: str, out: str) -> Iterator[str]:
    """Write the box in ``file`` as meshes in ``out`` (``models.mesh_export``: ``<name>.glb|.obj|.stl`` and one STL
    per part). Yields what was written, how many lock features are shown, and each one that is not, with why."""
    from puzzlebox.models.lock_features import layout_lock_features
    from puzzlebox.models.mesh_export import export_meshes  # MuJoCo and trimesh only when asked

    spec = load_box_spec(file, use="export as meshes")
    paths = export_meshes(spec, out)
    yield f"wrote {len(paths)} files in {out}: {', '.join(p.name for p in paths[:3])} and one STL per part"
    layout = layout_lock_features(spec)
    yield f"lock features: {len(layout.features)} shown, {len(layout.skipped)} without room on their locker"
    for skipped in layout.skipped:  # a lock the physics enforces but the model cannot show: say so
        yield f"  not shown: {skipped.locker} -> {skipped.locked}: {skipped.reason}"
