"""Errors of the task runner."""

from __future__ import annotations

from puzzlebox.learning.errors import LearningError


class RunnerError(LearningError, ValueError):
    """A task list the runner cannot execute (duplicate keys, a key that is not a file name, settings that
    are not JSON, a function that cannot be pickled by reference) or an executor that cannot start."""
