"""``generate.py check-locks``: does each box's MuJoCo model alone hold its lock rules? Every part of each box is
pushed from every state reachable from all-closed (``models.lock_check``), with the box alone or in the whole
scene; :class:`LockChecks` keeps each box's record (moves as fractions of a part's travel), its lines, the
total and the command's exit code."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

from puzzlebox.lab.box_exports import latch_only
from puzzlebox.lab.cli import one_line
from puzzlebox.lab.errors import BoxBuildError
from puzzlebox.models import LockRule, ModelsError, PuzzleSpec

if TYPE_CHECKING:
    import mujoco

    from puzzlebox.models.lock_check import LockCheck
    from puzzlebox.models.mechanism_mjcf import LockMode


class LockChecks:
    """The checks of several boxes with ``locks`` (contact or latch), the box alone or ``with_robot``; every other
    part resting at each of ``offsets`` of its travel from the end stop of its state (the band check,
    ``models.lock_check.BAND_OFFSETS``; ``(0.0,)``: at the stops only)."""

    def __init__(self, locks: LockMode, with_robot: bool, offsets: tuple[float, ...] = (0.0,)) -> None:
        self.locks: LockMode = locks
        self.with_robot = with_robot
        self.offsets = offsets
        self.boxes: list[dict[str, Any]] = []
        self.errors: list[dict[str, str]] = []

    def check(self, file: str, spec: PuzzleSpec) -> list[str]:
        """Check one box: its line and one indented line per disagreement (:class:`BoxBuildError`, also kept
        in :attr:`errors`, if its model cannot be built)."""
        from puzzlebox.models.lock_check import check_locks  # MuJoCo only when asked

        try:
            model, joints = compiled_model(spec, self.locks, self.with_robot)
        except ModelsError as err:
            self.errors.append({"file": str(file), "spec": spec.name, "error": one_line(err)})
            raise BoxBuildError(f"{file}: {one_line(err)}") from err
        check = check_locks(spec, model, joints, offsets=self.offsets)
        box = box_record(file, spec, check, latch_only(spec, self.locks))
        self.boxes.append(box)
        lines = [box_line(box)]
        for t in box["disagreements"]:
            opened = ", ".join(t["open"]) or "none"
            moved = f"moved {100 * t['moved']:.1f} % of its travel"
            rest = "at their stops" if t["offset"] == 0 else f"{100 * t['offset']:.0f} % inside their bands"
            lines.append(f"  open [{opened}], the others {rest}: {t['component']} should be {t['expected']}, {moved}")
        return lines

    def run(self, specs: Iterable[tuple[str, PuzzleSpec]], say: Callable[[str], object],
            warn: Callable[[str], object]) -> None:  # fmt: skip
        """Check every box in turn: its lines to ``say`` as soon as it is checked, ``error: FILE: why`` to ``warn``
        for a box that cannot be built (and on to the next)."""
        for file, spec in specs:
            try:
                lines = self.check(file, spec)
            except BoxBuildError as err:
                warn(f"error: {err}")
                continue
            for line in lines:
                say(line)

    @property
    def agreeing(self) -> int:
        return sum(b["agreeing"] for b in self.boxes)

    @property
    def total(self) -> int:
        return sum(b["total"] for b in self.boxes)

    def record(self) -> dict[str, Any]:
        """Every box's result, as ``--json FILE`` writes it."""
        record = {"locks": self.locks, "with_robot": self.with_robot, "offsets": list(self.offsets),
                  "agreeing": self.agreeing, "total": self.total}  # fmt: skip
        return {**record, "boxes": self.boxes, "errors": self.errors}

    def total_line(self) -> str:
        """The last line: the total over every box checked, and how many could not be built."""
        held = [b["held_move_max"] for b in self.boxes if b["held_move_max"] is not None]
        summary = {
            "spec": f"total ({len(self.boxes)} box(es))",
            "agreeing": self.agreeing,
            "total": self.total,
            "held_move_max": max(held) if held else None,
            "unrealized": [u for b in self.boxes for u in b["unrealized"]],
        }
        return box_line(summary) + (f"; {len(self.errors)} box(es) not built" if self.errors else "")

    @property
    def exit_code(self) -> int:
        """2 if a box could not be built, else 1 if any transition disagrees, else 0."""
        if self.errors:
            return 2
        return 1 if self.agreeing < self.total else 0


def compiled_model(spec: PuzzleSpec, locks: LockMode, with_robot: bool) -> tuple[mujoco.MjModel, dict[str, str]]:
    """The compiled model of ``spec`` (the box alone, or the whole scene) and each component's joint name."""
    if not with_robot:
        from puzzlebox.models.box_export import compile_box

        return compile_box(spec, locks)
    from puzzlebox.models.scene import SceneConfig, build_scene

    scene = build_scene(spec, SceneConfig(locks=locks))  # UnreachableBoxPose: a ModelsError
    return scene.compile(), {name: names.joint for name, names in scene.names.components.items()}


def box_record(file: str, spec: PuzzleSpec, result: LockCheck, unrealized: list[tuple[LockRule, str]]) -> dict:
    """One box's check as JSON-ready data (moves are fractions of a part's travel)."""
    held = result.held_moves()
    return {
        "spec": spec.name,
        "file": str(file),
        "agreeing": result.agreeing,
        "total": len(result.transitions),
        "held_move_max": max(held) if held else None,
        "disagreements": [
            {
                "open": [c.name for k, c in enumerate(spec.components) if (t.state >> k) & 1],
                "component": t.component,
                "expected": "free" if t.expected_free else "held",
                "moved": t.moved,
                "offset": t.offset,
            }
            for t in result.disagreements()
        ],
        "unrealized": [{**dataclasses.asdict(rule), "reason": reason} for rule, reason in unrealized],
    }


def box_line(box: dict) -> str:
    """A box's (or the total's) line: transitions that agree, the largest play of a held part (how far it went before
    its lock caught it: a part that went past ``HELD_FRACTION`` of its travel is no longer held, and its transition
    disagrees), rules without a mechanism."""
    from puzzlebox.models.lock_check import HELD_FRACTION  # (MuJoCo: the check has run)

    held = box["held_move_max"]
    moved = (
        "no part held" if held is None
        else f"a held part's play (before its lock caught it) up to {100 * held:.1f} % of its travel, "
        f"held below {100 * HELD_FRACTION:.0f} %"
    )  # fmt: skip
    agree = f"{box['agreeing']}/{box['total']} transitions agree"
    return f"{box['spec']}: {agree}; {moved}; {len(box['unrealized'])} rule(s) without a mechanism"
