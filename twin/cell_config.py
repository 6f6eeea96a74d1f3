"""The twin's own cell config (:class:`models.cell_config.CellConfig`), read off a session's actual constants.

The force thresholds are the skills' (``skills.settings.PrimitiveConfig``: ``sensing.force_limit`` and
``judgement.blocked_force``); ``twin`` may not import ``skills`` (DESIGN.md, "Layers"), so whoever wires the two
passes them in.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from puzzlebox.models.cell_config import CellConfig, aruco_dictionary_name
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.markers import ARUCO_DICTIONARY
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.robot_interface import GRIPPER_CTRL_MAX

if TYPE_CHECKING:
    from puzzlebox.twin.session import TwinSession


def twin_cell_config(session: TwinSession, *, force_limit: float, blocked_force: float) -> CellConfig:
    """The cell config of ``session``'s cell.

    Args:
        session: the twin session whose cell is described.
        force_limit: the skills' safety limit on the wrist force [N].
        blocked_force: the skills' force that, with little progress, means a latch [N].

    Where each value comes from: cameras from the session's scene names; the dictionary from
    :data:`models.markers.ARUCO_DICTIONARY`; the marker size from the kinds of the session's spec; the gripper
    range from the servo's command range (0 open .. :data:`twin.robot_interface.GRIPPER_CTRL_MAX` closed); the
    rest posture from :attr:`twin.session.TwinConfig.home_qpos`; the workspace from the scene's horizontal
    reach (a square around the base) between the table top (z = 0) and the overview camera; the F/T rate
    from the reality profile's sensor (a continuous sensor, rate 0, is read every physics step).
    """
    names = session.scene.names
    sizes = {get_kind(c.kind).marker_size for c in session.spec.components}
    if len(sizes) != 1:
        raise TwinError(f"the spec's components carry markers of several sizes {sorted(sizes)} [m]; a cell has one")
    reach = session.config.scene.max_reach
    camera_z = float(session.nominal_model.camera(names.overview_camera).pos[2])  # the arm stays below it
    rate = session.ft.config.rate_hz or 1.0 / session.timestep
    return CellConfig(
        name=f"twin-{session.reality.name}",
        camera_names=tuple(session.robot.camera_names),
        overview_camera=names.overview_camera,
        wrist_camera=names.wrist_camera,
        aruco_dictionary=aruco_dictionary_name(ARUCO_DICTIONARY),
        marker_size=sizes.pop(),
        force_limit=force_limit,
        blocked_force=blocked_force,
        gripper_open=0.0,
        gripper_closed=GRIPPER_CTRL_MAX,
        rest_posture=tuple(session.config.home_qpos),
        workspace_min=(-reach, -reach, 0.0),
        workspace_max=(reach, reach, camera_z),
        ft_rate_hz=float(rate),
    )


__all__ = ["twin_cell_config"]
