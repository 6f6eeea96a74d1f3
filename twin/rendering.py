"""Headless RGB rendering of a MuJoCo model's named cameras, with their pinhole intrinsics and poses.

OpenGL backend
--------------
The :class:`Renderer` owns its OpenGL context and picks the backend from the ``MUJOCO_GL`` environment
variable, as MuJoCo does: ``egl`` (the default when ``MUJOCO_GL`` is unset: headless, on the GPU or
on the CPU through Mesa's llvmpipe), ``osmesa`` (pure software, needs ``libosmesa6``) or ``glfw`` (needs
a display). It creates the context itself instead of going through ``mujoco.Renderer``, so it works
whatever ``MUJOCO_GL`` was when ``mujoco`` was first imported (unset, MuJoCo would have chosen GLFW,
which fails without a display).

There is no automatic fallback from EGL to OSMesa within one process, on purpose. PyOpenGL fixes its
platform at its first import (``PYOPENGL_PLATFORM``, which ``mujoco.egl`` sets to ``egl``), and once
``libEGL`` is loaded MuJoCo's GL loader finds it before ``libOSMesa`` and fails with "gladLoadGL error"
on an OSMesa context (measured with mujoco 3.17.0). So when EGL fails, :class:`Renderer` raises a
:class:`~twin.errors.RenderingError` telling to start the process with ``MUJOCO_GL=osmesa``.

Shadows are off unless asked for (:attr:`RenderConfig.shadows`): on the CPU they make a frame 3-4x
slower (DESIGN.md) and ArUco detection does not need them. Without them the render context's shadow map is
1x1 instead of the model's 4096x4096 (the model keeps its setting): it is never drawn into, and its
allocation was 40-120 ms of the ~0.2 s a render context took to make on llvmpipe.

A renderer can draw another model whose render resources are the same (:func:`render_resources_key`: the
meshes, textures and materials a render context uploads, and the visual settings it copies) with
:meth:`Renderer.rebind`; :mod:`twin.renderer_pool` keeps renderers across the sessions of a process that way.

Camera conventions
------------------
MuJoCo cameras look along their -z axis with y up. :meth:`Renderer.camera_pose_in_world` returns the
OpenCV camera frame (x right, y down, z forward) so that poses from ``cv2.solvePnP`` compose with it
directly: ``T_world_marker = T_world_camera @ T_camera_marker``. :meth:`Renderer.camera_intrinsics`
uses OpenCV's pixel convention (integer coordinates at pixel centres), which puts the principal point
of a centred camera at ``((W - 1) / 2, (H - 1) / 2)``, not ``(W / 2, H / 2)``.
"""

from __future__ import annotations

import atexit
import contextlib
import hashlib
import importlib
import math
import os
import threading
import warnings
import weakref
from dataclasses import dataclass

import mujoco
import numpy as np

from puzzlebox.twin.errors import RenderingError, UnknownCamera

__all__ = [
    "GL_BACKENDS",
    "MUJOCO_TO_OPENCV",
    "RenderConfig",
    "Renderer",
    "camera_pose_in_world",
    "gl_backend",
    "pinhole_intrinsics",
    "presentation_look",
    "render_resources_key",
]

GL_BACKENDS: tuple[str, ...] = ("egl", "osmesa", "glfw")
"""OpenGL backends a :class:`Renderer` can use, as spelled in ``MUJOCO_GL``."""

# MUJOCO_GL values that MuJoCo itself accepts to mean "its default": here the default is headless EGL.
_DEFAULT_VALUES = ("", "enable", "enabled", "on", "true", "1")
_DISABLED_VALUES = ("disable", "disabled", "off", "false", "0")
MUJOCO_TO_OPENCV = np.diag([1.0, -1.0, -1.0])
"""OpenCV's camera frame from MuJoCo's: same x, y and z flipped (MuJoCo looks along -z with y up)."""


@dataclass(frozen=True)
class RenderConfig:
    """How a :class:`Renderer` draws its images."""

    width: int = 640
    """Image width [px]."""
    height: int = 480
    """Image height [px]."""
    shadows: bool = False
    """Draw shadows of lights that cast them. Off by default: 3-4x slower per frame on the CPU."""
    max_geoms: int = 10_000
    """Capacity of the abstract scene [geoms]; geoms beyond it are silently not drawn."""

    def __post_init__(self) -> None:
        if self.width < 1 or self.height < 1:
            raise ValueError(f"image size must be positive [px], got {self.width}x{self.height}")
        if self.max_geoms < 1:
            raise ValueError(f"max_geoms must be positive, got {self.max_geoms}")


def gl_backend() -> str:
    """The OpenGL backend a new :class:`Renderer` uses, from ``MUJOCO_GL`` (``egl`` when unset).

    Raises:
        RenderingError: if ``MUJOCO_GL`` disables rendering or names a backend this platform lacks.
    """
    value = os.environ.get("MUJOCO_GL", "").strip().lower()
    if value in GL_BACKENDS:
        return value
    if value in _DEFAULT_VALUES:
        # mujoco.egl refuses to load once PYOPENGL_PLATFORM names another platform; follow it then.
        pyopengl = os.environ.get("PYOPENGL_PLATFORM", "").strip().lower()
        return pyopengl if pyopengl in ("egl", "osmesa") else "egl"
    if value in _DISABLED_VALUES:
        raise RenderingError(f"rendering is disabled by MUJOCO_GL={value!r}; use one of {list(GL_BACKENDS)}")
    raise RenderingError(f"MUJOCO_GL={value!r} is not a backend a Renderer can use; use one of {list(GL_BACKENDS)}")


def _context_hint(backend: str) -> str:
    if backend == "egl":
        return (
            "EGL needs libegl1 and a driver (libegl-mesa0 and libgl1-mesa-dri on the CPU). Without one, install "
            "libosmesa6 and start the process with MUJOCO_GL=osmesa: once libEGL is loaded, MuJoCo cannot switch "
            "to OSMesa in the same process."
        )
    if backend == "osmesa":
        return "OSMesa needs libosmesa6; or start the process with MUJOCO_GL=egl."
    return "GLFW needs a display; headless, start the process with MUJOCO_GL=egl (or osmesa)."


def _create_gl_context(backend: str, width: int, height: int):
    """A current OpenGL context of the given backend, from MuJoCo's own context classes."""
    try:
        module = importlib.import_module(f"mujoco.{backend}")
        gl_context = module.GLContext(width, height)
    except Exception as exc:  # ImportError, RuntimeError, EGLError, GLFWError...: all mean "no context"
        raise RenderingError(
            f"cannot create an OpenGL context with MUJOCO_GL={backend} ({type(exc).__name__}: {exc}). "
            + _context_hint(backend)
        ) from exc
    try:
        gl_context.make_current()
    except Exception as exc:
        _free_gl_context(gl_context)
        raise RenderingError(
            f"cannot make the {backend} OpenGL context current ({type(exc).__name__}: {exc}). " + _context_hint(backend)
        ) from exc
    return gl_context


def _free_gl_context(gl_context) -> None:
    try:
        gl_context.free()
    finally:
        # MuJoCo's context classes free themselves again in __del__; after a failed free (e.g. EGL already
        # terminated) that second attempt would print a traceback at interpreter exit.
        if hasattr(gl_context, "_context"):
            gl_context._context = None


# Renderers still open at interpreter exit are closed by an atexit hook registered after the first GL
# context exists: atexit runs hooks last-in first-out, so ours runs before the eglTerminate that
# mujoco.egl registers when it first initialises the display, and closing still finds EGL alive.
_open_renderers: weakref.WeakSet[Renderer] = weakref.WeakSet()
_atexit_lock = threading.Lock()
_atexit_registered = False


def _close_open_renderers() -> None:
    for renderer in list(_open_renderers):
        with contextlib.suppress(Exception):
            renderer.close()


def _track(renderer: Renderer) -> None:
    global _atexit_registered
    with _atexit_lock:
        if not _atexit_registered:
            atexit.register(_close_open_renderers)
            _atexit_registered = True
        _open_renderers.add(renderer)


PRESENTATION_RGBA = {"table": (0.64, 0.63, 0.60, 1.0), "floor": (0.36, 0.37, 0.40, 1.0)}
"""Colours of the scene's geoms that pictures for people show muted (the white table washed the overview out)."""
PRESENTATION_LIGHTS = {"headlight_ambient": 0.22, "headlight_diffuse": 0.32, "headlight_specular": 0.08,
                       "light_diffuse": 0.42, "light_specular": 0.1}  # fmt: skip
"""Lights [0-1] of pictures for people: the scene's (ambient 0.25, headlight 0.3 with specular 0.5, key light 0.55)
turned down, specular most, so that the lid, the plates and the markers keep their contrast (the mean luminance of
the lid's top face in the overview 220+ of 255 before, ~170 after)."""


def presentation_look(model: mujoco.MjModel) -> None:
    """Set on ``model`` the colours and lights of pictures made for people — the rollout video, the gallery —
    (:data:`PRESENTATION_RGBA`, :data:`PRESENTATION_LIGHTS`). Never on a model whose cameras the pipeline reads:
    what it senses would change."""
    for name, rgba in PRESENTATION_RGBA.items():
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
        if geom >= 0:
            model.geom_rgba[geom] = rgba
    lights = PRESENTATION_LIGHTS
    headlight = model.vis.headlight
    headlight.ambient[:] = lights["headlight_ambient"]
    headlight.diffuse[:] = lights["headlight_diffuse"]
    headlight.specular[:] = lights["headlight_specular"]
    model.light_diffuse[:] = lights["light_diffuse"]
    model.light_specular[:] = lights["light_specular"]


def pinhole_intrinsics(model: mujoco.MjModel, cam: int, width: int, height: int) -> np.ndarray:
    """Pinhole matrix ``K`` [px] of camera ``cam`` of ``model`` rendered at ``width`` x ``height``
    (see :meth:`Renderer.camera_intrinsics`; needs no OpenGL context)."""
    sensor = model.cam_sensorsize[cam]
    if sensor[1] > 0:
        # The frustum mjv_updateScene builds on the near plane n (read back from MjvGLCamera with
        # mujoco 3.17.0): centre n/fx * px, half-width n/fx * sx/2, bottom n/fy * (-sy/2 - py),
        # top n/fy * (sy/2 - py), with focal lengths (fx, fy) and principal offsets (px, py) from
        # cam_intrinsic and the sensor size (sx, sy), all in sensor units [m].
        focal_x, focal_y, principal_x, principal_y = model.cam_intrinsic[cam]
        fx = width * focal_x / sensor[0]
        fy = height * focal_y / sensor[1]
        cx = width * (0.5 - principal_x / sensor[0]) - 0.5
        cy = height * (0.5 - principal_y / sensor[1]) - 0.5
    else:
        fy = 0.5 * height / math.tan(math.radians(model.cam_fovy[cam]) / 2)
        fx = fy
        cx, cy = (width - 1) / 2, (height - 1) / 2
    return np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])


# What mjr_makeContext uploads or copies from a model: mesh, texture, height-field, skin and flex buffers, the
# materials' texture bindings (MjrContext.mat_texid...) and a display list per plane geom (its size and
# material). The visual settings it copies follow below.
_RESOURCE_PREFIXES = ("mesh_", "tex_", "hfield_", "skin_", "flex_", "mat_")
_GEOM_RESOURCES = ("geom_type", "geom_size", "geom_dataid", "geom_matid")


def _bound_visual(model: mujoco.MjModel, config: RenderConfig) -> tuple[int, int, int]:
    """The offscreen buffer size [px] and shadow map size [texels] a renderer sets on the model it draws."""
    global_ = model.vis.global_
    shadowsize = int(model.vis.quality.shadowsize) if config.shadows else 1  # unused: see the module docstring
    return max(int(global_.offwidth), config.width), max(int(global_.offheight), config.height), shadowsize


def render_resources_key(model: mujoco.MjModel, config: RenderConfig) -> str:
    """A fingerprint of everything a render context built for ``model`` holds, bar what depends on the
    model's extent (fog and shadow clipping, which :meth:`Renderer.rebind` sets): two models with the same key
    render identically through one context. SHA-256 over the resource arrays (~1 ms for the paper scenes)."""
    digest = hashlib.sha256(repr(config).encode())
    for name in sorted(dir(model)):
        if name.startswith(_RESOURCE_PREFIXES) or name in _GEOM_RESOURCES:
            value = getattr(model, name)
            if isinstance(value, np.ndarray):
                digest.update(f"{name}{value.shape}{value.dtype}".encode())
                digest.update(np.ascontiguousarray(value).tobytes())
    vis = model.vis
    offwidth, offheight, shadowsize = _bound_visual(model, config)
    settings = (
        vis.global_.linewidth, offwidth, offheight, shadowsize, vis.quality.offsamples, vis.quality.numslices,
        vis.quality.numstacks, vis.quality.numquads, vis.map.shadowscale, tuple(vis.rgba.fog),
    )  # fmt: skip
    digest.update(repr(settings).encode())
    return digest.hexdigest()


def camera_pose_in_world(data: mujoco.MjData, cam: int) -> np.ndarray:
    """``T_world_camera`` of camera ``cam`` in state ``data``, OpenCV camera frame (see
    :meth:`Renderer.camera_pose_in_world`; ``data`` needs its camera poses computed: ``mj_forward``, or
    ``mj_kinematics`` then ``mj_camlight``)."""
    transform = np.eye(4)
    transform[:3, :3] = data.cam_xmat[cam].reshape(3, 3) @ MUJOCO_TO_OPENCV
    transform[:3, 3] = data.cam_xpos[cam]
    return transform


class Renderer:
    """Renders RGB images of a model's named cameras offscreen, headless.

    Owns an OpenGL context (see the module docstring for the backend); close it with :meth:`close` or
    use the renderer as a context manager. A renderer is meant for one thread at a time.

    Example::

        with Renderer(model, RenderConfig(width=640, height=480)) as renderer:
            image = renderer.render(data, "overview")  # (480, 640, 3) uint8
            K = renderer.camera_intrinsics("overview")
            T_world_camera = renderer.camera_pose_in_world(data, "overview")
    """

    def __init__(self, model: mujoco.MjModel, config: RenderConfig = RenderConfig()) -> None:  # noqa: B008
        """Create the OpenGL context and MuJoCo's render context for ``model``.

        If the model's offscreen buffer (``<visual><global offwidth offheight>``, 640x480 by default) is
        smaller than the configured image, it is enlarged on ``model``: a visual-only setting.

        Raises:
            RenderingError: if no OpenGL context can be created with the backend in ``MUJOCO_GL``.
        """
        # Set first so that close() and __del__ work whatever fails below.
        self._gl_context = None
        self._mjr_context: mujoco.MjrContext | None = None
        self._config = config
        self._backend = gl_backend()
        self.resources_key = render_resources_key(model, config)
        """:func:`render_resources_key` of the models this renderer can draw."""
        self._bind(model)
        self._option = mujoco.MjvOption()
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self._rect = mujoco.MjrRect(0, 0, config.width, config.height)
        self._pixels = np.empty((config.height, config.width, 3), dtype=np.uint8)

        self._gl_context = _create_gl_context(self._backend, config.width, config.height)
        try:
            # The smallest font scale: no text is drawn, and the font textures cost memory per context. The shadow
            # map's size is read at creation only: set for it, then the model's own again (a renderer with shadows
            # made later from the same model gets the model's map).
            quality = model.vis.quality
            shadowsize, quality.shadowsize = quality.shadowsize, _bound_visual(model, config)[2]
            try:
                self._mjr_context = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_50)
            finally:
                quality.shadowsize = shadowsize
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._mjr_context)
        except Exception as exc:  # mujoco.FatalError: "gladLoadGL error", "no OpenGL platform library"...
            self.close()
            raise RenderingError(
                f"MuJoCo cannot render with the {self._backend} OpenGL context ({type(exc).__name__}: {exc}). "
                + _context_hint(self._backend)
            ) from exc
        _track(self)

    def _bind(self, model: mujoco.MjModel) -> None:
        """Draw ``model`` from now on: its cameras, a fresh abstract scene, its visual settings adjusted."""
        config = self._config
        self._model = model
        names = (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(model.ncam))
        self._camera_ids = {name: i for i, name in enumerate(names) if name}
        global_ = model.vis.global_
        global_.offwidth, global_.offheight, _ = _bound_visual(model, config)
        self._scene = mujoco.MjvScene(model, maxgeom=config.max_geoms)
        self._scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = config.shadows

    def rebind(self, model: mujoco.MjModel) -> None:
        """Draw ``model`` instead, through the same OpenGL and render contexts: frames are then the same as a
        new renderer of ``model`` would draw (the context's extent-dependent settings are set from it).

        Raises:
            RenderingError: if the renderer is closed, or ``model``'s render resources differ (another key).
        """
        if self._mjr_context is None:
            raise RenderingError("rebind() called on a closed Renderer; create a new one")
        if render_resources_key(model, self._config) != self.resources_key:
            raise RenderingError("rebind() needs a model with the same meshes, textures, materials and visual settings")
        self._bind(model)
        # mjr_makeContext copies these from the model's extent (float32 in the context, as here)
        extent, vis_map = model.stat.extent, model.vis.map
        self._mjr_context.fogStart = extent * vis_map.fogstart
        self._mjr_context.fogEnd = extent * vis_map.fogend
        self._mjr_context.shadowClip = extent * vis_map.shadowclip

    @property
    def model(self) -> mujoco.MjModel:
        """The model this renderer draws."""
        return self._model

    @property
    def config(self) -> RenderConfig:
        """The configuration this renderer was created with."""
        return self._config

    @property
    def backend(self) -> str:
        """The OpenGL backend in use: ``egl``, ``osmesa`` or ``glfw``."""
        return self._backend

    @property
    def camera_names(self) -> tuple[str, ...]:
        """Names of the model's cameras, in model order."""
        return tuple(self._camera_ids)

    @property
    def closed(self) -> bool:
        """Whether :meth:`close` has freed the OpenGL resources."""
        return self._mjr_context is None

    def camera_id(self, camera: str) -> int:
        """Index of a named camera in the model.

        Raises:
            UnknownCamera: if the model has no camera of that name; the message lists those it has.
        """
        try:
            return self._camera_ids[camera]
        except KeyError:
            raise UnknownCamera(camera, self._camera_ids) from None

    def render(self, data: mujoco.MjData, camera: str) -> np.ndarray:
        """Draw the scene in state ``data`` as seen by a named camera.

        ``data`` must hold positions computed for its state (``mj_forward``, ``mj_kinematics`` or a step).

        Returns:
            A new ``uint8`` array of shape ``(height, width, 3)``, RGB, row 0 at the top of the image.

        Raises:
            UnknownCamera: if the model has no camera of that name.
            RenderingError: if the renderer is closed.
        """
        self._camera.fixedcamid = self.camera_id(camera)
        if self._mjr_context is None or self._gl_context is None:  # (closed together)
            raise RenderingError("render() called on a closed Renderer; create a new one")
        mujoco.mjv_updateScene(
            self._model, data, self._option, None, self._camera, mujoco.mjtCatBit.mjCAT_ALL, self._scene
        )
        self._gl_context.make_current()
        mujoco.mjr_render(self._rect, self._scene, self._mjr_context)
        mujoco.mjr_readPixels(self._pixels, None, self._rect, self._mjr_context)
        # OpenGL's rows run bottom-up.
        return np.flipud(self._pixels).copy()

    def camera_intrinsics(self, camera: str) -> np.ndarray:
        """Pinhole matrix ``K`` of a named camera at the configured image size, OpenCV convention.

        For a camera given by ``fovy``: ``fx = fy = (H / 2) / tan(fovy / 2)``, ``cx = (W - 1) / 2``,
        ``cy = (H - 1) / 2`` (pixel centres at integer coordinates; MuJoCo keeps pixels square by
        widening the horizontal field of view with the aspect ratio). For a camera given by
        ``sensorsize``/``focal``/``principal`` the frustum MuJoCo builds from them is used; pixels are then
        square only if the image has the sensor's aspect ratio. The images carry no lens distortion.

        Returns:
            ``(3, 3)`` float array [px].

        Raises:
            UnknownCamera: if the model has no camera of that name.
            RenderingError: for an orthographic camera, which has no pinhole model.
        """
        cam = self.camera_id(camera)
        if self._model.cam_projection[cam] == mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC:
            raise RenderingError(f"camera {camera!r} is orthographic: it has no pinhole intrinsics")
        return pinhole_intrinsics(self._model, cam, self._config.width, self._config.height)

    def camera_pose_in_world(self, data: mujoco.MjData, camera: str) -> np.ndarray:
        """``T_world_camera`` of a named camera in state ``data``, OpenCV camera frame (x right, y down,
        z forward).

        ``data`` must hold positions computed for its state (``mj_forward`` or ``mj_kinematics``).

        Returns:
            ``(4, 4)`` homogeneous transform, translation [m].

        Raises:
            UnknownCamera: if the model has no camera of that name.
        """
        return camera_pose_in_world(data, self.camera_id(camera))

    def close(self) -> None:
        """Free the OpenGL resources. Idempotent; the renderer cannot render afterwards."""
        mjr_context, gl_context = self._mjr_context, self._gl_context
        self._mjr_context = None
        self._gl_context = None
        _open_renderers.discard(self)
        try:
            if mjr_context is not None and gl_context is not None:
                # MuJoCo's render context deletes GL objects: its own context must be current.
                gl_context.make_current()
                mjr_context.free()
        finally:
            if gl_context is not None:
                _free_gl_context(gl_context)

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def __del__(self) -> None:
        if getattr(self, "_gl_context", None) is None:
            return
        # Like an unclosed file: say so (hidden by default), then free without ever raising from __del__.
        with contextlib.suppress(Exception):
            warnings.warn(f"unclosed {self!r}; call close() or use it as a context manager", ResourceWarning, 2)
        with contextlib.suppress(Exception):
            self.close()

    def __repr__(self) -> str:
        state = "closed" if self.closed else self._backend
        return f"Renderer({self._config.width}x{self._config.height}, {state}, cameras={list(self.camera_names)})"
