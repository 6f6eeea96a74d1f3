"""Camera calibration from images of a ChArUco board: intrinsics, a fixed camera's pose, hand-eye.

Pure functions over images and poses, as a real cell's calibration runs: they know the board
(:mod:`models.charuco`) and what the arm reported, never the cameras' true parameters. The procedure
that moves the board and the arm lives with the caller (``scripts/calibrate.py`` with
``twin.calibration_rig`` in the twin); the result goes into a :class:`models.calibration.CellCalibration`.

1. :func:`calibrate_intrinsics`: ``K`` and distortion ``[k1, k2, p1, p2, k3]`` from several views of
   the board at varied distances and tilts (``cv2.calibrateCamera``, Zhang's method), views whose
   residual is far above the others' dropped once.
2. :func:`fixed_camera_pose`: a fixed camera's ``T_base_camera`` from the board at a known place
   ``T_base_board``: ``solvePnP`` (IPPE for the planar board) refined by Levenberg-Marquardt over all
   the corners seen.
3. :func:`hand_eye`: a camera on the arm (eye-in-hand), from views of a board that stays put while the
   arm moves: ``T_base_tcp_i @ T_tcp_camera @ T_camera_board_i = T_base_board`` for every view ``i``.
   Closed-form start (Park & Martin 1994: rotation from the axes of relative motions, translation by
   linear least squares) then a joint refinement of ``T_tcp_camera`` and ``T_base_board`` on the
   reprojection error of every corner of every view. ``cv2.calibrateHandEye`` would give the start, but
   the installed OpenCV 5.0 Python binding does not export it, and the refinement matters more.

Conventions: OpenCV pixel coordinates (integer at pixel centres) and camera frame (x right, y down,
z forward); poses are 4x4 matrices named after their frames; lengths in metres.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from puzzlebox.models.charuco import DEFAULT_BOARD, CharucoBoardSpec
from puzzlebox.skills.errors import BoardNotFound, InconsistentViews, TooFewViews

__all__ = [
    "BoardView",
    "board_pose_in_camera",
    "CalibrationConfig",
    "FixedPoseResult",
    "HandEyeResult",
    "IntrinsicsResult",
    "calibrate_intrinsics",
    "detect_board",
    "fixed_camera_pose",
    "hand_eye",
    "pose_error",
    "solve_hand_eye_closed_form",
]


@dataclass(frozen=True)
class CalibrationConfig:
    """How board images are read and which views count."""

    board: CharucoBoardSpec = DEFAULT_BOARD
    """The calibration board (its squares, markers and dictionary)."""
    min_corners: int = 8
    """A view with fewer ChArUco corners is not used: too few to fix a pose, let alone a tilt."""
    min_views_intrinsics: int = 6
    """Intrinsics need at least this many usable views (Zhang's method needs 3; distortion and a
    well-conditioned focal length need varied tilts)."""
    min_views_hand_eye: int = 4
    """Hand-eye needs at least this many usable views (two motions with non-parallel axes at least)."""
    fix_k3: bool = True
    """Keep k3 at zero: on a lens of moderate field of view it only trades off against k1/k2 and
    extrapolates badly at the image corners."""
    outlier_factor: float = 3.0
    """A view whose RMS reprojection error exceeds this many times the median (and 0.5 px) is dropped
    once and the calibration redone (a misdetected corner, motion blur)."""


@dataclass(frozen=True)
class BoardView:
    """The ChArUco corners found in one image.

    Attributes:
        ids: ``(N,)`` ChArUco corner ids.
        image_points: ``(N, 2)`` corner positions [px].
        object_points: ``(N, 3)`` the same corners in the board frame [m].
        image_size: ``(width, height)`` [px].
    """

    ids: np.ndarray
    image_points: np.ndarray
    object_points: np.ndarray
    image_size: tuple[int, int]


@dataclass(frozen=True)
class IntrinsicsResult:
    """Result of :func:`calibrate_intrinsics`.

    Attributes:
        K: 3x3 intrinsics [px].
        dist: ``(5,)`` distortion ``[k1, k2, p1, p2, k3]``.
        image_size: ``(width, height)`` [px].
        rms_px: RMS reprojection error over every corner of the views used [px].
        views_used: indices (into the images given) of the views the calibration used.
        views_dropped: indices of views seen but dropped as outliers.
    """

    K: np.ndarray
    dist: np.ndarray
    image_size: tuple[int, int]
    rms_px: float
    views_used: tuple[int, ...]
    views_dropped: tuple[int, ...] = ()


@dataclass(frozen=True)
class FixedPoseResult:
    """Result of :func:`fixed_camera_pose`: ``T_base_camera`` [m] and the RMS reprojection error [px]."""

    T_base_camera: np.ndarray
    rms_px: float


@dataclass(frozen=True)
class HandEyeResult:
    """Result of :func:`hand_eye`.

    Attributes:
        T_tcp_camera: 4x4 camera pose in the TCP frame [m] (OpenCV camera frame).
        T_base_board: 4x4 pose of the (fixed) board in the base frame found along with it [m].
        rms_px: RMS reprojection error of every corner of every view used, after refinement [px].
        views_used: indices (into the images given) of the views used.
    """

    T_tcp_camera: np.ndarray
    T_base_board: np.ndarray
    rms_px: float
    views_used: tuple[int, ...]


# -- small pose helpers --------------------------------------------------------------------------------
def _pose(rvec: np.ndarray, tvec: np.ndarray) -> np.ndarray:
    """4x4 pose from a rotation vector (OpenCV's ``rvec``, axis times angle) and a translation."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(np.asarray(rvec, dtype=float).reshape(3)).as_matrix()
    T[:3, 3] = np.asarray(tvec, dtype=float).reshape(3)
    return T


def _rvec_tvec(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The inverse of :func:`_pose`: rotation vector and translation of a 4x4 pose."""
    return Rotation.from_matrix(T[:3, :3]).as_rotvec(), T[:3, 3].copy()


def _params_to_pose(p: np.ndarray) -> np.ndarray:
    return _pose(p[:3], p[3:6])


def _pose_to_params(T: np.ndarray) -> np.ndarray:
    return np.concatenate(_rvec_tvec(T))


def pose_error(T_estimate: np.ndarray, T_truth: np.ndarray) -> tuple[float, float]:
    """Distance between two poses: translation [m] and rotation angle [rad] of ``T_truth⁻¹ T_estimate``."""
    T_estimate, T_truth = np.asarray(T_estimate, float), np.asarray(T_truth, float)
    delta = np.linalg.inv(T_truth) @ T_estimate
    angle = Rotation.from_matrix(delta[:3, :3]).magnitude()
    return float(np.linalg.norm(T_estimate[:3, 3] - T_truth[:3, 3])), float(angle)


def _rms(errors: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum(np.asarray(errors).reshape(-1, 2) ** 2, axis=1))))


# -- detection -----------------------------------------------------------------------------------------
def _gray(image) -> np.ndarray:
    pixels = np.asarray(getattr(image, "rgb", image))
    if pixels.ndim == 3:
        return cv2.cvtColor(pixels, cv2.COLOR_RGB2GRAY)
    if pixels.ndim != 2:
        raise InconsistentViews(f"an image is (H, W) or (H, W, 3), got shape {pixels.shape}")
    return pixels


@functools.lru_cache(maxsize=4)
def _detector(board: CharucoBoardSpec) -> cv2.aruco.CharucoDetector:
    """One detector per board, built once: it holds the board and its dictionary."""
    return cv2.aruco.CharucoDetector(board.cv_board())


def detect_board(image, config: CalibrationConfig | None = None) -> BoardView | None:
    """The board's ChArUco corners in an image (RGB, gray, or anything with ``.rgb``), or None when
    fewer than :attr:`CalibrationConfig.min_corners` are found."""
    config = config or CalibrationConfig()
    gray = _gray(image)
    corners, ids, _, _ = _detector(config.board).detectBoard(gray)
    if ids is None or len(ids) < config.min_corners:
        return None
    ids = ids.ravel().astype(int)
    return BoardView(
        ids=ids,
        image_points=corners.reshape(-1, 2).astype(np.float64),
        object_points=config.board.corners_in_board()[ids],
        image_size=(gray.shape[1], gray.shape[0]),
    )


def _board_views(images: Sequence, config: CalibrationConfig) -> list[tuple[int, BoardView]]:
    """The views (index, corners) that show the board: images are detected, :class:`BoardView` taken as
    they are, None (what :func:`detect_board` gives an image without the board) skipped."""
    views = [
        (i, image if image is None or isinstance(image, BoardView) else detect_board(image, config))
        for i, image in enumerate(images)
    ]
    views = [(i, v if v is not None and len(v.ids) >= config.min_corners else None) for i, v in views]
    sizes = {v.image_size for _, v in views if v is not None}
    if len(sizes) > 1:
        raise InconsistentViews(f"images of one camera must share one size, got {sorted(sizes)}")
    return [(i, v) for i, v in views if v is not None]


def board_pose_in_camera(view: BoardView, K: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """``T_camera_board`` of one view [m]: IPPE (planar target) then Levenberg-Marquardt on every corner.

    Raises:
        BoardNotFound: solvePnP found no pose.
    """
    obj = view.object_points.astype(np.float64)
    img = view.image_points.reshape(-1, 1, 2)
    ok, rvec, tvec = cv2.solvePnP(obj, img, K, dist, flags=cv2.SOLVEPNP_IPPE)
    if not ok:
        raise BoardNotFound(f"solvePnP found no board pose from {len(obj)} corners")
    rvec, tvec = cv2.solvePnPRefineLM(obj, img, K, dist, rvec, tvec)
    return _pose(rvec, tvec)


# -- 1. intrinsics -------------------------------------------------------------------------------------
def calibrate_intrinsics(images: Sequence, config: CalibrationConfig | None = None) -> IntrinsicsResult:
    """Intrinsics and distortion of one camera from several views of the board (module docstring, 1).

    Args:
        images: board views of one camera (``(H, W, 3)`` RGB, ``(H, W)`` gray, objects with ``.rgb``, or
            what :func:`detect_board` made of them: a :class:`BoardView`, or None for no board).
        config: board and acceptance settings.

    Raises:
        TooFewViews: fewer than :attr:`CalibrationConfig.min_views_intrinsics` views show the board.
        InconsistentViews: images of different sizes.
    """
    config = config or CalibrationConfig()
    views = _board_views(images, config)
    _require_views(len(views), len(images), config.min_views_intrinsics, "intrinsic calibration", config)
    size = views[0][1].image_size
    flags = cv2.CALIB_FIX_K3 if config.fix_k3 else 0

    def run(selected: list[tuple[int, BoardView]]):
        obj = [v.object_points.astype(np.float32) for _, v in selected]
        img = [v.image_points.astype(np.float32).reshape(-1, 1, 2) for _, v in selected]
        _, K, dist, rvecs, tvecs = cv2.calibrateCamera(obj, img, size, None, None, flags=flags)
        per_view = []
        for (_, v), r, t in zip(selected, rvecs, tvecs, strict=True):
            projected, _ = cv2.projectPoints(v.object_points, r, t, K, dist)
            per_view.append(projected.reshape(-1, 2) - v.image_points)
        return K, dist.ravel(), per_view

    K, dist, residuals = run(views)
    view_rms = np.array([_rms(r) for r in residuals])
    bad = view_rms > max(config.outlier_factor * float(np.median(view_rms)), 0.5)
    dropped: tuple[int, ...] = ()
    if bad.any() and (~bad).sum() >= config.min_views_intrinsics:
        dropped = tuple(i for (i, _), b in zip(views, bad, strict=True) if b)
        views = [view for view, b in zip(views, bad, strict=True) if not b]
        K, dist, residuals = run(views)
    dist5 = np.zeros(5)
    dist5[: min(5, dist.size)] = dist[:5]
    return IntrinsicsResult(
        K=K,
        dist=dist5,
        image_size=size,
        rms_px=_rms(np.concatenate(residuals)),
        views_used=tuple(i for i, _ in views),
        views_dropped=dropped,
    )


def _require_views(found: int, given: int, needed: int, what: str, config: CalibrationConfig) -> None:
    if found < needed:
        raise TooFewViews(
            f"{what} needs at least {needed} views showing >= {config.min_corners} board corners; "
            f"{found} of the {given} images given do"
        )


# -- 2. a fixed camera ---------------------------------------------------------------------------------
def fixed_camera_pose(
    images,
    K: np.ndarray,
    dist: np.ndarray,
    T_base_board: np.ndarray,
    config: CalibrationConfig | None = None,
) -> FixedPoseResult:
    """A fixed camera's pose from the board at a known place (module docstring, 2).

    Args:
        images: one image, or several of the same still scene (their corners are pooled, which averages
            the image noise).
        K, dist: the camera's intrinsics [px] and distortion (from :func:`calibrate_intrinsics`).
        T_base_board: 4x4 pose of the board in the base frame [m] (where it was laid).

    Raises:
        BoardNotFound: no image shows at least :attr:`CalibrationConfig.min_corners` board corners.
    """
    config = config or CalibrationConfig()
    if isinstance(images, np.ndarray | BoardView) or hasattr(images, "rgb"):
        images = [images]
    views = [v for _, v in _board_views(images, config)]
    if not views:
        raise BoardNotFound(
            f"no board with >= {config.min_corners} corners in the {len(images)} image(s) of the fixed camera"
        )
    pooled = BoardView(
        ids=np.concatenate([v.ids for v in views]),
        image_points=np.concatenate([v.image_points for v in views]),
        object_points=np.concatenate([v.object_points for v in views]),
        image_size=views[0].image_size,
    )
    K, dist = np.asarray(K, float), np.asarray(dist, float)
    T_camera_board = board_pose_in_camera(pooled, K, dist)
    rvec, tvec = _rvec_tvec(T_camera_board)
    projected, _ = cv2.projectPoints(pooled.object_points, rvec, tvec, K, dist)
    return FixedPoseResult(
        T_base_camera=np.asarray(T_base_board, float) @ np.linalg.inv(T_camera_board),
        rms_px=_rms(projected.reshape(-1, 2) - pooled.image_points),
    )


# -- 3. hand-eye ---------------------------------------------------------------------------------------
def solve_hand_eye_closed_form(T_base_tcp: Sequence[np.ndarray], T_camera_board: Sequence[np.ndarray]) -> np.ndarray:
    """``T_tcp_camera`` from ``T_base_tcp_i @ X @ T_camera_board_i = const`` (Park & Martin 1994).

    Every pair of views gives ``A X = X B`` with ``A = T_base_tcp_j⁻¹ T_base_tcp_i`` and
    ``B = T_camera_board_j T_camera_board_i⁻¹``; the rotation aligns the rotation vectors of the ``B``
    with those of the ``A`` (orthogonal Procrustes), the translation solves
    ``(R_A - I) t = R_X t_B - t_A`` by least squares.

    Raises:
        TooFewViews: the motions do not turn about two non-parallel axes (the rotation is undetermined).
    """
    G = [np.asarray(T, float) for T in T_base_tcp]
    C = [np.asarray(T, float) for T in T_camera_board]
    if len(G) != len(C):
        raise InconsistentViews(f"need one TCP pose per board pose, got {len(G)} and {len(C)}")
    alphas, betas, As, Bs = [], [], [], []
    for i, j in itertools.combinations(range(len(G)), 2):
        A = np.linalg.inv(G[j]) @ G[i]
        B = C[j] @ np.linalg.inv(C[i])
        a = Rotation.from_matrix(A[:3, :3]).as_rotvec()
        b = Rotation.from_matrix(B[:3, :3]).as_rotvec()
        if np.linalg.norm(a) < np.radians(2.0):  # almost pure translation: no information on the rotation
            continue
        alphas.append(a)
        betas.append(b)
        As.append(A)
        Bs.append(B)
    if len(alphas) < 2 or np.linalg.matrix_rank(np.array(alphas), tol=np.radians(1.0)) < 2:
        raise TooFewViews(
            "hand-eye needs arm motions that turn the camera about at least two non-parallel axes "
            f"(> 2 deg); the {len(G)} views give {len(alphas)} such motions"
        )
    H = np.array(betas).T @ np.array(alphas)  # sum of b a^T
    U, _, Vt = np.linalg.svd(H)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
    R_X = Vt.T @ D @ U.T
    lhs = np.concatenate([A[:3, :3] - np.eye(3) for A in As])
    rhs = np.concatenate([R_X @ B[:3, 3] - A[:3, 3] for A, B in zip(As, Bs, strict=True)])
    t_X = np.linalg.lstsq(lhs, rhs, rcond=None)[0]
    X = np.eye(4)
    X[:3, :3] = R_X
    X[:3, 3] = t_X
    return X


def hand_eye(
    images: Sequence,
    T_base_tcp: Sequence[np.ndarray],
    K: np.ndarray,
    dist: np.ndarray,
    config: CalibrationConfig | None = None,
) -> HandEyeResult:
    """An arm camera's ``T_tcp_camera`` from views of a board that stays put (module docstring, 3).

    Args:
        images: the arm camera's images of the board, one per arm pose (or what :func:`detect_board`
            made of them, as for :func:`calibrate_intrinsics`).
        T_base_tcp: the TCP pose the arm reported at each capture (4x4, base frame) [m].
        K, dist: the camera's intrinsics [px] and distortion.

    Raises:
        TooFewViews: fewer than :attr:`CalibrationConfig.min_views_hand_eye` images show the board, or
            the arm poses do not turn the camera about two different axes.
        InconsistentViews: not one TCP pose per image, or images of different sizes.
    """
    config = config or CalibrationConfig()
    if len(images) != len(T_base_tcp):
        raise InconsistentViews(f"need one TCP pose per image, got {len(images)} images and {len(T_base_tcp)} poses")
    K, dist = np.asarray(K, float), np.asarray(dist, float)
    views = _board_views(images, config)
    _require_views(len(views), len(images), config.min_views_hand_eye, "hand-eye calibration", config)
    G = [np.asarray(T_base_tcp[i], float) for i, _ in views]
    C = [board_pose_in_camera(v, K, dist) for _, v in views]
    X0 = solve_hand_eye_closed_form(G, C)
    # The board's pose: the mean of what each view says, rotations averaged by their chordal mean.
    boards = [g @ X0 @ c for g, c in zip(G, C, strict=True)]
    Y0 = np.eye(4)
    Y0[:3, :3] = Rotation.from_matrix([b[:3, :3] for b in boards]).mean().as_matrix()
    Y0[:3, 3] = np.mean([b[:3, 3] for b in boards], axis=0)

    G_inv = [np.linalg.inv(g) for g in G]

    def residuals(p: np.ndarray) -> np.ndarray:
        X_inv = np.linalg.inv(_params_to_pose(p[:6]))
        Y = _params_to_pose(p[6:])
        out = []
        for (_, v), g_inv in zip(views, G_inv, strict=True):
            rvec, tvec = _rvec_tvec(X_inv @ g_inv @ Y)
            projected, _ = cv2.projectPoints(v.object_points, rvec, tvec, K, dist)
            out.append((projected.reshape(-1, 2) - v.image_points).ravel())
        return np.concatenate(out)

    solution = least_squares(residuals, np.concatenate([_pose_to_params(X0), _pose_to_params(Y0)]), method="lm")
    return HandEyeResult(
        T_tcp_camera=_params_to_pose(solution.x[:6]),
        T_base_board=_params_to_pose(solution.x[6:]),
        rms_px=_rms(residuals(solution.x)),
        views_used=tuple(i for i, _ in views),
    )
