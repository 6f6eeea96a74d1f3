"""What a trial is: the simulator, the agent, the seed, the budget and — in the twin — the cell."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from puzzlebox.lab.errors import TrialConfigError
from puzzlebox.lab.inputs import MAX_ACTIONS, InputError, check_count, check_seed
from puzzlebox.learning.dual_controller import MAX_LOCKERS
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
        if not isinstance(self.agent, str):
            problems.append(f"agent must be an agent's name (give an agent object to run_trial), got {self.agent!r}")
        checks = [(check_seed, self.seed, "seed", ()), (check_count, self.max_actions, "max_actions", (MAX_ACTIONS,))]
        if self.max_lockers is not None:
            checks.append((check_count, self.max_lockers, "max_lockers", (MAX_LOCKERS,)))
        for check, value, name, bounds in checks:
            try:
                check(int(value) if isinstance(value, np.integer) else value, name, *bounds)
            except InputError as err:
                problems.append(str(err))
        if not isinstance(self.reality, str | Path | RealityProfile):
            problems.append(f"reality must be a profile's name, a file or a RealityProfile, got {self.reality!r}")
        if self.calibration is not None and not isinstance(self.calibration, CellCalibration):
            problems.append(f"calibration must be a CellCalibration (load_calibration), got {self.calibration!r}")
        for name in ("memory", "checkpoint"):
            if getattr(self, name) is not None and not isinstance(getattr(self, name), str | Path):
                problems.append(f"{name} must be a path, got {getattr(self, name)!r}")
        if self.locks not in LOCK_MODES:
            problems.append(f"locks must be one of {list(LOCK_MODES)}, got {self.locks!r}")
        if self.sim == "symbolic" and self.misreport_kind:
            problems.append("misreport_kind is a twin fault (the symbolic simulator's is FaultConfig)")
        if problems:
            raise TrialConfigError("; ".join(problems))
