"""The cell's nominal calibration: what the datasheets and the CAD model say of its cameras.

The overview camera's ``K`` from its field of view and the image size, zero distortion, its designed
``T_base_camera``; the wrist camera's ``K`` and designed ``T_tcp_camera`` (its pose in the TCP frame,
OpenCV camera frame). It comes from the session's *nominal* model, so it ignores the reality profile:
under ``ideal`` it is exactly the truth (:meth:`TwinSession.camera_truth`); under another profile it
is the starting point a calibration procedure improves on.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import mujoco
import numpy as np

from models.calibration import CameraCalibration, CellCalibration
from twin.rendering import pinhole_intrinsics
from twin.sensors.cameras import MUJOCO_TO_OPENCV

if TYPE_CHECKING:
    from twin.session import TwinSession


def _pose(pos: np.ndarray, xmat: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = xmat.reshape(3, 3)
    T[:3, 3] = pos
    return T


def nominal_calibration(session: TwinSession) -> CellCalibration:
    """The nominal (datasheet / CAD) calibration of ``session``'s cell (see the module docstring)."""
    model = session.nominal_model
    names = session.scene.names
    data = mujoco.MjData(model)
    data.qpos[session.arm_qpos] = session.config.home_qpos
    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)  # camera poses are not part of mj_kinematics
    width, height = session.config.render.width, session.config.render.height
    tcp = model.site(names.tcp_site).id
    T_base_tcp = _pose(data.site_xpos[tcp], data.site_xmat[tcp])
    cameras = {}
    for name in (names.overview_camera, names.wrist_camera):
        cam = model.camera(name).id
        K = pinhole_intrinsics(model, cam, width, height)
        T_base_camera = _pose(data.cam_xpos[cam], data.cam_xmat[cam].reshape(3, 3) @ MUJOCO_TO_OPENCV)
        extra = {"source": "nominal model"}
        if model.cam_bodyid[cam] == 0:
            cameras[name] = CameraCalibration(K, np.zeros(5), (width, height), T_base_camera=T_base_camera, extra=extra)
        else:
            T_tcp_camera = np.linalg.solve(T_base_tcp, T_base_camera)
            cameras[name] = CameraCalibration(K, np.zeros(5), (width, height), T_tcp_camera=T_tcp_camera, extra=extra)
    return CellCalibration(cameras, source="nominal (datasheet / CAD model)")


__all__ = ["nominal_calibration"]
