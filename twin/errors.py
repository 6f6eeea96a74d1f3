"""Exceptions of the `twin` package.

Every error raised on purpose by `twin` derives from :class:`TwinError`, so callers can catch the whole
family at once; each message names what was wrong and what exists instead.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "CommandError",
    "ProfileError",
    "RenderingError",
    "SimulationDiverged",
    "TwinError",
    "UnknownCamera",
    "VideoError",
]


class TwinError(Exception):
    """Base class of every error raised by the `twin` package."""


class RenderingError(TwinError):
    """Offscreen rendering is impossible: no OpenGL context, a closed renderer, a camera that cannot be used."""


class UnknownCamera(TwinError, KeyError):
    """A camera name that the model does not have."""

    def __init__(self, camera: str, available: Iterable[str]) -> None:
        self.camera = camera
        self.available = tuple(sorted(available))
        super().__init__(f"unknown camera {camera!r}. Available camera names: {list(self.available)}")

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


class VideoError(TwinError):
    """A video cannot be written: a frame of the wrong shape or type, or a closed writer."""


class SimulationDiverged(TwinError):
    """MuJoCo flagged an unstable simulation (autoreset is disabled: the state is never reset silently)."""


class CommandError(TwinError, ValueError):
    """A robot command that cannot be sent: wrong length, not finite, or outside the actuator's range."""


class ProfileError(TwinError, ValueError):
    """A reality profile that cannot be used: an unknown preset or key, or a value out of its range
    (a negative noise, a probability outside [0, 1]); the message names the key and the known ones."""
