"""A ``RobotWorld`` over a twin session exactly as a twin trial wires it (``puzzlebox.lab.twin_trial``: nominal
calibration, the spec's goal, ground truth for scoring only), and the session's robot watched for its peak true
wrist force, shared by the skills tests."""

from __future__ import annotations

from puzzlebox.lab.observers import ObservedRobot, PeakWristForce
from puzzlebox.lab.twin_trial import evaluation_world
from puzzlebox.skills.robot_world import RobotWorld
from puzzlebox.twin.session import TwinSession

__all__ = ["TrueForceWatch", "twin_world"]


def twin_world(session: TwinSession, seed: int = 0) -> RobotWorld:
    return evaluation_world(session, seed=seed)


class TrueForceWatch(ObservedRobot):
    """``robot`` (a ``Robot``) watched by a :class:`~puzzlebox.lab.observers.PeakWristForce` on ``session``:
    :attr:`peak` is the largest true external wrist force since it was last set [N]."""

    def __init__(self, robot, session: TwinSession) -> None:
        self._session = session
        self._watch = PeakWristForce(session)
        super().__init__(robot, [self._watch])

    @property
    def peak(self) -> float:
        return self._watch.peak

    @peak.setter
    def peak(self, value: float) -> None:
        self._watch.peak = value

    @property
    def peak_during(self) -> str:
        return self._watch.peak_during
