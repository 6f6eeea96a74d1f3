"""ArUco marker images and the MJCF texture and material that put them on a geom.

One dictionary serves the whole project (:data:`ARUCO_DICTIONARY`); a spec's ``marker`` field is an id in it.

How a marker gets into a scene
------------------------------
MuJoCo maps a ``2d`` texture onto a box geom face by face: with ``texuniform="false"`` every face gets
the texture once (``texrepeat="1 1"``), stretched over the whole face. On the +z face the texture's
horizontal axis runs along the geom's +x and its top row lies at the geom's +y edge, so seen from
above the image appears upright and unmirrored. That is exactly the object frame OpenCV gives a marker
(x right, y up in the image, z out of the marker towards the viewer), so a marker pose estimated by
``cv2.solvePnP(..., SOLVEPNP_IPPE_SQUARE)`` *is* the pose of the geom frame.
``tests/models/test_markers.py`` checks this by rendering a yawed marker and recovering its yaw.

Builders therefore put each marker on its own thin, square box geom (see :func:`add_marker_geom`):
half-side :func:`marker_geom_size`, so that the black square is exactly the marker size and the white
quiet zone is all around it; a thickness of ``MARKER_THICKNESS`` to stay clear of z-fighting with the
surface it lies on; ``contype=conaffinity=0`` so that it never takes part in contacts (the part it is
glued to carries the collision shape); ``group=2`` (visual). The other five faces carry the texture
too, squeezed, which is harmless at this thickness. A plane geom cannot do this job: MuJoCo allows planes
only in static bodies ("plane only allowed in static bodies"), and markers ride on moving doors, slides
and wheels.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import cv2
import numpy as np

from puzzlebox.models.errors import ModelsError

if TYPE_CHECKING:
    from dm_control import mjcf

__all__ = [
    "ARUCO_DICTIONARY",
    "MARKER_BITS",
    "MARKER_THICKNESS",
    "MAX_MARKER_ID",
    "MarkerError",
    "add_marker_geom",
    "add_marker_material",
    "add_png_material",
    "aruco_dictionary",
    "marker_geom_size",
    "marker_image",
    "marker_png",
    "png_bytes",
]

ARUCO_DICTIONARY: int = cv2.aruco.DICT_4X4_250
"""The project's ArUco dictionary (an OpenCV ``cv2.aruco.DICT_*`` constant). 4x4 data bits because, for
a given marker size, that gives the largest bits of any dictionary: the markers stay readable in
low-resolution overview renders where one marker spans only ~35-40 px; 250 ids cover every puzzle box."""

MAX_MARKER_ID: int = 249
"""Largest marker id in :data:`ARUCO_DICTIONARY` (ids run 0..249)."""

MARKER_BITS: int = 6
"""Side of a marker in bits: 4 data bits plus a one-bit black border on each side."""

MARKER_THICKNESS: float = 0.0005
"""Full thickness of the marker geom [m]: thin enough to look printed on, thick enough that its top face
never z-fights with the face it lies on."""


class MarkerError(ModelsError, ValueError):
    """A marker id outside the project's dictionary, or marker dimensions that cannot be drawn."""


def aruco_dictionary(dictionary: int = ARUCO_DICTIONARY) -> cv2.aruco.Dictionary:
    """The OpenCV dictionary object of ``dictionary`` (a ``cv2.aruco.DICT_*`` constant; the project's
    :data:`ARUCO_DICTIONARY` by default), for detectors and marker generation."""
    return cv2.aruco.getPredefinedDictionary(dictionary)


def _check_id(marker_id: int) -> int:
    if isinstance(marker_id, bool) or not isinstance(marker_id, int | np.integer):
        raise MarkerError(f"marker id must be an integer in 0..{MAX_MARKER_ID}, got {marker_id!r}")
    if not 0 <= marker_id <= MAX_MARKER_ID:
        raise MarkerError(
            f"marker id {marker_id} is outside the project's ArUco dictionary DICT_4X4_250: "
            f"valid ids are 0..{MAX_MARKER_ID}"
        )
    return int(marker_id)


def marker_image(marker_id: int, pixels_per_bit: int = 16, quiet_zone_bits: int = 1) -> np.ndarray:
    """The marker as a grayscale image: black border and data bits inside a white quiet zone.

    Args:
        marker_id: id in :data:`ARUCO_DICTIONARY`, 0..:data:`MAX_MARKER_ID`.
        pixels_per_bit: side of one bit [px]; every bit is an exact square of this many pixels.
        quiet_zone_bits: width of the white margin on each side [bits]; detectors need at least one.

    Returns:
        ``uint8`` array of shape ``(n, n)`` with ``n = (MARKER_BITS + 2 * quiet_zone_bits) * pixels_per_bit``;
        0 is black, 255 white. Row 0 is the top of the marker as OpenCV draws it.

    Raises:
        MarkerError: for an id outside 0..249, or a non-positive ``pixels_per_bit`` or negative quiet zone.
    """
    marker_id = _check_id(marker_id)
    if pixels_per_bit < 1:
        raise MarkerError(f"pixels_per_bit must be at least 1, got {pixels_per_bit}")
    if quiet_zone_bits < 0:
        raise MarkerError(f"quiet_zone_bits must be 0 or more, got {quiet_zone_bits}")
    # Draw one pixel per bit and scale up by repetition: OpenCV's own resizing to an arbitrary side
    # would blur bit edges when the side is not a multiple of the bit count.
    bits = cv2.aruco.generateImageMarker(aruco_dictionary(), marker_id, MARKER_BITS, borderBits=1)
    image = np.kron(bits, np.ones((pixels_per_bit, pixels_per_bit), dtype=np.uint8))
    margin = quiet_zone_bits * pixels_per_bit
    return np.pad(image, margin, mode="constant", constant_values=255).astype(np.uint8)


def png_bytes(gray: np.ndarray) -> bytes:
    """A grayscale ``uint8`` image encoded as PNG bytes (3-channel, which every MuJoCo version decodes)."""
    image = np.asarray(gray, dtype=np.uint8)
    ok, encoded = cv2.imencode(".png", cv2.cvtColor(image, cv2.COLOR_GRAY2BGR))
    if not ok:  # pragma: no cover - OpenCV only fails here when out of memory
        raise MarkerError(f"OpenCV could not encode a {image.shape} image as PNG")
    return encoded.tobytes()


def marker_png(marker_id: int, pixels_per_bit: int = 16, quiet_zone_bits: int = 1) -> bytes:
    """:func:`marker_image` encoded as PNG bytes (:func:`png_bytes`)."""
    return png_bytes(marker_image(marker_id, pixels_per_bit, quiet_zone_bits))


def marker_geom_size(marker_size_m: float, quiet_zone_bits: int = 1) -> float:
    """Half-side of the square marker geom whose texture shows a black square ``marker_size_m`` wide [m].

    The texture is the whole :func:`marker_image`, black square plus quiet zone, stretched over the face,
    so the face is ``(MARKER_BITS + 2 * quiet_zone_bits) / MARKER_BITS`` times the black square.

    Args:
        marker_size_m: side of the marker's black square [m].
        quiet_zone_bits: quiet zone of the texture on each side [bits], as given to :func:`marker_image`.
    """
    if marker_size_m <= 0:
        raise MarkerError(f"marker size must be positive [m], got {marker_size_m}")
    if quiet_zone_bits < 0:
        raise MarkerError(f"quiet_zone_bits must be 0 or more, got {quiet_zone_bits}")
    return 0.5 * marker_size_m * (MARKER_BITS + 2 * quiet_zone_bits) / MARKER_BITS


def add_marker_material(
    mjcf_root: mjcf.RootElement,
    marker_id: int,
    name: str,
    pixels_per_bit: int = 16,
    quiet_zone_bits: int = 1,
) -> mjcf.Element:
    """Add the marker's texture (``<name>_texture``) and material (``<name>``) to an MJCF model.

    The material maps the texture once onto each face of a box geom (``texuniform="false"``,
    ``texrepeat="1 1"``): on the +z face upright and unmirrored when seen from above, with the marker's
    x along the geom's +x (see the module docstring). It is matte (no specular highlight) so that lights
    never wash out the black bits.

    Args:
        mjcf_root: the model to add the assets to.
        marker_id: id in :data:`ARUCO_DICTIONARY`, 0..:data:`MAX_MARKER_ID`.
        name: name of the material; the texture is named ``<name>_texture``. Must be unique in the model.
        pixels_per_bit: texture resolution [px per bit]; 16 keeps bits crisp up to ~100 px per marker side.
        quiet_zone_bits: white margin in the texture [bits]; give the same value to :func:`marker_geom_size`.

    Returns:
        The ``<material>`` element, to be set as ``material`` of the marker geom.

    Raises:
        MarkerError: for an id outside 0..249.
    """
    return add_png_material(mjcf_root, marker_png(marker_id, pixels_per_bit, quiet_zone_bits), name)


def add_png_material(mjcf_root: mjcf.RootElement, png: bytes, name: str) -> mjcf.Element:
    """Add a PNG image as a ``2d`` texture (``<name>_texture``) and a matte material (``<name>``) that maps
    it once onto each face of a box geom (``texuniform="false"``, ``texrepeat="1 1"``; the orientation
    on the +z face is in the module docstring). Matte (no specular highlight, no reflection) so that the
    lights never wash out black print.

    Args:
        mjcf_root: the model to add the assets to.
        png: the image, PNG-encoded (:func:`png_bytes`).
        name: name of the material; the texture is named ``<name>_texture``. Must be unique in the model.

    Returns:
        The ``<material>`` element.
    """
    # Imported here, not at module level: importing dm_control picks an OpenGL backend from MUJOCO_GL
    # (GLFW when unset, which warns at exit without a display), and marker images alone need none.
    from dm_control import mjcf

    texture = mjcf_root.asset.add(
        "texture",
        name=f"{name}_texture",
        type="2d",
        file=mjcf.Asset(contents=png, extension=".png"),
    )
    return mjcf_root.asset.add(
        "material",
        name=name,
        texture=texture,
        texuniform=False,
        texrepeat=[1, 1],
        specular=0.0,
        shininess=0.0,
        reflectance=0.0,
    )


def add_marker_geom(
    parent: mjcf.Element,
    marker_id: int,
    name: str,
    marker_size_m: float,
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0),
    yaw: float = 0.0,
    quiet_zone_bits: int = 1,
) -> mjcf.Element:
    """Add a marker geom lying flat on a surface, with its own texture and material.

    The geom is a thin box (visual only: ``contype=conaffinity=0``, ``group=2``) whose frame is the marker
    frame: origin at the centre of the marker's top face, z out of the marker, x along the marker's x.

    Args:
        parent: body (or worldbody) to add the geom to; its root receives the texture and material.
        marker_id: id in :data:`ARUCO_DICTIONARY`, 0..:data:`MAX_MARKER_ID`.
        name: geom name; the material is ``<name>_material``, the texture ``<name>_material_texture``.
        marker_size_m: side of the black square [m].
        pos: centre of the marker's top face in the parent frame [m]; the box extends below it.
        yaw: rotation of the marker about the parent's z axis [rad].
        quiet_zone_bits: white margin around the black square [bits].
    """
    material = add_marker_material(parent.root, marker_id, f"{name}_material", quiet_zone_bits=quiet_zone_bits)
    half = marker_geom_size(marker_size_m, quiet_zone_bits)
    x, y, z = pos
    return parent.add(
        "geom",
        name=name,
        type="box",
        size=[half, half, MARKER_THICKNESS / 2],
        pos=[x, y, z - MARKER_THICKNESS / 2],
        # A quaternion, not euler: euler is read in the compiler's angle unit (degrees by default).
        quat=[math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)],
        material=material,
        rgba=[1, 1, 1, 1],
        contype=0,
        conaffinity=0,
        group=2,
        mass=0,
    )
