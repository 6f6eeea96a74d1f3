"""The cell's nominal calibration: what the datasheets and the CAD model say of its cameras.

The overview camera's ``K`` from its field of view and the image size, zero distortion, its designed
``T_base_camera``; the wrist camera's ``K`` and designed ``T_tcp_camera`` (its pose in the TCP frame,
OpenCV camera frame). It comes from the session's *nominal* model, so it ignores the reality profile:
under ``ideal`` it is exactly the truth (:meth:`TwinSession.camera_truth`); under another profile it
is the starting point a calibration procedure improves on. Both are made by :func:`camera_calibration`.
"""

from __future__ import annotations

from typing import Any, Protocol

import mujoco
import numpy as np

from puzzlebox.models.calibration import CameraCalibration, CellCalibration
from puzzlebox.models.scene import Scene
from puzzlebox.twin.rendering import RenderConfig, camera_pose_in_world, pinhole_intrinsics
from puzzlebox.twin.sensors.encoders import JointEncoders


class NominalCellConfig(Protocol):
    """What the nominal calibration reads of a cell's configuration."""

    @property
    def home_qpos(self) -> tuple[float, ...] | np.ndarray: ...
    @property
    def render(self) -> RenderConfig: ...


class NominalCell(Protocol):
    """The parts of a cell the nominal calibration reads (a :class:`~puzzlebox.twin.session.TwinSession` has
    them): its nominal model, scene names, the arm's qpos indices, home pose and image size, its encoders'
    nominal kinematics."""

    nominal_model: mujoco.MjModel
    scene: Scene
    arm_qpos: np.ndarray
    encoders: JointEncoders

    @property
    def config(self) -> NominalCellConfig: ...


def camera_calibration(
    model: mujoco.MjModel,
    qpos: np.ndarray,
    cam: int,
    K: np.ndarray,
    dist: np.ndarray,
    size: tuple[int, int],
    T_base_tcp: np.ndarray,
    extra: dict[str, Any],
) -> CameraCalibration:
    """Calibration of camera ``cam`` of ``model`` in the configuration ``qpos`` (all of the model's), with
    intrinsics ``K`` [px] and distortion ``dist`` for images of ``size`` ``(W, H)`` [px]: a camera fixed in
    the world gets its ``T_base_camera``, one carried by the arm its ``T_tcp_camera`` relative to
    ``T_base_tcp`` (the TCP as the arm's kinematics report it) [m]."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)  # camera poses are not part of mj_kinematics
    T_base_camera = camera_pose_in_world(data, cam)
    K, dist = np.array(K, dtype=float), np.array(dist, dtype=float)
    if model.cam_bodyid[cam] == 0:
        return CameraCalibration(K, dist, size, T_base_camera=T_base_camera, extra=extra)
    T_tcp_camera = np.linalg.solve(T_base_tcp, T_base_camera)
    return CameraCalibration(K, dist, size, T_tcp_camera=T_tcp_camera, extra=extra)


def nominal_calibration(session: NominalCell) -> CellCalibration:
    """The nominal (datasheet / CAD) calibration of ``session``'s cell (see the module docstring)."""
    model = session.nominal_model
    names = session.scene.names
    qpos = model.qpos0.copy()
    qpos[session.arm_qpos] = session.config.home_qpos
    size = (session.config.render.width, session.config.render.height)
    T_base_tcp = session.encoders.nominal_tcp_pose(np.asarray(session.config.home_qpos, dtype=float))
    cameras = {}
    for name in (names.overview_camera, names.wrist_camera):
        cam = model.camera(name).id
        K = pinhole_intrinsics(model, cam, *size)
        cameras[name] = camera_calibration(
            model, qpos, cam, K, np.zeros(5), size, T_base_tcp, extra={"source": "nominal model"}
        )
    return CellCalibration(cameras, source="nominal (datasheet / CAD model)")


__all__ = ["NominalCell", "camera_calibration", "nominal_calibration"]
