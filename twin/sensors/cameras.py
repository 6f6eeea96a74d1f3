"""The cell's cameras as a real camera delivers frames: the true lens and pose, then the frame's
imperfections (:class:`~twin.reality.CameraReality`).

The renderer draws an ideal pinhole image. A true camera with intrinsics ``K_true`` and lens
distortion ``dist_true`` (OpenCV's model) sees, at its pixel ``p``, the ray ``undistort(p)``; so each
frame is the pinhole render sampled at ``K_render · undistort(p)`` (:func:`cv2.undistortPoints` over
the pixel grid, computed once per cell and camera, then :func:`cv2.remap`). When the true camera sees wider
than the nominal one, it is rendered with a wider field of view (:func:`true_lens`) so no true pixel falls
outside the render. Then, per frame: occluders, defocus and motion blur, gain, noise.
A dropped frame is None. The mounting error lives in the session's model (``cam_pos``/``cam_quat``).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from typing import Any

import cv2
import mujoco
import numpy as np

from puzzlebox.models.robot import CameraImage
from puzzlebox.twin import renderer_pool
from puzzlebox.twin.errors import UnknownCamera
from puzzlebox.twin.reality import CameraReality
from puzzlebox.twin.rendering import MUJOCO_TO_OPENCV, RenderConfig, Renderer, pinhole_intrinsics


@dataclass(frozen=True)
class TrueLens:
    """A camera's true intrinsics and the resampling that turns a pinhole render into its image."""

    K: np.ndarray
    """3x3 true intrinsics [px]."""
    dist: np.ndarray
    """``(5,)`` true distortion ``[k1, k2, p1, p2, k3]``."""
    map_x: np.ndarray | None
    """Render column sampled by each true pixel [px] (None: the true camera is the render's pinhole)."""
    map_y: np.ndarray | None
    """Render row sampled by each true pixel [px]."""


def undistorted_rays(K: np.ndarray, dist: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``(H, W, 2)`` normalized ray ``(x/z, y/z)`` seen by each pixel of a camera ``(K, dist)`` [-]."""
    width, height = size
    u, v = np.meshgrid(np.arange(width, dtype=np.float64), np.arange(height, dtype=np.float64))
    pixels = np.stack([u, v], axis=-1).reshape(-1, 1, 2)
    criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 50, 1e-12)  # sub-millipixel, k1 up to ~0.1
    rays = cv2.undistortPoints(pixels, K, dist, R=np.eye(3), P=np.eye(3), criteria=criteria)
    return rays.reshape(height, width, 2)


# The rays of a true camera depend only on the cell (its K_true, dist and the image size), yet every
# trial builds a new session: keep the few most recent (~5 MB each at 640x480), read-only.
_RAYS_CACHE_SIZE = 8
_rays_cache: dict[tuple[bytes, bytes, tuple[int, int]], np.ndarray] = {}
_rays_lock = threading.Lock()


def _cached_rays(K: np.ndarray, dist: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    width, height = size  # (a list, read from a file, is no key)
    key = (np.asarray(K, dtype=np.float64).tobytes(), np.asarray(dist, dtype=np.float64).tobytes(), (width, height))
    with _rays_lock:
        rays = _rays_cache.get(key)
    if rays is None:
        rays = undistorted_rays(K, dist, size)
        rays.flags.writeable = False
        with _rays_lock:
            _rays_cache[key] = rays
            while len(_rays_cache) > _RAYS_CACHE_SIZE:
                del _rays_cache[next(iter(_rays_cache))]  # the oldest
    return rays


def true_lens(model: mujoco.MjModel, cam: int, K_true: np.ndarray, dist: np.ndarray, size: tuple[int, int]) -> TrueLens:
    """The true lens ``(K_true, dist)`` of camera ``cam``, rendered as a pinhole by ``model``.

    When the true camera is the model's pinhole, no resampling (maps None) and ``model`` is untouched.
    Otherwise, when the true camera sees wider than the model's camera, the model's ``cam_fovy`` is widened
    (a centred pinhole, as MuJoCo renders a ``fovy`` camera, with a half-percent margin) so that every true
    pixel lies inside the render; the maps then sample that render.
    """
    width, height = size
    K_render = pinhole_intrinsics(model, cam, width, height)
    if np.array_equal(K_true, K_render) and not np.any(dist):
        return TrueLens(K_true, dist, None, None)
    rays = _cached_rays(K_true, dist, size)
    # a centred render of focal f keeps x·f + (W-1)/2 inside [0, W-1]: f <= (W-1)/2 / max|x|
    limit = min((width - 1) / 2 / np.abs(rays[..., 0]).max(), (height - 1) / 2 / np.abs(rays[..., 1]).max())
    if K_render[1, 1] > limit:
        model.cam_fovy[cam] = math.degrees(2 * math.atan(0.5 * height / (0.995 * limit)))
        K_render = pinhole_intrinsics(model, cam, width, height)
    map_x = (rays[..., 0] * K_render[0, 0] + K_render[0, 2]).astype(np.float32)
    map_y = (rays[..., 1] * K_render[1, 1] + K_render[1, 2]).astype(np.float32)
    return TrueLens(K_true, dist, map_x, map_y)


def motion_blur_kernel(dx: float, dy: float) -> np.ndarray | None:
    """A normalised line kernel of the smear ``(dx, dy)`` [px] (None below half a pixel)."""
    length = math.hypot(dx, dy)
    if length < 0.5:
        return None
    half = math.ceil(length / 2)
    kernel = np.zeros((2 * half + 1, 2 * half + 1), np.float32)
    for t in np.linspace(-0.5, 0.5, max(2, math.ceil(2 * length) + 1)):
        kernel[round(half + t * dy), round(half + t * dx)] += 1.0
    return kernel / kernel.sum()


class Cameras:
    """The cell's cameras (see the module docstring); the session owns them."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        names: tuple[str, ...],
        lenses: dict[str, TrueLens],
        config: CameraReality,
        render: RenderConfig,
    ) -> None:
        self.names = names
        self._model, self._data = model, data
        self._ids = {name: model.camera(name).id for name in names}
        self._lenses = lenses
        self.config = config
        self.render_config = render
        self._renderer: Renderer | None = None
        c = config
        self._frame_effects = bool(
            c.noise_sigma or not c.gain.is_identity or c.exposure or c.defocus_sigma or c.occluder_probability
        )

    def lens(self, camera: str) -> TrueLens:
        self._check(camera)
        return self._lenses[camera]

    def _check(self, camera: str) -> None:
        if camera not in self._ids:
            raise UnknownCamera(camera, self.names)

    def reset(self, rngs: dict[str, np.random.Generator]) -> None:
        """A new trial: each camera's per-frame randomness from its own generator."""
        self._rngs = rngs

    def capture(self, camera: str, time: float) -> CameraImage | None:
        """A frame of a named camera as the true camera delivers it, or None when it drops the frame."""
        self._check(camera)
        c, rng = self.config, self._rngs[camera]
        if c.dropped_frame_probability > 0 and rng.random() < c.dropped_frame_probability:
            return None
        if self._renderer is None:
            self._renderer = renderer_pool.acquire(self._model, self.render_config)
        rgb = self._renderer.render(self._data, camera)
        lens = self._lenses[camera]
        if lens.map_x is not None and lens.map_y is not None:  # (None together)
            rgb = cv2.remap(rgb, lens.map_x, lens.map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        if self._frame_effects:
            rgb = self._effects(rgb, camera, lens, rng)
        return CameraImage(camera=camera, rgb=rgb, time=time)

    def _effects(self, rgb: np.ndarray, camera: str, lens: TrueLens, rng: np.random.Generator) -> np.ndarray:
        c = self.config
        height, width = rgb.shape[:2]
        if c.occluder_probability > 0 and rng.random() < c.occluder_probability:
            rgb = rgb.copy()
            for _ in range(int(rng.integers(1, c.occluder_count + 1))):
                centre = (int(rng.uniform(0, width)), int(rng.uniform(0, height)))
                a, b = rng.uniform(*c.occluder_size, size=2)
                grey = int(rng.uniform(0, 120))  # shadows and dark objects: dark to mid grey
                if rng.random() < 0.5:
                    cv2.rectangle(rgb, (int(centre[0] - a / 2), int(centre[1] - b / 2)),
                                  (int(centre[0] + a / 2), int(centre[1] + b / 2)), (grey,) * 3, -1)  # fmt: skip
                else:
                    angle = float(rng.uniform(0, 180))
                    cv2.ellipse(rgb, centre, (int(a / 2), int(b / 2)), angle, 0, 360, (grey,) * 3, -1)
        image = rgb.astype(np.float32)
        if c.defocus_sigma > 0:
            image = cv2.GaussianBlur(image, (0, 0), c.defocus_sigma)
        if c.exposure > 0:
            kernel = motion_blur_kernel(*(self._image_speed(camera, lens) * c.exposure))
            if kernel is not None:
                image = cv2.filter2D(image, -1, kernel, borderType=cv2.BORDER_REPLICATE)
        if not c.gain.is_identity:
            image *= float(c.gain.draw(rng))
        if c.noise_sigma > 0:
            image += rng.normal(0.0, c.noise_sigma, image.shape).astype(np.float32)
        return np.clip(np.rint(image), 0, 255).astype(np.uint8)

    def _image_speed(self, camera: str, lens: TrueLens) -> np.ndarray:
        """Image velocity ``(du/dt, dv/dt)`` of a static point on the optical axis at ``blur_depth`` [px/s]."""
        velocity = np.zeros(6)
        mujoco.mj_objectVelocity(
            self._model, self._data, mujoco.mjtObj.mjOBJ_CAMERA, self._ids[camera], velocity, 1
        )  # [angular, linear] in the camera's (MuJoCo) frame
        w = MUJOCO_TO_OPENCV @ velocity[:3]
        v = MUJOCO_TO_OPENCV @ velocity[3:]
        z = self.config.blur_depth
        # a static point P seen from a moving camera: dP/dt = -v - w x P, at P = (0, 0, z)
        return np.array([lens.K[0, 0] * (-v[0] / z - w[1]), lens.K[1, 1] * (-v[1] / z + w[0])])

    def get_state(self) -> dict[str, Any]:
        return {name: rng.bit_generator.state for name, rng in self._rngs.items()}

    def set_state(self, state: dict[str, Any]) -> None:
        for name, rng_state in state.items():
            self._rngs[name].bit_generator.state = rng_state

    def close(self) -> None:
        """Give the renderer back to the process's pool (the next session of this spec draws with it)."""
        if self._renderer is not None:
            renderer_pool.release(self._renderer)
            self._renderer = None
