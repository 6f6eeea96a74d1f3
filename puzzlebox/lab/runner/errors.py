"""Errors of the task runner. Each is a :class:`~puzzlebox.learning.errors.LearningError`, as it was before the
runner moved out of ``learning/`` (issue 34): the callers that map a failed run to one line catch that."""

from __future__ import annotations

from puzzlebox.learning.errors import LearningError


class RunnerError(LearningError, ValueError):
    """A task list the runner cannot execute (duplicate keys, a key that is not a file name, settings that
    are not JSON, a function that cannot be pickled by reference) or an executor that cannot start."""
