"""Exceptions of the `skills` package; all derive from :class:`SkillError`."""

from __future__ import annotations

from collections.abc import Iterable

from puzzlebox.models.try_outcome import Cause


class SkillError(Exception):
    """Base class of every error raised on purpose by the `skills` package."""


class ConfigError(SkillError, ValueError):
    """A setting of the skills out of its range, or one that does not exist (the message says which)."""


class MarkersNotFound(SkillError):
    """Markers the cell expects were not seen (or seen twice) from any camera: no pose is invented."""

    def __init__(self, missing: Iterable[int], duplicated: Iterable[int] = (), cameras: Iterable[str] = ()) -> None:
        self.missing = tuple(sorted(missing))
        self.duplicated = tuple(sorted(duplicated))
        self.cameras = tuple(cameras)
        parts = []
        if self.missing:
            parts.append(f"missing marker ids {list(self.missing)}")
        if self.duplicated:
            parts.append(f"marker ids seen more than once {list(self.duplicated)}")
        super().__init__(f"{' and '.join(parts)} after looking from {list(self.cameras)}")


class UnknownMarker(SkillError, KeyError):
    """A marker id the marker map does not list."""

    def __str__(self) -> str:
        return str(self.args[0])


class IKFailure(SkillError):
    """Inverse kinematics could not reach a target (out of reach, or stalled at a joint limit)."""

    cause = Cause.UNREACHABLE


class GraspFailure(SkillError):
    """The gripper closed on nothing."""

    cause = Cause.GRASP_EMPTY


class CalibrationFailed(SkillError):
    """A calibration step could not produce a trustworthy result (too few usable views, no board seen)."""


class TooFewViews(CalibrationFailed):
    """Fewer usable board views than a calibration step needs; the message says how many of which."""


class BoardNotFound(CalibrationFailed):
    """The calibration board was not seen (or too few of its corners) in an image that needs it."""


class InconsistentViews(CalibrationFailed, ValueError):
    """Calibration inputs that do not go together: images of one camera in different sizes, an image that
    is not ``(H, W)`` or ``(H, W, 3)``, not one arm pose per image."""


class ForceLimitExceeded(SkillError):
    """The wrist force passed the safety limit during a motion: the motion was stopped.

    Attributes:
        force: the filtered force magnitude that passed the limit [N].
        limit: the limit it passed [N].
        phase: what the primitive was doing (``models.toggle_log.PHASES``).
    """

    cause = Cause.FORCE_LIMIT

    def __init__(self, force: float, limit: float, phase: str) -> None:
        self.force, self.limit, self.phase = force, limit, phase
        super().__init__(f"force limit: {force:.0f} N > {limit:.0f} N while {phase}, motion stopped")

    def __reduce__(self):  # type: ignore[override]  # (pickled across worker processes)
        return type(self), (self.force, self.limit, self.phase)


class SlipDetected(SkillError):
    """The handle left the grasp during the motion (the gripper closed past the handle's width)."""

    cause = Cause.SLIPPED
