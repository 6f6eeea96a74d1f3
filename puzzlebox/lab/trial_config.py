"""What a trial is: the simulator, the agent, the seed, the budget and — in the twin — the cell."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from puzzlebox.lab.errors import TrialConfigError
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.mechanism_mjcf import LOCK_MODES
from puzzlebox.twin.reality import RealityProfile

__all__ = ["SIMS", "TrialConfig"]

SIMS = ("twin", "symbolic")


@dataclass(frozen=True)
class TrialConfig:
    """One trial's settings (the agent itself may be given as an object to :func:`puzzlebox.lab.run_trial`).

    Attributes:
        sim: ``"twin"`` (perception, motion primitives and physics in MuJoCo) or ``"symbolic"`` (the symbolic
            simulator: the agent's actions act on the spec directly).
        agent: name of a registered agent (``puzzlebox.learning.AGENT_NAMES``), used when no agent object is
            given: ``dual``, ``memory`` (needs ``memory``), ``random``, ``oracle``, the deep agents (need
            ``checkpoint``).
        seed: the trial's seed: the agent's generator, the twin's noise and the box's placement draw from it.
        max_actions: the most tries before the trial counts as unsolved.
        reality: the twin's reality profile: ``ideal``, ``realistic``, ``harsh``, a profile JSON file or a
            :class:`~puzzlebox.twin.reality.RealityProfile`.
        calibration: the cell's camera calibration (``calibrate.py``'s file, loaded); None: the twin's nominal,
            datasheet calibration — exact only under ``ideal``.
        memory: the memory agent's memory file (SQLite, ``train.py``'s).
        checkpoint: a deep agent's checkpoint file.
        misreport_kind: the pipeline is told one component's kind wrong (drawn from the seed).
        max_lockers: the most lockers the belief-based agents allow one component (1: the paper's; None: what fits
            the scene and the memory, ``learning.scene_lockers.scene_max_lockers``).
        locks: the twin box's locks: ``contact`` (mechanisms that block by contact) or ``latch`` (rule-driven
            joint constraints, the ablation).
    """

    sim: Literal["twin", "symbolic"] = "twin"
    agent: str = "dual"
    seed: int = 0
    max_actions: int = 30
    reality: str | Path | RealityProfile = "ideal"
    calibration: CellCalibration | None = None
    memory: Path | None = None
    checkpoint: Path | None = None
    misreport_kind: bool = False
    max_lockers: int | None = None
    locks: Literal["contact", "latch"] = "contact"

    def __post_init__(self) -> None:
        problems = []
        if self.sim not in SIMS:
            problems.append(f"sim must be one of {list(SIMS)}, got {self.sim!r}")
        if self.max_actions < 1:
            problems.append(f"max_actions must be at least 1, got {self.max_actions}")
        if self.max_lockers is not None and self.max_lockers < 1:
            problems.append(f"max_lockers must be at least 1, got {self.max_lockers}")
        if self.locks not in LOCK_MODES:
            problems.append(f"locks must be one of {list(LOCK_MODES)}, got {self.locks!r}")
        if self.sim == "symbolic" and self.misreport_kind:
            problems.append("misreport_kind is a twin fault (the symbolic simulator's is FaultConfig)")
        if problems:
            raise TrialConfigError("; ".join(problems))
