"""The calibration rig: what a person does in a real cell to calibrate its cameras, done in the twin.

A :class:`CalibrationCell` is the usual twin of a spec (:class:`~twin.session.TwinSession`) with the
ChArUco board of :mod:`models.charuco` added as a mocap body (``SceneConfig.calibration_board``). The
rig places the board where a person would hold or lay it (:meth:`CalibrationCell.place_board`), and
every image is taken through the session's robot interface (:meth:`CalibrationCell.capture`), so the
calibration sees whatever the twin does to images (a reality profile's intrinsic, distortion and
mounting errors, noise, dropped frames).

It also proposes the procedure's poses: board poses held in front of a fixed camera at varied
distances and tilts (:meth:`CalibrationCell.board_poses_in_front_of`), the known place where the board
lies flat for the fixed camera's pose and the hand-eye (:meth:`CalibrationCell.table_place`), and TCP
poses from which the wrist camera looks at it (:meth:`CalibrationCell.wrist_viewpoints`). These are
aimed with the cell's *nominal* calibration (:func:`twin.nominal_calibration.nominal_calibration`: the
datasheet intrinsics and the design drawing's camera poses), as a person aims them by eye, never with
the true cameras; the calibration itself never reads them. Moving the arm is the robot pipeline's job
(the skills' IK), so the script that runs the procedure does that.

:meth:`CalibrationCell.camera_truth` gives the cameras' true parameters
(:meth:`twin.session.TwinSession.camera_truth`), for evaluating a calibration in the twin only.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from puzzlebox.models.calibration import CameraCalibration
from puzzlebox.models.charuco import BOARD_BODY, DEFAULT_BOARD, CharucoBoardSpec, board_pose_flat
from puzzlebox.models.robot import CameraImage
from puzzlebox.models.spec import PuzzleSpec
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.nominal_calibration import nominal_calibration
from puzzlebox.twin.reality import RealityProfile, load_profile
from puzzlebox.twin.session import TwinConfig, TwinSession

__all__ = ["CalibrationCell", "RigConfig", "RigError"]


class RigError(TwinError):
    """The rig cannot do what was asked (no frame delivered, no board pose that fits in front of a camera)."""


@dataclass(frozen=True)
class RigConfig:
    """Where the rig puts the board and the arm."""

    board_distance: tuple[float, float] = (0.22, 0.40)
    """Range of the board's distance from a fixed camera while held in front of it [m]."""
    board_max_tilt: float = 40.0
    """Largest tilt of a held board away from facing the camera [deg] (Zhang's method needs tilts;
    beyond ~50 deg the far corners shrink below a few pixels per square)."""
    board_min_visible: float = 0.7
    """A held pose is kept only if this fraction of the corners projects into the nominal image [-]."""
    board_clearance: float = 0.03
    """A held board stays this far above the top of the box [m] (the rig's board is not solid)."""
    place_above_lid: float = 0.08
    """The known place: the board lies flat on a stand this far above the lid [m], under the fixed
    camera (the box occupies the table there; the stand clears its handles). The known place is a
    *surveyed fixture*: the fixed camera's pose is only as good as this number. Here the lid's height
    comes exactly from the spec's box height (``spec.box.size[2]``), so the place is known exactly; a
    real cell must measure the stand's height (and the board's position on it) instead."""
    place_yaw: float = 0.0
    """Yaw of the board at the known place [rad]."""
    wrist_distance: tuple[float, float] = (0.24, 0.34)
    """Range of the wrist camera's distance from the board centre [m]."""
    wrist_max_tilt: float = 30.0
    """Largest angle of the wrist camera's axis from the board's normal [deg]."""
    wrist_max_roll: float = 60.0
    """Largest turn of the gripper about the camera axis from its nominal top-down yaw [deg]."""
    wrist_aim_spread: float = 0.03
    """The wrist camera aims within this distance of the board centre [m]."""
    capture_attempts: int = 5
    """Captures tried before a camera that delivers no frame is an error."""


@dataclass
class CalibrationCell:
    """A twin cell with a ChArUco board the rig can place (see the module docstring).

    Args:
        spec: the puzzle box of the cell (the overview camera hangs at a height that depends on it).
        seed: the session's seed (per-trial randomness).
        reality: the reality profile: a profile, a preset name or a profile JSON file; None for ``ideal``.
        cell_seed: the seed of the cell's fixed imperfections (the profile's ``cell_seed``), None to keep
            the profile's.
        config: where the rig puts the board and the arm.
        twin_config: the session's settings (its scene gets the board).
    """

    spec: PuzzleSpec
    seed: int = 0
    reality: RealityProfile | str | Path | None = None
    cell_seed: int | None = None
    config: RigConfig = field(default_factory=RigConfig)
    twin_config: TwinConfig | None = None
    board: CharucoBoardSpec = field(init=False, default=DEFAULT_BOARD)

    def __post_init__(self) -> None:
        base = self.twin_config or TwinConfig()
        twin_config = dataclasses.replace(base, scene=dataclasses.replace(base.scene, calibration_board=True))
        profile = load_profile(self.reality)
        if self.cell_seed is not None:
            profile = dataclasses.replace(profile, cell_seed=self.cell_seed)
        self.session = TwinSession(self.spec, seed=self.seed, config=twin_config, reality=profile)
        self.model, self.data = self.session.model, self.session.data
        self._mocap = int(self.model.body(BOARD_BODY).mocapid[0])
        names = self.session.scene.names
        self.overview_camera, self.wrist_camera = names.overview_camera, names.wrist_camera
        # What the rig aims with, as a person aims by eye: the datasheet and the drawing, never the truth.
        self.nominal = nominal_calibration(self.session)

    # -- the session -------------------------------------------------------------------------------
    @property
    def robot(self):
        """The robot interface: the only way images and arm poses reach the calibration."""
        return self.session.robot

    @property
    def box_height(self) -> float:
        """Height of the box's lid above the table [m] (the spec's; the overview camera hangs 0.5 m above it)."""
        box = self.session.spec.box
        assert box is not None  # the twin builds puzzle boxes only (models.scene)
        return float(box.size[2])

    def close(self) -> None:
        self.session.close()

    def __enter__(self) -> CalibrationCell:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the board ---------------------------------------------------------------------------------
    def place_board(self, T_base_board: np.ndarray) -> None:
        """Put the board (its OpenCV board frame, :mod:`models.charuco`) at ``T_base_board`` [m]."""
        T = np.asarray(T_base_board, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise RigError(f"a board pose is a finite 4x4 matrix, got {T!r}")
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        self.data.mocap_pos[self._mocap] = T[:3, 3]
        self.data.mocap_quat[self._mocap] = (w, x, y, z)
        # The renderer reads body and camera poses; mj_kinematics alone leaves the cameras where they were.
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def capture(self, camera: str) -> CameraImage:
        """A frame of a camera through the robot interface, retried when the camera drops a frame."""
        for _ in range(self.config.capture_attempts):
            frame = self.robot.capture(camera)
            if frame is not None:
                return frame
            self.robot.wait(0.05)
        raise RigError(f"camera {camera!r} delivered no frame in {self.config.capture_attempts} attempts")

    # -- the procedure's poses ---------------------------------------------------------------------
    def _nominal_pose(self, camera: CameraCalibration) -> np.ndarray:
        """A camera's nominal pose now: a fixed camera's as drawn, an arm camera's composed with the TCP
        pose the arm reports."""
        return camera.pose_in_base(self.robot.tcp_pose_in_base() if camera.on_arm else None)

    def board_poses_in_front_of(self, camera: str, count: int, rng: np.random.Generator) -> list[np.ndarray]:
        """``count`` board poses ``T_base_board`` held in front of a camera (aimed with its nominal
        calibration): at varied distances, tilted up to :attr:`RigConfig.board_max_tilt` about varied
        axes, turned about the normal, spread over the image (mostly inside it), all above the box."""
        c = self.config
        nominal = self.nominal.camera(camera)
        T_base_camera = self._nominal_pose(nominal)
        K = nominal.K
        width, height = nominal.image_size
        corners = self.board.corners_in_board()
        outline = self.board.outline_in_board()
        lowest = self.box_height + 0.04 + c.board_clearance  # handles stand ~3-4 cm above the lid
        poses: list[np.ndarray] = []
        for _ in range(200 * count):
            if len(poses) == count:
                break
            distance = rng.uniform(*c.board_distance)
            centre = np.array(
                [
                    rng.uniform(-0.35, 0.35) * distance * (width / 2) / K[0, 0],
                    rng.uniform(-0.35, 0.35) * distance * (height / 2) / K[1, 1],
                    distance,
                ]
            )
            phi = rng.uniform(0.0, 2 * np.pi)
            tilt = np.radians(c.board_max_tilt) * math.sqrt(rng.uniform(0.15, 1.0))
            R = (
                Rotation.from_rotvec(tilt * np.array([math.cos(phi), math.sin(phi), 0.0]))
                * Rotation.from_rotvec([0.0, 0.0, rng.uniform(-np.pi, np.pi)])
            ).as_matrix()
            T_camera_board = np.eye(4)
            T_camera_board[:3, :3] = R
            T_camera_board[:3, 3] = centre - R @ self.board.center_in_board
            in_camera = corners @ R.T + T_camera_board[:3, 3]
            if np.any(in_camera[:, 2] < 0.05):
                continue
            pixels = in_camera[:, :2] / in_camera[:, 2:] * np.diag(K)[:2] + K[:2, 2]
            visible = np.mean(
                (pixels[:, 0] > 4) & (pixels[:, 0] < width - 5) & (pixels[:, 1] > 4) & (pixels[:, 1] < height - 5)
            )
            T_base_board = T_base_camera @ T_camera_board
            plate_z = (outline @ T_base_board[:3, :3].T + T_base_board[:3, 3])[:, 2]
            if visible >= c.board_min_visible and plate_z.min() > lowest:
                poses.append(T_base_board)
        if len(poses) < count:
            raise RigError(f"found only {len(poses)} of {count} board poses in front of {camera!r} above the box")
        return poses

    def table_place(self) -> np.ndarray:
        """The known place ``T_base_board``: flat, print up, on a stand :attr:`RigConfig.place_above_lid`
        above the lid, centred under the overview camera's nominal position.

        A surveyed fixture: its height here is exactly the spec's box height plus
        :attr:`RigConfig.place_above_lid`, so the fixed camera's pose is found against an exact place; a
        real cell must measure where the board lies (a calibrated stand, a survey), and the fixed
        camera's pose inherits that measurement's error."""
        x, y = self.session.config.scene.overview_xy
        z = self.box_height + self.config.place_above_lid
        return board_pose_flat(x, y, z, self.config.place_yaw, self.board)

    def wrist_viewpoints(self, T_base_board: np.ndarray, count: int, rng: np.random.Generator) -> list[np.ndarray]:
        """``count`` TCP poses ``T_base_tcp`` from which the wrist camera (at its nominal ``T_tcp_camera``)
        looks at the board lying at ``T_base_board``: from above, at varied distances, off the normal by
        up to :attr:`RigConfig.wrist_max_tilt`, turned about the camera axis by up to
        :attr:`RigConfig.wrist_max_roll` (hand-eye needs rotations about several axes)."""
        c = self.config
        T_tcp_camera = self.nominal.camera(self.wrist_camera).T_tcp_camera
        assert T_tcp_camera is not None  # the wrist camera is on the arm
        centre = T_base_board[:3, :3] @ self.board.center_in_board + T_base_board[:3, 3]
        up = -T_base_board[:3, 2]  # the board's z goes into the board
        # Nominal: the gripper straight down, its x along the base x (skills.kinematics.top_down(p, 0)).
        R_down = np.diag([1.0, -1.0, -1.0])
        poses = []
        for _ in range(count):
            phi = rng.uniform(0.0, 2 * np.pi)
            tilt = np.radians(c.wrist_max_tilt) * math.sqrt(rng.uniform(0.0, 1.0))
            direction = Rotation.from_rotvec(tilt * np.array([math.cos(phi), math.sin(phi), 0.0])).apply(up)
            camera_position = centre + rng.uniform(*c.wrist_distance) * direction
            aim = centre + np.append(rng.uniform(-c.wrist_aim_spread, c.wrist_aim_spread, 2), 0.0)
            z_camera = aim - camera_position
            z_camera /= np.linalg.norm(z_camera)
            R_tcp = Rotation.from_rotvec(
                np.radians(rng.uniform(-c.wrist_max_roll, c.wrist_max_roll)) * np.array([0, 0, -1.0])
            )
            R_camera0 = (Rotation.from_matrix(R_down) * R_tcp).as_matrix() @ T_tcp_camera[:3, :3]
            # The smallest turn taking the nominal camera axis onto the wanted one keeps the roll.
            turn = Rotation.align_vectors([z_camera], [R_camera0[:, 2]])[0]
            T_base_camera = np.eye(4)
            T_base_camera[:3, :3] = turn.as_matrix() @ R_camera0
            T_base_camera[:3, 3] = camera_position
            poses.append(T_base_camera @ np.linalg.inv(T_tcp_camera))
        return poses

    # -- truth (evaluation only) -------------------------------------------------------------------
    def camera_truth(self, camera: str) -> CameraCalibration:
        """A camera's true calibration now (:meth:`twin.session.TwinSession.camera_truth`): intrinsics and
        lens with the profile's errors, the true mounting pose (an arm camera's relative to the TCP).
        For evaluating a calibration in the twin; never for the calibration itself."""
        return self.session.camera_truth(camera)
