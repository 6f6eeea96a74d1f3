"""A calibration file carries its cell: a trial takes the cell seed from it (``calibrate.py --cell-seed 3`` makes
a file ``trial.py`` then runs with), and still refuses a calibration of another profile or box."""

from __future__ import annotations

import pytest

from puzzlebox.lab.cells import profile_of_calibration
from puzzlebox.models.calibration import CalibrationError, CellCalibration
from puzzlebox.twin.reality import load_profile


def _calibration(profile: str, cell_seed: int) -> CellCalibration:
    return CellCalibration(cameras={}, cell={"profile": profile, "cell_seed": cell_seed, "box_height": 0.08})


def test_a_trial_takes_the_cell_seed_from_its_calibration():
    realistic = load_profile("realistic")
    calibration = _calibration("realistic", 3)
    profile = profile_of_calibration(realistic, calibration)
    assert profile.cell_seed == 3 and profile.name == "realistic"
    calibration.check_cell(profile.name, profile.cell_seed, 0.08)  # the cell it was made in: accepted
    assert profile_of_calibration(realistic, None) is realistic


def test_a_calibration_of_another_profile_or_box_is_still_refused():
    harsh = load_profile("harsh")
    calibration = _calibration("realistic", 3)
    profile = profile_of_calibration(harsh, calibration)
    assert profile == harsh
    with pytest.raises(CalibrationError, match="profile 'realistic' instead of 'harsh'"):
        calibration.check_cell(profile.name, profile.cell_seed, 0.08)
    with pytest.raises(CalibrationError, match="box height"):
        calibration.check_cell("realistic", 3, 0.12)
