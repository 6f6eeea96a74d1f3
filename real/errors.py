"""Exceptions of the ``real`` package (drivers of a real cell): one base, typed subclasses."""

from __future__ import annotations


class RealError(Exception):
    """Base class of every error raised on purpose by ``real``."""


class ArmUnreachable(RealError):
    """No xArm controller answers at the address given."""


class SDKMissing(RealError):
    """``xarm-python-sdk`` is not installed (``pip install puzzlebox[real]``)."""


class SDKCallFailed(RealError):
    """An SDK call returned a non-zero code (see UFACTORY's API code documentation)."""


class CommandRefused(RealError):
    """A command the driver refuses before it reaches the arm (non-finite, out of range, after a stop)."""


class ArmStopped(RealError):
    """The driver stopped the arm (``emergency_stop``) for a safety limit; every later command is refused."""


class ForceLimitExceeded(ArmStopped):
    """The wrist force passed the cell's limit; the arm was stopped."""


class WorkspaceExceeded(ArmStopped):
    """The TCP left the cell's workspace box; the arm was stopped."""


class UnknownCamera(RealError, KeyError):
    """A camera the cell does not have."""

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


__all__ = [
    "ArmStopped",
    "ArmUnreachable",
    "CommandRefused",
    "ForceLimitExceeded",
    "RealError",
    "SDKCallFailed",
    "SDKMissing",
    "UnknownCamera",
    "WorkspaceExceeded",
]
