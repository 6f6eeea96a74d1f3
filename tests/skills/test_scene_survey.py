"""The survey's viewpoints: one out of the arm's reach is left alone, so the arm never winds itself into a fold."""

from __future__ import annotations

import math

import numpy as np

from puzzlebox.lab import twin_trial
from puzzlebox.lab.hard_sets import hard_box
from puzzlebox.lab.observers import ObservedRobot, PeakWristForce
from puzzlebox.lab.trial_config import TrialConfig
from puzzlebox.skills.errors import IKFailure
from puzzlebox.skills.scene_survey import SceneSurvey


class _Camera:
    on_arm = True
    T_tcp_camera = np.eye(4)


class _Calibration:
    def camera(self, name):
        return _Camera()


class _Toggler:
    """Records where it was sent; raises as the real one does for a target it cannot reach."""

    rest_posture = np.array([0.0, -0.247, 0.0, 0.909, 0.0, 1.156, 0.0])

    def __init__(self):
        self.sent: list[np.ndarray] = []

    def travel_to(self, target, duration):
        self.sent.append(target[:3, 3].copy())
        if np.hypot(*target[:2, 3]) > 0.7:
            raise IKFailure("out of reach")


def test_a_viewpoint_out_of_reach_is_not_travelled_to_and_one_in_reach_is():
    toggler = _Toggler()
    survey = SceneSurvey(None, _Calibration(), toggler)
    assert not survey._wrist_from_above(np.array([0.85, -0.2, 0.08]), 0.4)
    assert toggler.sent == [], "no yaw of a viewpoint 0.87 m out reaches it: the arm must not set out"
    assert survey._wrist_from_above(np.array([0.45, 0.1, 0.08]), 0.4)
    np.testing.assert_allclose(toggler.sent[0], (0.45, 0.1, 0.48))


def test_the_survey_of_a_box_whose_search_points_lie_out_of_reach_touches_nothing():
    """hard-chain8-s91002 at world seed 91101: the search round centred past the overview's view has six
    viewpoints beyond the arm's reach. Set out towards each, the arm was left stretched where the IK gave up and
    the wrist wound to its joint limit; the IK then folded the forearm onto the gripper (a finger pad on link 4 at
    388 N true) before the first action."""
    spec = hard_box("chain8", 91002)
    config = TrialConfig(sim="twin", agent="oracle", seed=91101, reality="realistic")
    with twin_trial.twin_session(spec, config) as session:
        peak = PeakWristForce(session)
        world = twin_trial.evaluation_world(session, ObservedRobot(session.robot, [peak]), None, 91101, {}, None)
        assert set(world.markers) == {c.marker for c in spec.components}
        assert peak.peak < 20.0, f"{peak.peak:.0f} N true while {peak.peak_during}"
        assert math.isfinite(peak.peak)
