"""Errors of the composition layer: one base, typed subclasses; each message names what was wrong and what exists."""

from __future__ import annotations

__all__ = [
    "AgentClassError",
    "LabError",
    "OutputHoldsAnotherConfig",
    "OutputHoldsResults",
    "OutputNotADirectory",
    "OutputNotWritable",
    "ResumeAndForce",
    "RunStoreError",
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
