"""The command's pace along a motion: slow over the start, then a ramp with no jump in speed, then the full pace."""

import numpy as np

from puzzlebox.skills.pacing import Pacing


def test_the_pace_rises_without_a_jump_and_every_span_is_reached_when_said():
    pacing = Pacing(pace=0.004, slow_pace=0.0016, slow_span=0.3, ramp=30)
    ks = np.arange(0, 600)
    covered = np.array([pacing.at(k) for k in ks])
    speeds = np.diff(covered)
    assert np.all(speeds > 0) and speeds[0] == np.float64(0.0016)
    assert np.abs(np.diff(speeds)).max() <= (0.004 - 0.0016) / 30 + 1e-12  # no step: at most one ramp increment
    assert speeds[-1] == np.float64(0.004) or abs(speeds[-1] - 0.004) < 1e-12
    for span in (0.1, 0.3, 0.31, 0.35, 1.0, 1.3):
        k = pacing.ticks_to(span)
        assert pacing.at(k) >= span - 1e-12 > pacing.at(k - 1)


def test_without_a_slow_span_the_motion_runs_at_its_pace():
    pacing = Pacing(pace=0.01, slow_pace=0.004, slow_span=0.0)
    assert pacing.at(50) == 0.5 and pacing.ticks_to(1.0) == 100
