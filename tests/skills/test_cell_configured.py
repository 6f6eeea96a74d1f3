"""The skills take a cell's cameras and force thresholds from its cell config: configured from the twin's own
config they are exactly today's, and a cell with other names is looked at through those names."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.models.cell_config import CellConfig
from puzzlebox.models.generator import generate_chain, paper_family
from puzzlebox.skills.primitives import PrimitiveConfig
from puzzlebox.skills.robot_world import RobotWorld, WorldConfig
from puzzlebox.skills.scene_survey import SceneSurvey, SurveyConfig
from puzzlebox.twin.cell_config import twin_cell_config
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.session import TwinSession


@pytest.fixture(scope="module")
def twin_cell():
    defaults = PrimitiveConfig()
    with TwinSession(paper_family("test")[0], seed=0) as session:
        return twin_cell_config(
            session, force_limit=defaults.sensing.force_limit, blocked_force=defaults.judgement.blocked_force
        )


def test_skills_configured_from_the_twins_cell_config_see_and_feel_the_twin_exactly_as_todays():
    """A world whose survey and primitives come from the twin's cell config (as a real cell's come from its file)
    finds every marker through the cell's overview camera, reads the latched door blocked and the free slide moved,
    and does so step for step as the world with today's default configs: same outcomes, forces, times and arm."""
    spec = generate_chain(["slide", "door"], seed=2)  # the slide holds the door closed
    defaults = PrimitiveConfig()
    runs = {}
    for configured in (True, False):
        with TwinSession(spec, seed=0) as session:
            cell = twin_cell_config(
                session, force_limit=defaults.sensing.force_limit, blocked_force=defaults.judgement.blocked_force
            )
            config = WorldConfig(survey=SurveyConfig.for_cell(cell), primitives=PrimitiveConfig.for_cell(cell))
            world = RobotWorld(
                session.robot, nominal_calibration(session), {c.marker: c.kind for c in spec.components},
                spec.components[1].marker, config=config if configured else WorldConfig(),
            )  # fmt: skip
            assert world.seen_by_overview == {c.marker for c in spec.components}
            slide, door = (world.markers.index(c.marker) for c in spec.components)
            outcomes = [world.try_toggle(door).outcome, world.try_toggle(slide).outcome]
            assert outcomes == ["blocked", "moved"] and session.component_states().tolist() == [1, 0]
            log = [(a.outcome, a.peak_force, a.progress, a.sim_time) for a in world.log]
            runs[configured] = (log, session.robot.joint_positions(), session.time)
    log, arm, sim_time = runs[True]
    assert log == runs[False][0] and sim_time == runs[False][2]
    np.testing.assert_array_equal(arm, runs[False][1])


def test_another_cells_thresholds_and_cameras_are_the_ones_used(twin_cell):
    data = {**twin_cell.to_dict(), "camera_names": ["top", "hand"], "overview_camera": "top", "wrist_camera": "hand",
            "force_limit": 45.0, "blocked_force": 15.0}  # fmt: skip
    cell = CellConfig.from_dict(data)
    primitives = PrimitiveConfig.for_cell(cell, rest_time=2.0)
    assert (primitives.sensing.force_limit, primitives.judgement.blocked_force, primitives.retreat.rest_time) == (
        45.0,
        15.0,
        2.0,
    )

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
