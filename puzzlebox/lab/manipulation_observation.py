"""What ``puzzlebox/BoxManipulation-v0`` observes: the robot as its sensors give it, plus by ``obs_mode`` the parts'
joints (privileged) or small camera images.

A ``gymnasium.spaces.Dict``; every vector float32, base frame, SI units:

- ``joint_pos`` (7,) the arm's joints as the encoders read them [rad]; ``joint_vel`` (7,) [rad/s];
- ``tcp_pose`` (9,) the TCP the arm's own kinematics report: position [m], then the first two columns of its
  rotation matrix (continuous, unlike a quaternion of a gripper pointing down);
- ``gripper`` (1,) how closed the gripper is, 0 (open) .. 1 (closed);
- ``wrench`` (6,) the wrist F/T reading ``[Fx, Fy, Fz, Tx, Ty, Tz]`` in the sensor frame [N, N·m], tared at reset,
  with the reality profile's noise, bias drift, delay and quantisation;
- ``obs_mode="state"`` adds the simulator's truth: ``part_pos`` (N,) each part's joint position [m or rad], 0 closed
  .. its travel open, and ``handle_pos`` (N, 3) the grasp point on each handle [m] (12 mm under its top, where the
  skills pinch it);
- ``obs_mode="rgb"`` adds ``overview`` and ``wrist``, (S, S, 3) uint8 frames of the overview and wrist cameras as
  they deliver them (the profile's lens, noise and blur; a dropped frame repeats the last one).
"""

from __future__ import annotations

import numpy as np
from gymnasium import spaces

from puzzlebox.skills.joint_model import GRASP_DEPTH
from puzzlebox.twin.session import TwinSession

OBS_MODES = ("state", "rgb")
"""The observation modes."""


def _vector(bound: float | list[float], *shape: int) -> spaces.Box:
    high = np.broadcast_to(np.asarray(bound, dtype=np.float32), shape)
    return spaces.Box(-high, high, shape=shape, dtype=np.float32)


def observation_space(obs_mode: str, num_parts: int, image_size: int) -> spaces.Dict:
    """The observation space of a box of ``num_parts`` parts (see the module docstring). The bounds are loose
    physical ones (joints within +-7 rad, the TCP and handles within 2 m of the base, the wrench within 10 kN and
    1 kN·m): a reading passes them only on a crash, which the force limit ends."""
    items: dict[str, spaces.Space] = {
        "joint_pos": _vector(7.0, 7),
        "joint_vel": _vector(100.0, 7),
        "tcp_pose": _vector([2.0] * 3 + [1.0] * 6, 9),
        "gripper": spaces.Box(0.0, 1.0, shape=(1,), dtype=np.float32),
        "wrench": _vector([1e4] * 3 + [1e3] * 3, 6),
    }
    if obs_mode == "state":
        items |= {"part_pos": _vector(7.0, num_parts), "handle_pos": _vector(2.0, num_parts, 3)}
    else:
        image = spaces.Box(0, 255, shape=(image_size, image_size, 3), dtype=np.uint8)
        items |= {"overview": image, "wrist": image}
    return spaces.Dict(items)


class Observer:
    """Reads one session's observations (see the module docstring); the wrench read is kept in :attr:`wrench`."""

    def __init__(self, session: TwinSession, obs_mode: str) -> None:
        self.session, self.obs_mode = session, obs_mode
        self.robot = session.robot
        m = session.model
        names = session.scene.names
        self._handles = np.array([m.site(names.components[c.name].handle_site).id for c in session.spec.components])
        self._cameras = {"overview": names.overview_camera, "wrist": names.wrist_camera}
        self._frames: dict[str, np.ndarray] = {}
        self.wrench = np.zeros(6)
        """The last wrench read [N, N·m] (the force limit checks it)."""
        self.tcp = np.eye(4)
        """The last TCP pose the arm reported (4x4, [m]): the controller's start."""
        self._grasp: np.ndarray | None = None

    def grasp_points(self) -> np.ndarray:
        """``(N, 3)`` the grasp point of every handle at the last observation [m], base frame: ground truth."""
        if self._grasp is None:
            d = self.session.data
            axes = d.site_xmat[self._handles][:, 2::3]  # each site's z axis: the third column of its row-major frame
            self._grasp = d.site_xpos[self._handles] - GRASP_DEPTH * axes
        return self._grasp

    def observe(self) -> dict[str, np.ndarray]:
        """The observation now; its vectors are views of one new float32 array (one conversion, not one each)."""
        r = self.robot
        self._grasp = None
        self.tcp = T = r.tcp_pose_in_base()
        self.wrench = r.wrench()
        parts = [r.joint_positions(), r.joint_velocities(), T[:3, 3], T[:3, 0], T[:3, 1], [r.gripper_opening()],
                 self.wrench]  # fmt: skip
        state = self.obs_mode == "state"
        if state:
            parts += [self.session.data.qpos[self.session.component_qpos], self.grasp_points().ravel()]
        flat = np.concatenate(parts, dtype=np.float32)
        obs = {"joint_pos": flat[:7], "joint_vel": flat[7:14], "tcp_pose": flat[14:23], "gripper": flat[23:24],
               "wrench": flat[24:30]}  # fmt: skip
        if state:
            n = len(self._handles)
            obs["part_pos"], obs["handle_pos"] = flat[30 : 30 + n], flat[30 + n :].reshape(n, 3)
        else:
            for key, camera in self._cameras.items():
                image = r.capture(camera)
                if image is not None:
                    self._frames[key] = image.rgb
                elif key not in self._frames:  # dropped at reset: nothing seen yet
                    size = self.session.config.render
                    self._frames[key] = np.zeros((size.height, size.width, 3), dtype=np.uint8)
                obs[key] = self._frames[key].copy()
        return obs


__all__ = ["OBS_MODES", "Observer", "observation_space"]
