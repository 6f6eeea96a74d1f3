"""The skills take a cell's cameras and force thresholds from its cell config: configured from the twin's own
config they are exactly today's, and a cell with other names is looked at through those names."""

from __future__ import annotations

import pytest

from puzzlebox.models.cell_config import CellConfig
from puzzlebox.models.generator import paper_family
from puzzlebox.skills.primitives import PrimitiveConfig
from puzzlebox.skills.scene_survey import SceneSurvey, SurveyConfig
from puzzlebox.twin.cell_config import twin_cell_config
from puzzlebox.twin.session import TwinSession


@pytest.fixture(scope="module")
def twin_cell():
    defaults = PrimitiveConfig()
    with TwinSession(paper_family("test")[0], seed=0) as session:
        return twin_cell_config(session, force_limit=defaults.force_limit, blocked_force=defaults.blocked_force)


def test_the_twins_cell_config_gives_the_skills_their_defaults(twin_cell):
    assert PrimitiveConfig.for_cell(twin_cell) == PrimitiveConfig()
    assert SurveyConfig.for_cell(twin_cell) == SurveyConfig()


def test_another_cells_thresholds_and_cameras_are_the_ones_used(twin_cell):
    data = {**twin_cell.to_dict(), "camera_names": ["top", "hand"], "overview_camera": "top", "wrist_camera": "hand",
            "force_limit": 45.0, "blocked_force": 15.0}  # fmt: skip
    cell = CellConfig.from_dict(data)
    primitives = PrimitiveConfig.for_cell(cell, rest_time=2.0)
    assert (primitives.force_limit, primitives.blocked_force, primitives.rest_time) == (45.0, 15.0, 2.0)

    asked: list[str] = []

    class Robot:  # gives no frame, recording which cameras are asked for
        def capture(self, camera):
            asked.append(camera)

        def wait(self, seconds):
            pass

    class Calibration:  # any camera, fixed in the cell
        def camera(self, name):
            return type("Camera", (), {"on_arm": False})()

    survey = SceneSurvey(Robot(), Calibration(), None, None, SurveyConfig.for_cell(cell))
    assert survey.overview() == [] and set(asked) == {"top"}
