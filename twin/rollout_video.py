"""The multi-view rollout video of a twin trial: three views tiled, a caption strip and a live force plot.

Each frame is drawn from a :class:`RolloutFrame` — the simulator's joint positions at that instant, the looks the
pipeline took since the previous frame (its own detections, never detected again here, and the state at each
capture), the caption of the action under way, the part being tried and the recent wrist force — so frames are
taken at a fixed simulated rate (:attr:`RolloutConfig.period`: ten per simulated second) while the trial runs, and
drawn in a **second process** (:class:`BackgroundRollout`): on the 2-core machines this project runs on, the trial
keeps one core and the drawing takes the other. Layout (:meth:`RolloutConfig.layout`, 1296 x 794 px by default):

- ``three-quarter`` (left, 864 x 648): a perspective camera on the far side of the box from the robot, aimed at
  the box where it was placed and as close as holds the whole box (its shell corners, footprints and handle tops)
  with :attr:`RolloutConfig.three_quarter_margin` to spare, whatever the placement; low enough that the arm, which
  reaches over the box from the robot's side, seldom hides the lid;
- ``overview`` (top right, 432 x 324): the cell's fixed camera cropped to the box (an off-axis frustum: the crop is
  rendered at the panel's resolution, not enlarged), with the markers the pipeline detected in it outlined;
- ``wrist`` (bottom right): the camera on the gripper, with the markers the pipeline detected in it.

A look's detections are drawn on **one frame only**, the first after its capture, and that frame's panel of the
camera is drawn from the state at the capture (:attr:`Look.qpos`): the outlines lie on the image that produced
them, never on a later one after the camera or the parts moved. The part being tried is tinted
(:data:`HIGHLIGHT_RGB`) and named in the three-quarter view.

The video has its own look, set on its own copy of the model (the trial's model, and so what the pipeline senses,
is never touched): :func:`twin.rendering.presentation_look`'s muted table and floor and softer lights, and a backdrop
(boxes drawn around the cell, never in the segmentation the evaluations read) instead of a black void, so that the
lid, the plates and the markers stay readable: the mean luminance of the lid's top face in every view that shows
it lies in :attr:`RolloutConfig.lid_luminance` (60-200 of 255, :meth:`RolloutDrawer.lid_luminance`; the trial's
own lights gave the overview's lid 220+).

Below the views, a caption strip (action number, the component tried and its kind, the outcome as sensed and
— in evaluation — the truth, the agent's exploration weight ``w`` and the chosen component's ``Q_info`` and
``Q_exploit``) and the wrist force [N] over the last :attr:`RolloutConfig.plot_window` seconds. The MP4 is
H.264 in yuv420p (:class:`twin.video.VideoWriter`, written atomically): browsers play it. Beside it,
``<name>.frames.json`` (:func:`frames_path`) indexes every frame: its simulated time, caption, the part tried and
the cameras whose looks it shows.

Rendering: MuJoCo's offscreen renderer without shadows or multisampling (on the CPU a shadowed, multisampled frame
costs 10x a plain one), on the arm's links simplified for the video (:attr:`RolloutConfig.mesh_cell`,
:func:`twin.mesh_lod.coarsen_meshes`: the xArm's 91 k triangles cost every view the same whether seen or not; the
gripper, seen from centimetres, keeps all of its). A frame whose bodies did not move since the
previous one by more than :attr:`RolloutConfig.still` (under half a pixel) reuses its views. The drawing process
renders with two llvmpipe threads and hands frames to x264 from a thread of its own (:class:`_Encoder`).

Cost (paper-test-0 under ``realistic``: ~98 s simulated, ~980 frames; 2026-11-28, a loaded 2-core machine): ~44 ms
of CPU a frame (drawing ~33, x264 ~10; it was ~49 before the changes above, on the same machine at the same time),
~7x the trial's own CPU. Twice the trial's wall time would leave ~16 ms of CPU a frame on two cores for rendering
~1 Mpx and encoding it: out of reach for a CPU renderer at this size and rate (a GPU renders it in ~1 ms).
"""

from __future__ import annotations

import contextlib
import copy
import json
import math
import multiprocessing
import os
import queue
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import mujoco
import numpy as np

from puzzlebox.models.atomic import PublishedOnExit, write_text_atomically
from puzzlebox.models.scene import BOX
from puzzlebox.twin.errors import VideoError
from puzzlebox.twin.mesh_lod import coarsen_meshes
from puzzlebox.twin.rendering import pinhole_intrinsics, presentation_look
from puzzlebox.twin.video import X264_PRESETS, VideoWriter

VIEWS = ("three-quarter", "overview", "wrist")
"""The tiled views: the large one on the left, then the right column top to bottom."""
LID_TOP = (-2, int(mujoco.mjtObj.mjOBJ_UNKNOWN))
"""What segmentation rendering reports for the lid's top face in :meth:`RolloutDrawer.lid_luminance` (object id,
type): a label no model object has."""
ABORT = "abort"
"""Sent instead of a frame: the trial failed, the drawing process discards its video."""
HIGHLIGHT_RGB = (1.0, 0.78, 0.1)
"""Colour [0-1] the part being tried is tinted towards (its plate, handle and lock features; not its marker)."""
DRAW_THREADS = 2
"""llvmpipe's rasterizer threads in the drawing process (``LP_NUM_THREADS``)."""
BACKDROP_RGB = ((0.58, 0.63, 0.70), (0.46, 0.50, 0.56), (0.30, 0.31, 0.34))
"""Colours [0-1] of the backdrop's walls, ceiling and floor (lit as well as glowing: they look paler)."""


@dataclass(frozen=True)
class RolloutConfig:
    """Size, rate and framing of the rollout video."""

    period: float = 0.1
    """Simulated time between frames [s]: ten frames per simulated second (a toggle of ~12 s gets ~120)."""
    fps: float = 30.0
    """Playback rate [frames/s]: with ``period`` 0.1 s, three times real time."""
    main_size: tuple[int, int] = (864, 648)
    """Width and height of the three-quarter view [px]."""
    side_size: tuple[int, int] = (432, 324)
    """Width and height of the overview and wrist views, stacked right of it [px]."""
    caption_height: int = 56
    """Height of the caption strip [px]."""
    plot_height: int = 90
    """Height of the force plot [px]."""
    plot_window: float = 15.0
    """Simulated time the force plot spans [s]."""
    plot_max_force: float = 60.0
    """Top of the force plot [N] (the primitives' force limit)."""
    three_quarter_elevation: float = -35.0
    """Elevation of the three-quarter camera [deg] (negative: looking down)."""
    three_quarter_side: float = 40.0
    """Azimuth of the three-quarter camera away from the robot-box line [deg] (nominally: of this side, its mirror
    and 15 deg either way, the one that shows the box the largest)."""
    three_quarter_margin: float = 1.08
    """Image extent over the box's extent on the tighter side of the three-quarter view [-] (the box fills 25-45 %
    of the view, whatever the placement)."""
    overview_margin: float = 1.15
    """Crop extent over the box's extent on the tighter side of the overview's crop [-]."""
    lid_luminance: tuple[float, float] = (60.0, 200.0)
    """The band the mean luminance (Rec. 601 luma, 0-255) of the lid's pixels keeps in every view: neither
    washed out nor sunk in shade (:meth:`RolloutDrawer.lid_luminance`)."""
    mesh_cell: float = 0.004
    """Grid the video's copy of the arm's meshes is simplified on [m] (:func:`twin.mesh_lod.coarsen_meshes`; 0: as
    modelled; the gripper is kept whole): 4 mm takes the xArm from 91 k to 70 k triangles (the links from 42 k
    to 21 k)."""
    preset: str = "veryfast"
    """x264's preset (:data:`twin.video.X264_PRESETS`): its CPU per frame against the file's size."""
    still: float = 2e-4
    """Largest move of any body since the previous frame [m] (its origin, or a point 10 cm from it as it turns)
    under which a frame reuses the previous frame's views: 0.2 mm is under half a pixel in every view."""

    def __post_init__(self) -> None:
        if not self.period > 0 or not self.fps > 0:
            raise VideoError(f"period and fps must be positive, got {self.period} s and {self.fps} frames/s")
        for name in ("main_size", "side_size"):
            if any(v < 16 or v % 2 for v in getattr(self, name)):
                raise VideoError(f"{name} must be even and at least 16 px, got {getattr(self, name)}")
        if self.mesh_cell < 0:
            raise VideoError(f"mesh_cell must be 0 (meshes as modelled) or positive [m], got {self.mesh_cell}")
        if self.preset not in X264_PRESETS:
            raise VideoError(f"unknown x264 preset {self.preset!r}; presets: {list(X264_PRESETS)}")
        if self.three_quarter_margin < 1 or self.overview_margin < 1:
            raise VideoError("the margins must be at least 1 (the box in view)")

    def layout(self) -> dict[str, tuple[int, int, int, int]]:
        """Where each view lies in a frame: ``(x, y, width, height)`` [px]."""
        (mw, mh), (sw, sh) = self.main_size, self.side_size
        return {"three-quarter": (0, 0, mw, mh), "overview": (mw, 0, sw, sh), "wrist": (mw, sh, sw, sh)}

    @property
    def views_height(self) -> int:
        """Height of the views' block [px]."""
        return max(self.main_size[1], 2 * self.side_size[1])

    @property
    def frame_size(self) -> tuple[int, int]:
        """Width and height of a whole frame: views, caption strip, force plot [px]."""
        return self.main_size[0] + self.side_size[0], self.views_height + self.caption_height + self.plot_height


@dataclass(frozen=True)
class Caption:
    """What the caption strip says of the action under way."""

    action: int = 0
    """1-based number of the action under way (0: the survey before the first)."""
    component: str = ""
    """The component tried (name and kind)."""
    sensed: str = ""
    """The outcome as the robot sensed it (empty while the try runs)."""
    truth: str = ""
    """Evaluation only: whether the component really moved."""
    weight_info: float | None = None
    """The agent's exploration weight ``w`` of this decision [-]."""
    q_info: float | None = None
    """The chosen component's information value [nats]."""
    q_exploit: float | None = None
    """The chosen component's exploitation value [-]."""
    phase: str = ""
    """What the arm is doing (surveying, approaching, actuating, ...)."""
    previous: str = ""
    """How the action before this one ended (e.g. ``action 1 door-0: moved (truth: moved)``): the frames
    after an action ends are the next action's, or the trial's last frame."""

    def ending(self) -> str:
        """How this caption's action ended, as the next caption's :attr:`previous` says it ("" before it ended)."""
        if not self.action or not self.sensed:
            return ""
        truth = f" (truth: {self.truth})" if self.truth else ""
        return f"action {self.action} {self.component}: {self.sensed}{truth}"


@dataclass(frozen=True)
class Look:
    """One look the pipeline took through a camera: when, what it detected, and the state it looked at."""

    time: float
    """Capture time [s]."""
    found: list[tuple[int, np.ndarray]]
    """What it detected: (marker id, (4, 2) corners [px at the camera's capture size])."""
    qpos: np.ndarray | None = None
    """The simulator's joint positions at the capture (None: unknown; the frame's are drawn)."""


@dataclass(frozen=True)
class RolloutFrame:
    """One frame's state: everything needed to draw it, small enough to pass between processes."""

    time: float
    """Simulated time [s]."""
    qpos: np.ndarray
    """The simulator's joint positions."""
    caption: Caption
    looks: dict[str, Look] = field(default_factory=dict)
    """Camera name -> the pipeline's latest look through it since the previous frame (none: no outline)."""
    forces: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    """``(n, 2)``: simulated time [s] and wrist force magnitude [N] over the plot window."""
    highlight: str = ""
    """Spec name of the part being tried ("" between tries)."""


@dataclass(frozen=True)
class SceneCameras:
    """Where the views look from and at: the model's camera names, the box, its parts."""

    overview: str
    wrist: str
    lid_centre: tuple[float, float, float]
    """The lid's top centre in the world [m]."""
    lid_diagonal: float
    """The lid's diagonal [m]."""
    capture_size: tuple[int, int]
    """Width and height of the pipeline's camera images [px] (its detections are in these pixels)."""
    box_points: tuple[tuple[float, float, float], ...] = ()
    """World points [m] the views frame: the shell's corners, each part's footprint on the lid and its handle's
    top (none: the lid's centre and diagonal frame it)."""
    parts: dict[str, str] = field(default_factory=dict)
    """Spec name of each part -> its body's name in the model (the part tried is highlighted)."""


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec. 601 luma (0-255) of RGB pixels."""
    return np.asarray(rgb, dtype=float) @ np.array([0.299, 0.587, 0.114])


class RolloutDrawer:
    """Draws :class:`RolloutFrame` s of one model (see the module docstring). Works on its own copy of the model."""

    def __init__(self, model: mujoco.MjModel, cameras: SceneCameras, config: RolloutConfig) -> None:
        self.model = model = copy.deepcopy(model)  # the video's look is set on it: never on the trial's model
        self.cameras, self.config = cameras, config
        self.data = mujoco.MjData(model)
        presentation_look(model)
        width = max(config.main_size[0], config.side_size[0])
        height = max(config.main_size[1], config.side_size[1])
        model.vis.quality.offsamples = 0  # the context's buffers are made here: no multisampling
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, height)
        if config.mesh_cell > 0:  # before the renderers upload the meshes
            # the gripper keeps every triangle: the wrist camera sees it from centimetres, the three-quarter view
            # from closest, and its thin shell folds on itself when clustered
            carried = _meshes_in_subtree(model, int(model.camera(cameras.wrist).bodyid[0]))
            coarsen_meshes(model, config.mesh_cell, [m for m in range(model.nmesh) if m not in carried])
        side = mujoco.Renderer(model, config.side_size[1], config.side_size[0])  # a context: ~100 MB
        self.renderers = {
            "three-quarter": mujoco.Renderer(model, config.main_size[1], config.main_size[0]),
            "overview": side,
            "wrist": side,
        }
        """Each view's renderer (the overview and the wrist view share one)."""
        self.option = mujoco.MjvOption()
        self.option.geomgroup[3] = 0  # the lock mechanisms (their pins would show as grey rods)
        self._box_geoms = np.flatnonzero(
            np.isin(model.geom_bodyid, [b for b in range(model.nbody) if model.body(b).name.startswith(BOX)])
        )
        self._lid_geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{BOX}shell")
        self._parts = {name: self._part_geoms(body) for name, body in cameras.parts.items()}
        self._rgba = model.geom_rgba.copy()
        self.pose(model.qpos0)
        points = self._framed_points()
        self.free = self._three_quarter(points)
        self.crop = self._overview_crop(points)
        """The overview's crop ``(u0, v0, u1, v1)``: pixel edges in the capture image (0..width, 0..height)."""
        self._backdrop = _backdrop(points.mean(axis=0))
        self._last: tuple[np.ndarray, str, dict[str, np.ndarray]] | None = None

    # -- framing ------------------------------------------------------------------------------------------------

    def _framed_points(self) -> np.ndarray:
        if self.cameras.box_points:
            return np.asarray(self.cameras.box_points, dtype=float).reshape(-1, 3)
        centre, half = np.asarray(self.cameras.lid_centre), self.cameras.lid_diagonal / 2
        return centre + np.array([[sx * half, sy * half, 0.0] for sx in (-1, 1) for sy in (-1, 1)])

    def _three_quarter(self, points: np.ndarray) -> mujoco.MjvCamera:
        """A free camera beyond the box from the robot, aimed at the middle of ``points``, as close as holds them:
        of the headings :attr:`RolloutConfig.three_quarter_side` and 15 deg either side of it, to either side of
        the robot-box line, the one where the box's outline covers the most of the view."""
        side = self.config.three_quarter_side
        sides = [side, -side, side - 15, 15 - side, side + 15, -side - 15]
        cameras = [self._framed_camera(points, s) for s in sides]
        covers = [self._cover(camera, points) for camera in cameras]
        return cameras[int(np.argmax(np.round(covers, 2)))]  # the first of near ties: the nominal side first

    def _framed_camera(self, points: np.ndarray, side: float) -> mujoco.MjvCamera:
        c = self.config
        camera = mujoco.MjvCamera()
        camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        target = (points.min(axis=0) + points.max(axis=0)) / 2
        robot_to_box = math.degrees(math.atan2(target[1], target[0]))  # the robot base is the world origin
        # a free camera looks along its azimuth: looking back at the robot, it stands beyond the box
        camera.azimuth = robot_to_box + 180.0 + side
        camera.elevation = c.three_quarter_elevation
        forward, right, up = _free_axes(camera)
        relative = points - target
        depth = relative @ forward
        k_v = math.tan(math.radians(self.model.vis.global_.fovy) / 2) / c.three_quarter_margin
        k_h = k_v * c.main_size[0] / c.main_size[1]
        # each point within the frustum: |x| <= k (D + depth) per image axis (x across, depth along the view)
        needed = np.maximum(np.abs(relative @ right) / k_h, np.abs(relative @ up) / k_v) - depth
        camera.distance = max(float(needed.max()), 0.05 + float((-depth).max()))
        camera.lookat[:] = target
        return camera

    def _cover(self, camera: mujoco.MjvCamera, points: np.ndarray) -> float:
        """The share of the three-quarter view inside the outline (convex hull) of ``points``."""
        uv = np.array([self._free_pixel(p, camera) for p in points], dtype=np.float32)
        w, h = self.config.main_size
        return float(cv2.contourArea(cv2.convexHull(uv))) / (w * h)

    def _project(self, camera: str, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates (OpenCV: centres at integers) of world ``points`` in a fixed camera's capture image."""
        cam = self.model.camera(camera).id
        width, height = self.cameras.capture_size
        K = pinhole_intrinsics(self.model, cam, width, height)
        R, origin = self.data.cam_xmat[cam].reshape(3, 3), self.data.cam_xpos[cam]
        local = (points - origin) @ R  # MuJoCo's camera frame: x right, y up, looking along -z
        depth = np.maximum(-local[:, 2], 1e-6)
        return np.column_stack([K[0, 2] + K[0, 0] * local[:, 0] / depth, K[1, 2] - K[1, 1] * local[:, 1] / depth])

    def _overview_crop(self, points: np.ndarray) -> tuple[float, float, float, float]:
        """The part of the overview image around the box, with the panel's aspect, inside the image."""
        width, height = self.cameras.capture_size
        uv = self._project(self.cameras.overview, points) + 0.5  # pixel edges
        centre = (uv.min(axis=0) + uv.max(axis=0)) / 2
        aspect = self.config.side_size[0] / self.config.side_size[1]
        span = (uv.max(axis=0) - uv.min(axis=0)) * self.config.overview_margin
        w = min(max(span[0], span[1] * aspect, 0.25 * width), width, height * aspect)
        h = w / aspect
        u0 = float(np.clip(centre[0] - w / 2, 0.0, width - w))
        v0 = float(np.clip(centre[1] - h / 2, 0.0, height - h))
        return float(u0), float(v0), float(u0 + w), float(v0 + h)

    def _crop_frustum(self) -> None:
        """Set the overview's frustum (after ``update_scene``) to :attr:`crop`."""
        width, height = self.cameras.capture_size
        K = pinhole_intrinsics(self.model, self.model.camera(self.cameras.overview).id, width, height)
        u0, v0, u1, v1 = self.crop
        scene = self.renderers["overview"].scene
        for k in range(2):
            gl = scene.camera[k]
            near = gl.frustum_near
            left, right = (near * (u - 0.5 - K[0, 2]) / K[0, 0] for u in (u0, u1))
            top, bottom = (-near * (v - 0.5 - K[1, 2]) / K[1, 1] for v in (v0, v1))
            gl.frustum_center, gl.frustum_width = (left + right) / 2, (right - left) / 2
            gl.frustum_top, gl.frustum_bottom = top, bottom

    def to_panel(self, view: str, corners: np.ndarray) -> np.ndarray:
        """Capture pixels (OpenCV centres) of ``view``'s camera -> pixels of its panel."""
        pw, ph = self.config.side_size
        width, height = self.cameras.capture_size
        u0, v0, u1, v1 = self.crop if view == "overview" else (0.0, 0.0, float(width), float(height))
        points = np.asarray(corners, dtype=float).reshape(-1, 2) + 0.5
        return np.column_stack([(points[:, 0] - u0) * pw / (u1 - u0), (points[:, 1] - v0) * ph / (v1 - v0)]) - 0.5

    # -- rendering ----------------------------------------------------------------------------------------------

    def _part_geoms(self, body: str) -> np.ndarray:
        """The drawn geoms of a part's subtree (not its marker: it stays readable)."""
        root = self.model.body(body).id
        bodies = [b for b in range(self.model.nbody) if _in_subtree(self.model, b, root)]
        geoms = np.flatnonzero(np.isin(self.model.geom_bodyid, bodies) & (self.model.geom_group < 3))
        return np.array([g for g in geoms if not self.model.geom(g).name.endswith(":marker")], dtype=int)

    def pose(self, qpos: np.ndarray) -> None:
        """Put the model at the joint positions ``qpos`` (kinematics only: what the views show)."""
        self.data.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def part_geoms(self, part: str) -> np.ndarray:
        """The geoms :meth:`highlight` tints for ``part`` (a spec name): its drawn geoms but its marker."""
        return self._parts.get(part, np.zeros(0, dtype=int))

    def highlight(self, part: str) -> None:
        """Tint ``part`` (a spec name; "" for none) from now on."""
        rgba = self._rgba.copy()
        geoms = self._parts.get(part)
        if geoms is not None and len(geoms):
            rgba[geoms, :3] = 0.35 * rgba[geoms, :3] + 0.65 * np.array(HIGHLIGHT_RGB)
        self.model.geom_rgba[:] = rgba

    def render_view(
        self, view: str, qpos: np.ndarray | None = None, segmentation: bool = False, lid_top: bool = False
    ) -> np.ndarray:
        """One view (at the joint positions ``qpos`` if given, else where :meth:`pose` left the model): RGB, or
        with ``segmentation`` the ``(h, w, 2)`` object ids and types of MuJoCo's segmentation rendering; with
        ``lid_top`` too, the lid's top face as :data:`LID_TOP` (a film laid on it, under everything that stands
        on the lid)."""
        if qpos is not None:
            self.pose(qpos)
        camera = {"overview": self.cameras.overview, "wrist": self.cameras.wrist}.get(view, self.free)
        renderer = self.renderers[view]
        if segmentation:
            renderer.enable_segmentation_rendering()
        try:
            renderer.update_scene(self.data, camera, self.option)
            renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
            renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
            if view == "overview":
                self._crop_frustum()
            if not segmentation:
                _add_geoms(renderer.scene, self._backdrop)
            elif lid_top:
                _add_geoms(renderer.scene, [self._lid_film()], label=LID_TOP)
            return renderer.render()
        finally:
            if segmentation:
                renderer.disable_segmentation_rendering()

    def box_visibility(self, qpos: np.ndarray, arm_group: int = 1) -> dict[str, float]:
        """Evaluation: per view, the fraction of the box's pixels (lid and parts: geoms of bodies named
        ``box/...``) that are seen with the arm as it stands at ``qpos``, against the same view with the arm's
        visual geoms (group ``arm_group``) hidden: 1.0 unoccluded, 0.0 hidden. A view that shows no box at all
        without the arm (the wrist camera looking elsewhere) counts 0.0."""
        pixels = self.box_pixels(qpos, arm_group)
        return {view: seen / alone if alone else 0.0 for view, (seen, alone) in pixels.items()}

    def box_pixels(self, qpos: np.ndarray, arm_group: int = 1) -> dict[str, tuple[int, int]]:
        """Evaluation: per view, the box's pixels seen with the arm at ``qpos`` and with the arm hidden
        (:meth:`box_visibility`)."""
        self.pose(qpos)
        return {
            view: (int(self.geom_mask(view, self._box_geoms).sum()), int(self.box_mask(view, arm_group).sum()))
            for view in VIEWS
        }

    def box_mask(self, view: str, arm_group: int = 1) -> np.ndarray:
        """Evaluation: the pixels of ``view`` the box covers with the arm hidden (at the current pose)."""
        self.option.geomgroup[arm_group] = 0
        try:
            return self.geom_mask(view, self._box_geoms)
        finally:
            self.option.geomgroup[arm_group] = 1

    def lid_luminance(self, qpos: np.ndarray, least: int = 200) -> dict[str, float | None]:
        """Evaluation: per view, the mean luminance (0-255) of the pixels showing the lid's top face — the face
        the plates and markers stand on, found by MuJoCo's segmentation (:meth:`render_view` ``lid_top``) — as
        the video draws it; None for a view that shows fewer than ``least`` of them."""
        self.pose(qpos)
        out: dict[str, float | None] = {}
        for view in VIEWS:
            ids = self.render_view(view, segmentation=True, lid_top=True)
            mask = (ids[..., 0] == LID_TOP[0]) & (ids[..., 1] == LID_TOP[1])
            out[view] = float(luminance(self.render_view(view)[mask]).mean()) if mask.sum() >= least else None
        return out

    def _lid_film(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """A box 0.1 mm thick on the lid's top face (size, position, orientation, rgba)."""
        g = self._lid_geom
        size, rotation = self.model.geom_size[g], self.data.geom_xmat[g].reshape(3, 3)
        film = 5e-5
        centre = self.data.geom_xpos[g] + rotation @ [0.0, 0.0, size[2] + film]
        return np.array([size[0], size[1], film]), centre, rotation.ravel(), np.ones(4)

    def geom_mask(self, view: str, geoms: np.ndarray) -> np.ndarray:
        """Evaluation: the pixels of ``view`` (at the current pose) that show one of ``geoms`` (segmentation)."""
        ids = self.render_view(view, segmentation=True)
        chosen = np.zeros(self.model.ngeom + 1, dtype=bool)  # its last entry stands for anything not a geom
        chosen[np.asarray(geoms, dtype=int)] = True
        # (an int: numpy compares an array with MuJoCo's enum object element by element, 100x slower)
        return chosen[np.where(ids[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM), ids[..., 0], -1)]

    def draw(self, frame: RolloutFrame) -> np.ndarray:
        """The tiled frame: views, caption strip, force plot."""
        c = self.config
        width, total = c.frame_size
        out = np.empty((total, width, 3), dtype=np.uint8)
        out[: c.views_height] = 40
        last = self._last
        self.pose(frame.qpos)
        bodies = np.concatenate([self.data.xpos, 0.1 * self.data.xmat], axis=1)
        still = (
            last is not None and not frame.looks and frame.highlight == last[1]
            and float(np.abs(bodies - last[0]).max()) <= c.still
        )  # fmt: skip
        if still and last is not None:
            tiles = last[2]
        else:
            self.highlight(frame.highlight)
            tiles = {"three-quarter": self.render_view("three-quarter")}
            self._label_part(tiles["three-quarter"], frame.highlight)
            for view in ("overview", "wrist"):
                camera = self.cameras.overview if view == "overview" else self.cameras.wrist
                look = frame.looks.get(camera)
                if look is not None and look.qpos is not None:
                    self.pose(look.qpos)  # the state the look saw: its outlines lie on its image
                tiles[view] = image = self.render_view(view)
                if look is not None:
                    self._outline(view, image, look)
                    self.pose(frame.qpos)
            for view, image in tiles.items():
                _label(image, view if view != "overview" else "overview (cropped to the box)")
            # a frame with outlines is never reused: they belong to it alone
            self._last = None if frame.looks else (bodies, frame.highlight, tiles)
        for view, (x, y, w, h) in c.layout().items():
            out[y : y + h, x : x + w] = tiles[view]
        top = c.views_height
        out[top : top + c.caption_height] = self._caption(frame, width)
        out[top + c.caption_height :] = self._plot(frame, width)
        return out

    def _label_part(self, image: np.ndarray, part: str) -> None:
        """Name the part being tried beside its handle in the three-quarter view."""
        geoms = self._parts.get(part)
        if geoms is None or not len(geoms):
            return
        point = self.data.geom_xpos[geoms].mean(axis=0)
        u, v = self._free_pixel(point)
        if not (0 <= u < image.shape[1] and 0 <= v < image.shape[0]):
            return
        text = f"trying {part}"
        (tw, th), _ = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, 0.6, 1)
        x, y = int(np.clip(u + 24, 2, image.shape[1] - tw - 6)), int(np.clip(v - 30, th + 6, image.shape[0] - 4))
        cv2.line(image, (int(u), int(v)), (x, y - th // 2), (255, 200, 25), 2, cv2.LINE_AA)
        cv2.rectangle(image, (x - 4, y - th - 5), (x + tw + 4, y + 5), (30, 30, 30), -1)
        cv2.putText(image, text, (x, y), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 210, 60), 1, cv2.LINE_AA)

    def _free_pixel(self, point: np.ndarray, camera: mujoco.MjvCamera | None = None) -> tuple[float, float]:
        """Pixel of a world point in the three-quarter view (of ``camera``, default :attr:`free`)."""
        camera = camera or self.free
        w, h = self.config.main_size
        forward, right, up = _free_axes(camera)
        relative = np.asarray(point) - (np.asarray(camera.lookat) - camera.distance * forward)
        depth = max(float(relative @ forward), 1e-6)
        focal = 0.5 * h / math.tan(math.radians(self.model.vis.global_.fovy) / 2)
        return (w - 1) / 2 + focal * float(relative @ right) / depth, (h - 1) / 2 - focal * float(relative @ up) / depth

    def _outline(self, view: str, image: np.ndarray, look: Look) -> None:
        """Outline one look's detections on the panel of its camera, and say how many it found."""
        for marker_id, corners in look.found:
            points = np.round(self.to_panel(view, corners)).astype(np.int32)
            cv2.polylines(image, [points], True, (0, 230, 0), 2, cv2.LINE_AA)
            x, y = points[0]
            cv2.putText(image, str(marker_id), (int(x), int(y) - 3), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (0, 160, 0), 1,
                        cv2.LINE_AA)  # fmt: skip
        text = f"look: {len(look.found)} marker(s)"
        h = image.shape[0]
        cv2.rectangle(image, (0, h - 22), (10 + 8 * len(text), h), (0, 110, 0), -1)
        cv2.putText(image, text, (5, h - 7), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1, cv2.LINE_AA)

    def _caption(self, frame: RolloutFrame, width: int) -> np.ndarray:
        c = frame.caption
        strip = np.full((self.config.caption_height, width, 3), 24, dtype=np.uint8)
        head = f"t = {frame.time:6.1f} s   action {c.action}" if c.action else f"t = {frame.time:6.1f} s   survey"
        if c.component:
            head += f": {c.component}"
        if c.phase:
            head += f"   ({c.phase})"
        cv2.putText(strip, head, (8, 21), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (240, 240, 240), 1, cv2.LINE_AA)
        values = []
        if c.weight_info is not None:
            values.append(f"w = {c.weight_info:.2f}")
        if c.q_info is not None and c.q_exploit is not None:
            values.append(f"Q_info = {c.q_info:.3f}  Q_exploit = {c.q_exploit:.3f}")
        if c.sensed:
            values.append(f"sensed: {c.sensed}" + (f"   truth: {c.truth}" if c.truth else ""))
        elif c.previous:
            values.append(f"last: {c.previous}")
        colour = (120, 220, 120) if c.sensed == "moved" else (240, 200, 120) if c.sensed else (200, 200, 200)
        cv2.putText(strip, "   ".join(values), (8, 46), cv2.FONT_HERSHEY_SIMPLEX, 0.55, colour, 1, cv2.LINE_AA)
        return strip

    def _plot(self, frame: RolloutFrame, width: int) -> np.ndarray:
        c = self.config
        plot = np.full((c.plot_height, width, 3), 250, dtype=np.uint8)
        top, bottom, left, right = 8, c.plot_height - 14, 40, width - 8
        cv2.rectangle(plot, (left, top), (right, bottom), (200, 200, 200), 1)
        for newtons in (0, 30, 60):
            y = int(bottom - (bottom - top) * newtons / c.plot_max_force)
            cv2.putText(plot, f"{newtons}", (6, y + 4), cv2.FONT_HERSHEY_SIMPLEX, 0.35, (90, 90, 90), 1)
        cv2.putText(plot, "wrist force [N]", (left + 4, c.plot_height - 3), cv2.FONT_HERSHEY_SIMPLEX, 0.35,
                    (90, 90, 90), 1)  # fmt: skip
        forces = np.asarray(frame.forces, dtype=float).reshape(-1, 2)
        if len(forces) >= 2:
            start = frame.time - c.plot_window
            x = left + (right - left) * (forces[:, 0] - start) / c.plot_window
            y = bottom - (bottom - top) * np.clip(forces[:, 1], 0, c.plot_max_force) / c.plot_max_force
            points = np.stack([x, y], axis=1).astype(np.int32)
            cv2.polylines(plot, [points], False, (200, 60, 40), 1, cv2.LINE_AA)
        return plot

    def close(self) -> None:
        for renderer in {id(r): r for r in self.renderers.values()}.values():
            renderer.close()


def _label(image: np.ndarray, text: str) -> None:
    cv2.rectangle(image, (0, 0), (10 + 9 * len(text), 24), (30, 30, 30), -1)
    cv2.putText(image, text, (5, 17), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1, cv2.LINE_AA)


def _free_axes(camera: mujoco.MjvCamera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forward, right and up unit vectors of a free camera (world frame)."""
    az, el = math.radians(camera.azimuth), math.radians(camera.elevation)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def _in_subtree(model: mujoco.MjModel, body: int, root: int) -> bool:
    while body > 0:
        if body == root:
            return True
        body = int(model.body_parentid[body])
    return root == 0


def _meshes_in_subtree(model: mujoco.MjModel, root: int) -> set[int]:
    """The meshes drawn by geoms of ``root``'s subtree (bodies that move with it)."""
    geoms = [g for g in range(model.ngeom) if _in_subtree(model, int(model.geom_bodyid[g]), root)]
    return {int(model.geom_dataid[g]) for g in geoms if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH}


def _backdrop(centre: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """Four walls, a ceiling and a floor around the cell, 3 m from the box (size, position, orientation, rgba of
    each box geom); the floor lies just under the scene's own, which ends 2 m from the robot."""
    x, y, _ = centre
    reach, floor, ceiling, thick = 3.0, -0.76, 2.5, 0.05
    mid, half = (floor + ceiling) / 2, (ceiling - floor) / 2
    walls, sky, ground = (np.array([*rgb, 1.0]) for rgb in BACKDROP_RGB)
    level = np.eye(3).ravel()
    return [
        (np.array([thick, reach, half]), np.array([x + reach, y, mid]), level, walls),
        (np.array([thick, reach, half]), np.array([x - reach, y, mid]), level, walls),
        (np.array([reach, thick, half]), np.array([x, y + reach, mid]), level, walls),
        (np.array([reach, thick, half]), np.array([x, y - reach, mid]), level, walls),
        (np.array([reach, reach, thick]), np.array([x, y, ceiling + thick]), level, sky),
        (np.array([reach, reach, thick]), np.array([x, y, floor - thick]), level, ground),
    ]


def _add_geoms(
    scene: mujoco.MjvScene,
    boxes: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
    label: tuple[int, int] | None = None,
) -> None:
    """Append ``boxes`` (size, position, orientation, rgba) to an updated scene while it has room: glowing (their
    colour shows unlit too), or with ``label`` (object id, type) reported by segmentation rendering."""
    for size, pos, mat, rgba in boxes:
        if scene.ngeom >= scene.maxgeom:
            return
        geom = scene.geoms[scene.ngeom]
        mujoco.mjv_initGeom(geom, mujoco.mjtGeom.mjGEOM_BOX, size, pos, mat, rgba.astype(np.float32))
        geom.emission = 0.6
        if label is not None:
            geom.objid, geom.objtype = label
            geom.segid = scene.ngeom
        scene.ngeom += 1


def _serve(inbox, outbox) -> None:
    """The drawing process: one video per job, for as long as the trial's process lives. A job is
    ``(model_path, cameras, config, path)`` then its frames then ``None`` (publish) or :data:`ABORT` (discard);
    ``None`` instead of a job ends the process. A failed job ends it too (its parent starts another)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    # Two rasterizer threads: while the trial runs they share its second core with x264; once it has ended (the
    # drawing, ~30 ms a frame on the CPU, lags far behind the trial) they take both cores.
    os.environ["LP_NUM_THREADS"] = str(DRAW_THREADS)
    current: dict[str, Any] = {"model": None, "video": None}
    _watch_parent(multiprocessing.parent_process(), current)
    while (job := inbox.get()) is not None:
        try:
            outbox.put(("ok", _draw_video(*job, inbox=inbox, current=current)))
        except BaseException as err:  # noqa: BLE001 (reported to the parent, which raises it)
            outbox.put(("error", f"{type(err).__name__}: {err}"))
            return


def _draw_video(model_path: str, cameras: SceneCameras, config: RolloutConfig, path: str, inbox, current) -> int:
    """One job of :func:`_serve`: draw every frame that arrives, write the MP4 and its index; the frame count."""
    current["model"] = model_path
    try:
        model = mujoco.MjModel.from_binary_path(model_path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(model_path)
    drawer = RolloutDrawer(model, cameras, config)
    index = []
    try:
        # no faststart: ffmpeg's second pass reopens the file by name, and would bring back one a dying trial's
        # watcher (_watch_parent) removed
        with VideoWriter(path, fps=config.fps, preset=config.preset, faststart=False) as video, \
                _Encoder(video) as encoder:  # fmt: skip
            current["video"] = video
            while (frame := inbox.get()) is not None:
                if isinstance(frame, str):  # ABORT: the trial failed; publish nothing
                    raise VideoError("aborted by the trial")
                encoder.append(drawer.draw(frame))
                c = frame.caption
                index.append({"time": round(frame.time, 6), "action": c.action, "component": c.component,
                              "sensed": c.sensed, "truth": c.truth, "phase": c.phase, "previous": c.previous,
                              "highlight": frame.highlight,
                              "looks": {_view_of(cameras, camera): round(look.time, 6)
                                        for camera, look in frame.looks.items()}})  # fmt: skip
            frames = video.frame_count
    finally:
        current["video"] = None
        drawer.close()
    sidecar = {"video": Path(path).name, "period_s": config.period, "fps": config.fps,
               "frame_size": list(config.frame_size), "layout": {v: list(r) for v, r in config.layout().items()},
               "overview_crop": [round(v, 2) for v in drawer.crop], "frames": index}  # fmt: skip
    write_text_atomically(frames_path(path), json.dumps(sidecar, indent=1))
    return frames


class _Encoder:
    """Hands frames to a :class:`VideoWriter` from a thread of its own: writing a 3 MB frame into ffmpeg's pipe
    waits on ffmpeg (the GIL released), and the next frame is drawn meanwhile. Leaving the ``with`` block waits
    for the frames handed over; an error in the thread comes back from the next :meth:`append` or at the end."""

    def __init__(self, video: VideoWriter, depth: int = 4) -> None:
        self._video = video
        self._frames: queue.Queue[np.ndarray | None] = queue.Queue(maxsize=depth)
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="rollout-encoder", daemon=True)

    def __enter__(self) -> _Encoder:
        self._thread.start()
        return self

    def _run(self) -> None:
        while (frame := self._frames.get()) is not None:
            if self._error is None:
                try:
                    self._video.append(frame)
                except BaseException as err:  # noqa: BLE001 (raised again in the drawing thread)
                    self._error = err

    def append(self, frame: np.ndarray) -> None:
        if self._error is not None:
            raise self._error
        self._frames.put(frame)

    def __exit__(self, exc_type, exc, tb) -> None:
        self._frames.put(None)
        self._thread.join()
        if self._error is not None and exc_type is None:
            raise self._error


def _view_of(cameras: SceneCameras, camera: str) -> str:
    return {cameras.overview: "overview", cameras.wrist: "wrist"}.get(camera, camera)


def _watch_parent(parent: Any, current: dict[str, Any]) -> None:
    """If the trial's process dies (a SIGKILL), discard the partial video and the model file and exit: the frame
    queue never closes (this process holds a copy of its writing end), and a frame cut in half by the kill leaves
    a read waiting for ever."""
    if parent is None:
        return

    def watch() -> None:
        parent.join()  # returns when the parent's sentinel closes: it exited or was killed
        # remove the files, then exit at once: an abort() here would wait on ffmpeg while the main thread runs on
        # (ffmpeg, its input closed by the exit, finishes into the unlinked file and exits)
        video = current["video"]
        for path in (current["model"], None if video is None else video.temporary_path):
            if path is not None:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(path)
        os._exit(1)

    threading.Thread(target=watch, name="rollout-parent-watch", daemon=True).start()


class _Server:
    """The drawing process and its queues, kept across the videos of one trial process (a worker running trial
    after trial pays its start-up, ~0.7 s, once)."""

    def __init__(self) -> None:
        context = multiprocessing.get_context("spawn")  # a fresh process: no GL context inherited
        self.inbox, self.outbox = context.Queue(maxsize=512), context.Queue()
        self.process = context.Process(target=_serve, args=(self.inbox, self.outbox), daemon=True)
        self.process.start()

    def alive(self) -> bool:
        return self.process.is_alive()

    def stop(self) -> None:
        with contextlib.suppress(Exception):
            self.inbox.cancel_join_thread()
        if self.process.is_alive():
            self.process.terminate()
        self.process.join(timeout=10)


_server: _Server | None = None


def _drawing_server() -> _Server:
    global _server
    if _server is None or not _server.alive():
        _server = _Server()
    return _server


def frames_path(video: str | os.PathLike[str]) -> Path:
    """The frame index written beside a rollout video: ``<name>.frames.json`` (per frame: simulated time [s],
    action number, component, sensed outcome and truth once it ended, phase, how the previous action ended)."""
    video = Path(video)
    return video.with_name(f"{video.stem}.frames.json")


def _save_model(model: mujoco.MjModel, directory: Path) -> str:
    """``model`` as an MJB file in ``directory`` (the trial's model as it is, its reality profile's changes
    included; 17 MB with its textures: a file, not a pipe, so the trial does not wait while it is read)."""
    handle, name = tempfile.mkstemp(prefix=".rollout-model.", suffix=".mjb", dir=directory)
    os.close(handle)
    mujoco.mj_saveModel(model, name, None)
    return name


class BackgroundRollout(PublishedOnExit):
    """Draws and writes a rollout video in a second process while the trial runs (one process per trial process,
    kept for its next videos).

    ``add(frame)`` hands a frame over (it returns at once); ``close()`` waits for the last frames, publishes
    the MP4 and raises :class:`VideoError` if the drawing failed; ``abort()`` (or leaving a ``with`` block by an
    exception) discards the video and leaves no file.
    """

    def __init__(self, path: str | os.PathLike[str], model: mujoco.MjModel, cameras: SceneCameras,
                 config: RolloutConfig | None = None) -> None:  # fmt: skip
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise VideoError(f"cannot write {self.path}: directory {self.path.parent} does not exist")
        self.config = config or RolloutConfig()
        self._server = _drawing_server()
        self._model_file = _save_model(model, self.path.parent)  # the process reads and removes it
        self._server.inbox.put((self._model_file, cameras, self.config, str(self.path)))
        self.frames_sent = 0

    def add(self, frame: RolloutFrame) -> None:
        """Hand ``frame`` over; :class:`VideoError` if the drawing process has died (checked every 16 frames)."""
        if self.frames_sent % 16 == 0 and not self._server.alive():
            self._dead()
        self._server.inbox.put(frame)
        self.frames_sent += 1

    def _dead(self) -> None:
        self._server.stop()
        self._remove_model_file()
        raise VideoError(f"the rollout drawing process died (exit code {self._server.process.exitcode})")

    def close(self, timeout: float = 600.0) -> int:
        """Finish the video; returns its frame count."""
        self._server.inbox.put(None)
        status, value = self._answer(timeout)
        self._remove_model_file()
        if status != "ok":
            raise VideoError(f"drawing the rollout video failed: {value}")
        return int(value)

    def _answer(self, timeout: float) -> tuple[str, Any]:
        deadline = time.monotonic() + timeout
        while True:
            try:
                return self._server.outbox.get(timeout=1.0)
            except queue.Empty:
                if not self._server.alive():  # died without a word (killed, or could not start)
                    self._dead()
                if time.monotonic() > deadline:
                    self._server.stop()
                    self._remove_model_file()
                    raise VideoError(f"the rollout drawing process gave no answer in {timeout:.0f} s") from None

    def abort(self) -> None:
        """Discard the video and leave no file (the process drops its partial video; stopped if it hangs)."""
        with contextlib.suppress(Exception):
            self._server.inbox.put(ABORT, timeout=1.0)
            self._answer(30.0)  # the job's "error: aborted": the process ends (the next video starts another)
        self._server.stop()
        self._remove_model_file()

    def _remove_model_file(self) -> None:
        with contextlib.suppress(FileNotFoundError):  # the process removed it, unless it died first
            os.unlink(self._model_file)


class FrameCollector:
    """Stands in for :class:`BackgroundRollout` (same constructor and methods) and keeps the frames' states in
    memory instead of drawing them: for evaluations that look at every frame (``bench.py``'s box visibility).
    The latest one made is :attr:`FrameCollector.last`, with the model and cameras it was given."""

    last: FrameCollector | None = None

    def __init__(self, path: str | os.PathLike[str], model: mujoco.MjModel, cameras: SceneCameras,
                 config: RolloutConfig | None = None) -> None:  # fmt: skip
        self.model, self.cameras, self.config = model, cameras, config or RolloutConfig()
        self.frames: list[RolloutFrame] = []
        FrameCollector.last = self

    def add(self, frame: RolloutFrame) -> None:
        self.frames.append(frame)

    def close(self) -> int:
        return len(self.frames)

    def abort(self) -> None:
        pass

    def __enter__(self) -> FrameCollector:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        pass
