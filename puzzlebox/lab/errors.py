"""Errors of the composition layer: one base, typed subclasses; each message names what was wrong and what exists."""

from __future__ import annotations

__all__ = [
    "AgentClassError",
    "ArmTrialFailed",
    "ArmTrialRefused",
    "BoxBuildError",
    "DatasetError",
    "ExperimentFailed",
    "ExperimentSettingsError",
    "ExperimentStepFailed",
    "LabError",
    "ManipulationEnvError",
    "NotABoxSpec",
    "OutputFileError",
    "OutputHoldsAnotherConfig",
    "OutputHoldsResults",
    "OutputInUse",
    "OutputNotADirectory",
    "OutputNotWritable",
    "ResumeAndForce",
    "RunStoreError",
    "SpecFileError",
    "SpecFilesInvalid",
    "TrainingError",
    "TrainingSetupError",
    "TrialConfigError",
]


class LabError(Exception):
    """Base of the composition layer's errors."""


class TrialConfigError(LabError, ValueError):
    """A trial configuration that cannot run (the message lists every problem)."""


class AgentClassError(LabError, ValueError):
    """A ``package.module:Class`` agent that cannot be loaded or does not satisfy the ``Agent`` protocol."""


class RunStoreError(LabError):
    """A results directory that cannot be taken up as asked."""


class ResumeAndForce(RunStoreError, ValueError):
    """Both resume (continue a directory) and force (empty it) were asked."""


class OutputNotADirectory(RunStoreError, NotADirectoryError):
    """The output path is a file."""


class OutputHoldsResults(RunStoreError, FileExistsError):
    """The output directory holds results and neither resume nor force was asked."""


class OutputHoldsAnotherConfig(RunStoreError, ValueError):
    """Resume was asked of a directory made with another configuration."""


class OutputNotWritable(RunStoreError, PermissionError):
    """The output directory cannot be written."""


class OutputInUse(RunStoreError, BlockingIOError):
    """Another process holds the output (its lock): the message names its pid and command."""


class SpecFileError(LabError, ValueError):
    """A spec file that cannot be read or is not a valid spec (the message names the file and the problem)."""


class NotABoxSpec(SpecFileError):
    """A valid spec with no box (a disassembly scene) where only a puzzle box will do."""


class SpecFilesInvalid(SpecFileError):
    """Some of several spec files cannot be used: :attr:`problems` holds one line per file, in order."""

    def __init__(self, problems: list[str]) -> None:
        super().__init__("\n".join(problems))
        self.problems = problems


class BoxBuildError(LabError):
    """A box whose MuJoCo model cannot be built (an unknown kind, a pose out of the robot's reach)."""


class DatasetError(LabError, ValueError):
    """A dataset of specs that cannot be made as asked: a count below 1, an output that is a file, a spec that
    fails, a runner that cannot start."""


class ExperimentSettingsError(LabError, ValueError):
    """Settings of an experiment that do not go together or are out of range (the message names the flag)."""


class ExperimentFailed(LabError):
    """An experiment the learning layer refused or could not finish (its message unchanged)."""


class ExperimentStepFailed(ExperimentFailed):
    """A command an experiment ran in a process of its own failed; it said why on stderr itself, and
    :attr:`returncode` is its exit code."""

    def __init__(self, command: str, returncode: int) -> None:
        super().__init__(f"{command} exited with {returncode}")
        self.returncode = returncode


class TrainingError(LabError):
    """A training run that cannot start as asked."""


class TrainingSetupError(TrainingError, ValueError):
    """Training settings that do not go together, or specs, a reality profile or a calibration that cannot be
    used (the message names the flag)."""


class OutputFileError(LabError):
    """An output file that cannot be written (a directory, a read-only place); found before any work is done."""


class ArmTrialRefused(LabError, ValueError):
    """A trial on a real arm that cannot run as asked (a flag, the cell config, the calibration, the agent)."""


class ArmTrialFailed(LabError, RuntimeError):
    """The arm refused or failed a call mid-trial (what was done is kept)."""


class ManipulationEnvError(LabError, ValueError):
    """``puzzlebox/BoxManipulation-v0`` asked for what it does not offer (an observation or reward mode, a reality
    profile, a box, an action): the message names the argument, what was given and the valid choices."""
