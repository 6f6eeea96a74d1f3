"""The composition layer: the one package that imports the twin, the skills, the learning layer and the real arm
together, to run trials (:func:`run_trial`, :func:`open_world`), sweeps, datasets, calibrations, reports and the
twin experiments (DESIGN.md, "Layers").

The names below are imported when first used (PEP 562): a command that needs one module of the package (its
argument checks, a report, a spec file) does not pay for the twin, the skills and torch at start-up."""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from puzzlebox.lab.cells import CellError, RealCell, TwinCell
    from puzzlebox.lab.errors import AgentClassError, LabError, RunStoreError, TrialConfigError
    from puzzlebox.lab.observers import ObservedRobot, PeakWristForce, SensedDigest, TrialContext, TrialObserver
    from puzzlebox.lab.trial_config import TrialConfig
    from puzzlebox.lab.trial_record import TrialRecord
    from puzzlebox.lab.trials import open_world, run_trial

_WHERE = {
    "CellError": "cells", "RealCell": "cells", "TwinCell": "cells",
    "AgentClassError": "errors", "LabError": "errors", "RunStoreError": "errors", "TrialConfigError": "errors",
    "ObservedRobot": "observers", "PeakWristForce": "observers", "SensedDigest": "observers",
    "TrialContext": "observers", "TrialObserver": "observers",
    "TrialConfig": "trial_config", "TrialRecord": "trial_record", "open_world": "trials", "run_trial": "trials",
}  # fmt: skip

__all__ = [
    "AgentClassError",
    "CellError",
    "LabError",
    "ObservedRobot",
    "PeakWristForce",
    "RealCell",
    "RunStoreError",
    "SensedDigest",
    "TrialConfig",
    "TrialConfigError",
    "TrialContext",
    "TrialObserver",
    "TrialRecord",
    "TwinCell",
    "open_world",
    "run_trial",
]


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'puzzlebox.lab' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"puzzlebox.lab.{module}"), name)
    globals()[name] = value  # imported once
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
