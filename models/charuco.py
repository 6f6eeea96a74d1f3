"""The ChArUco calibration board: its definition, its texture image, its corners, and its MJCF body.

A ChArUco board is a chessboard whose white squares carry ArUco markers: the markers identify each
chessboard corner, so a partly seen or tilted board still gives corners with known board coordinates,
and the corners themselves (saddle points) are located to a small fraction of a pixel.

Its markers come from :data:`CharucoBoardSpec.dictionary` (``DICT_5X5_100`` by default), not from the
puzzle markers' ``DICT_4X4_250``: a board lying in a scene never reads as a puzzle component.

Board frame
-----------
OpenCV's: origin at the outer corner of the top-left square of the printed board, x along the rows
(to the right on the print), y down the print, z = x × y into the board (away from whoever looks at
it). :meth:`CharucoBoardSpec.corners_in_board` gives the chessboard corners in this frame, exactly as
``cv2.aruco.CharucoBoard.getChessboardCorners`` does; ``cv2.solvePnP`` on detected corners therefore
gives ``T_camera_board`` directly.

How it is put into a scene
--------------------------
:func:`add_board_body` adds a *mocap* body whose frame is the board frame, so a rig sets
``mocap_pos``/``mocap_quat`` to a wanted ``T_base_board`` and nothing else. The board is a thin,
visual-only box geom textured with :meth:`CharucoBoardSpec.image`. MuJoCo maps a ``2d`` texture on the
+z face of a box with the image's horizontal axis along the geom's +x and its top row at the geom's +y
edge (see :mod:`models.markers`), so the print's (x right, y down) is (geom +x, geom -y) and the board
frame is the geom frame turned half a turn about x and shifted to the corner of the first square:
``T_geom_board`` (:meth:`CharucoBoardSpec.T_geom_board`). ``tests/twin/test_calibration_rig.py``
checks this by rendering a board at a known pose and recovering that pose with ``solvePnP``.

A board lying flat with its print up therefore has its z axis pointing *down*
(:func:`board_pose_flat`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import cv2
import numpy as np

from puzzlebox.models.errors import ModelsError
from puzzlebox.models.markers import add_png_material, aruco_dictionary, png_bytes

if TYPE_CHECKING:
    from dm_control import mjcf

__all__ = [
    "BOARD_BODY",
    "DEFAULT_BOARD",
    "CharucoBoardSpec",
    "CharucoError",
    "add_board_body",
    "board_pose_flat",
]

BOARD_BODY = "calibration_board"
"""Name of the board's mocap body (and prefix of its geom, material and texture) in a scene."""

BOARD_HIDDEN_POS = (0.0, 0.0, -0.5)
"""Where the board's mocap body starts [m]: inside the table, out of every camera's view."""


class CharucoError(ModelsError, ValueError):
    """A board definition that cannot be drawn or detected."""


@dataclass(frozen=True)
class CharucoBoardSpec:
    """A ChArUco board: a chessboard with ArUco markers in its white squares (see the module docstring)."""

    squares_x: int = 8
    """Squares along the board's x (along the print's rows)."""
    squares_y: int = 6
    """Squares along the board's y (down the print)."""
    square_size: float = 0.032
    """Side of a chessboard square [m]: the 8 x 6 board is 256 x 192 mm, which fills a third to a half of
    the overview camera's image at 0.25-0.4 m and of the wrist camera's at 0.25-0.35 m."""
    marker_size: float = 0.024
    """Side of a marker's black square [m] (3/4 of a square: a 5x5 marker + border is 7 bits of 3.4 mm)."""
    dictionary: int = cv2.aruco.DICT_5X5_100
    """OpenCV ArUco dictionary of the markers (ids 0..23 of it): not the puzzle markers' DICT_4X4_250."""
    margin: float = 0.016
    """White margin around the chessboard on the print [m] (half a square: the outer markers need a
    quiet zone)."""
    thickness: float = 0.003
    """Thickness of the board [m] (a printed plate)."""

    def __post_init__(self) -> None:
        if self.squares_x < 3 or self.squares_y < 3:
            raise CharucoError(f"a ChArUco board needs at least 3x3 squares, got {self.squares_x}x{self.squares_y}")
        if not 0 < self.marker_size < self.square_size:
            raise CharucoError(
                f"marker size must be positive and smaller than the square size [m], "
                f"got {self.marker_size} and {self.square_size}"
            )
        if self.margin < 0 or self.thickness <= 0:
            raise CharucoError(f"margin must be >= 0 and thickness > 0 [m], got {self.margin}, {self.thickness}")

    # -- OpenCV ------------------------------------------------------------------------------------
    def aruco_dictionary(self) -> cv2.aruco.Dictionary:
        return aruco_dictionary(self.dictionary)

    def cv_board(self) -> cv2.aruco.CharucoBoard:
        """The OpenCV board object (for ``cv2.aruco.CharucoDetector`` and ``matchImagePoints``)."""
        return cv2.aruco.CharucoBoard(
            (self.squares_x, self.squares_y), self.square_size, self.marker_size, self.aruco_dictionary()
        )

    @property
    def num_corners(self) -> int:
        """Number of inner chessboard corners (the points calibration uses)."""
        return (self.squares_x - 1) * (self.squares_y - 1)

    def corners_in_board(self) -> np.ndarray:
        """``(num_corners, 3)`` chessboard corners in the board frame [m], row by row; index = ChArUco id."""
        ids = np.arange(self.num_corners)
        x = (ids % (self.squares_x - 1) + 1) * self.square_size
        y = (ids // (self.squares_x - 1) + 1) * self.square_size
        return np.stack([x, y, np.zeros_like(x)], axis=1)

    def outline_in_board(self) -> np.ndarray:
        """``(4, 3)`` corners of the printed plate (chessboard plus margin) in the board frame [m]."""
        w, h, m = self.squares_x * self.square_size, self.squares_y * self.square_size, self.margin
        return np.array([[-m, -m, 0], [w + m, -m, 0], [w + m, h + m, 0], [-m, h + m, 0]], dtype=float)

    @property
    def center_in_board(self) -> np.ndarray:
        """Centre of the chessboard in the board frame [m]."""
        return np.array([self.squares_x * self.square_size / 2, self.squares_y * self.square_size / 2, 0.0])

    # -- the print ---------------------------------------------------------------------------------
    def margin_pixels(self, pixels_per_square: int) -> int:
        return round(self.margin / self.square_size * pixels_per_square)

    def image(self, pixels_per_square: int = 140) -> np.ndarray:
        """The printed board as a grayscale image (chessboard, markers and white margin).

        Args:
            pixels_per_square: side of a square [px]; 140 px makes a 5x5 marker (7 bits of 3/4 square)
                exactly 15 px per bit.

        Returns:
            ``uint8`` array ``(H, W)``, ``W = squares_x * pixels_per_square + 2 * margin`` px; row 0 is the
            print's top (board y = -margin), column 0 its left (board x = -margin).
        """
        if pixels_per_square < 8:
            raise CharucoError(f"pixels_per_square must be at least 8, got {pixels_per_square}")
        margin = self.margin_pixels(pixels_per_square)
        width = self.squares_x * pixels_per_square
        height = self.squares_y * pixels_per_square
        # Drawn without margin at an exact multiple of the square size (every square an exact pixel
        # square), then padded: OpenCV centres a board in a larger image by rounding.
        board = self.cv_board().generateImage((width, height), marginSize=0, borderBits=1)
        return np.pad(board, margin, mode="constant", constant_values=255).astype(np.uint8)

    def png(self, pixels_per_square: int = 140) -> bytes:
        """:meth:`image` encoded as PNG bytes (:func:`models.markers.png_bytes`)."""
        return png_bytes(self.image(pixels_per_square))

    # -- the plate in a scene ----------------------------------------------------------------------
    @property
    def plate_half_size(self) -> tuple[float, float, float]:
        """Half-sizes of the plate's box geom [m]: the print (chessboard + margins) and half the thickness."""
        return (
            self.squares_x * self.square_size / 2 + self.margin,
            self.squares_y * self.square_size / 2 + self.margin,
            self.thickness / 2,
        )

    def T_geom_board(self) -> np.ndarray:
        """4x4 pose of the board frame in the plate geom's frame (see the module docstring) [m]."""
        hx, hy, hz = self.plate_half_size
        T = np.eye(4)
        T[:3, :3] = np.diag([1.0, -1.0, -1.0])
        T[:3, 3] = (-hx + self.margin, hy - self.margin, hz)
        return T


DEFAULT_BOARD = CharucoBoardSpec()
"""The cell's calibration board."""


def board_pose_flat(
    x: float, y: float, z: float, yaw: float = 0.0, board: CharucoBoardSpec = DEFAULT_BOARD
) -> np.ndarray:
    """``T_base_board`` of a board lying print up with its chessboard centred at ``(x, y)`` and its print
    at height ``z`` [m]; ``yaw`` turns the print's x axis about the base z [rad]. The board's z points down."""
    c, s = math.cos(yaw), math.sin(yaw)
    R = np.array([[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]])  # x = (c, s, 0), z down, y = z × x
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = np.array([x, y, z]) - R @ board.center_in_board
    return T


def add_board_body(
    worldbody: mjcf.Element,
    board: CharucoBoardSpec = DEFAULT_BOARD,
    name: str = BOARD_BODY,
    pixels_per_square: int = 140,
) -> mjcf.Element:
    """Add the board as a mocap body whose frame is the board frame, hidden inside the table at first.

    The plate is one box geom, visual only (``contype=conaffinity=0``, ``group=2``, massless): a rig
    moves it anywhere, through the arm or the box, without disturbing the physics. Its material
    (``<name>_material``, texture ``<name>_material_texture``) is matte, as a marker's
    (:func:`models.markers.add_png_material`), so that the key light never washes out the squares.

    Returns:
        The ``<body>`` element.
    """
    material = add_png_material(worldbody.root, board.png(pixels_per_square), f"{name}_material")
    body = worldbody.add("body", name=name, mocap=True, pos=list(BOARD_HIDDEN_POS))
    T_board_geom = np.linalg.inv(board.T_geom_board())
    body.add(
        "geom",
        name=f"{name}_plate",
        type="box",
        size=list(board.plate_half_size),
        pos=T_board_geom[:3, 3].tolist(),
        quat=[0.0, 1.0, 0.0, 0.0],  # half a turn about x (module docstring)
        material=material,
        rgba=[1, 1, 1, 1],
        contype=0,
        conaffinity=0,
        group=2,
        mass=0,
    )
    return body
