"""Exceptions of the `learning` package; all derive from :class:`LearningError`."""

from __future__ import annotations


class LearningError(Exception):
    """Base class of every error raised on purpose by the `learning` package."""


class InvalidAction(LearningError, ValueError):
    """An action outside ``0..N-1`` (the message gives the valid range)."""


class AgentError(LearningError):
    """An agent broke the trial loop's seam: it chose something that is not one of the observation's parts, or it
    raised (``SystemExit`` included). The message names the agent; the tries before it stand."""


class UnknownAgent(LearningError, KeyError):
    """An agent name no factory knows; the message lists the known agents."""

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


class ConfigError(LearningError, ValueError):
    """A configuration value out of its documented range."""


class MemoryFileError(LearningError):
    """A memory file that cannot be used: missing, truncated, corrupted, foreign or of another schema."""
