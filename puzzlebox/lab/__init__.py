"""The composition layer: the one package that imports the twin, the skills, the learning layer and the real arm
together, to run trials (:func:`run_trial`, :func:`open_world`), sweeps, datasets, calibrations, reports and the
twin experiments (DESIGN.md, "Layers")."""

from puzzlebox.lab.cells import CellError, RealCell, TwinCell
from puzzlebox.lab.errors import AgentClassError, LabError, RunStoreError, TrialConfigError
from puzzlebox.lab.observers import ObservedRobot, PeakWristForce, SensedDigest, TrialContext, TrialObserver
from puzzlebox.lab.trial_config import TrialConfig
from puzzlebox.lab.trial_record import TrialRecord
from puzzlebox.lab.trials import open_world, run_trial

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
