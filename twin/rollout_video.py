"""The multi-view rollout video of a twin trial: three views tiled, a caption strip and a live force plot.

Each frame is drawn from a :class:`RolloutFrame` — the simulator's joint positions at that instant, the
pipeline's own latest marker detections per camera (never detected again here), the caption of the action
under way and the recent wrist force — so frames are taken at a fixed simulated rate
(:attr:`RolloutConfig.period`) while the trial runs, and drawn in a **second process**
(:class:`BackgroundRollout`): on the 2-core machines this project runs on, the trial keeps one core and
the drawing takes the other. Views, left to right:

- ``overview``: the cell's fixed camera, with the markers the pipeline detected in it outlined (for
  :attr:`RolloutConfig.detection_hold` after the look);
- ``three-quarter``: a perspective camera on the far side of the box from the robot, low enough that the arm,
  which reaches over the box from the robot's side, seldom hides the lid;
- ``wrist``: the camera on the gripper, with the markers the pipeline last detected in it.

Below the views, a caption strip (action number, the component tried and its kind, the outcome as sensed and
— in evaluation — the truth, the agent's exploration weight ``w`` and the chosen component's ``Q_info`` and
``Q_exploit``) and the wrist force [N] over the last :attr:`RolloutConfig.plot_window` seconds. The MP4 is
H.264 in yuv420p (:class:`twin.video.VideoWriter`, written atomically): browsers play it. Beside it,
``<name>.frames.json`` (:func:`frames_path`) indexes every frame: its simulated time and caption.

Rendering: MuJoCo's offscreen renderer without shadows or multisampling (on the CPU a shadowed,
multisampled frame costs 10x a plain one), views of ``view_size`` pixels.
"""

from __future__ import annotations

import contextlib
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
from puzzlebox.twin.video import VideoWriter

VIEWS = ("overview", "three-quarter", "wrist")
"""The tiled views, left to right."""
ABORT = "abort"
"""Sent instead of a frame: the trial failed, the drawing process discards its video."""


@dataclass(frozen=True)
class RolloutConfig:
    """Size and rate of the rollout video."""

    period: float = 1.0
    """Simulated time between frames [s]: one frame per simulated second (a toggle of ~12 s gets ~12). A frame
    costs ~15 ms of a core (three renders of ~4 ms: the arm's meshes, whatever the size); drawn beside the
    trial on the other core, a video at this rate made a 2.9 s ``trial.py`` run 3.9 s (x1.34), at 2 frames per
    simulated second x2.1."""
    fps: float = 5.0
    """Playback rate [frames/s]: with ``period`` 1 s, five times real time."""
    view_size: tuple[int, int] = (320, 240)
    """Width and height of each view [px]."""
    caption_height: int = 56
    """Height of the caption strip [px]."""
    plot_height: int = 90
    """Height of the force plot [px]."""
    plot_window: float = 15.0
    """Simulated time the force plot spans [s]."""
    detection_hold: float = 1.5
    """How long after a look its detections stay drawn [s]: the wrist camera moves on, parts move."""
    plot_max_force: float = 60.0
    """Top of the force plot [N] (the primitives' force limit)."""
    three_quarter_elevation: float = -28.0
    """Elevation of the three-quarter camera [deg] (negative: looking down)."""
    three_quarter_side: float = 40.0
    """Azimuth of the three-quarter camera away from the robot-box line [deg]."""
    three_quarter_distance: float = 1.7
    """Distance of the three-quarter camera from the lid centre, in lid diagonals [-]."""

    def __post_init__(self) -> None:
        if not self.period > 0 or not self.fps > 0:
            raise VideoError(f"period and fps must be positive, got {self.period} s and {self.fps} frames/s")
        if any(v < 16 or v % 2 for v in self.view_size):
            raise VideoError(f"view_size must be even and at least 16 px, got {self.view_size}")


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
class RolloutFrame:
    """One frame's state: everything needed to draw it, small enough to pass between processes."""

    time: float
    """Simulated time [s]."""
    qpos: np.ndarray
    """The simulator's joint positions."""
    caption: Caption
    detections: dict[str, tuple[float, list[tuple[int, np.ndarray]]]] = field(default_factory=dict)
    """Camera name -> the pipeline's latest look through it: its capture time [s] and what it detected, (marker
    id, (4, 2) corners [px at the camera's capture size])."""
    forces: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    """``(n, 2)``: simulated time [s] and wrist force magnitude [N] over the plot window."""


@dataclass(frozen=True)
class SceneCameras:
    """Where the views look from: the model's camera names and the three-quarter camera's target."""

    overview: str
    wrist: str
    lid_centre: tuple[float, float, float]
    """The lid's top centre in the world [m]."""
    lid_diagonal: float
    """The lid's diagonal [m]."""
    capture_size: tuple[int, int]
    """Width and height of the pipeline's camera images [px] (its detections are in these pixels)."""


class RolloutDrawer:
    """Draws :class:`RolloutFrame` s of one model (see the module docstring)."""

    def __init__(self, model: mujoco.MjModel, cameras: SceneCameras, config: RolloutConfig) -> None:
        self.model, self.cameras, self.config = model, cameras, config
        self.data = mujoco.MjData(model)
        width, height = config.view_size
        samples = model.vis.quality.offsamples
        model.vis.quality.offsamples = 0  # the context's buffers are made here: no multisampling
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, height)
        try:
            self.renderer = mujoco.Renderer(model, height, width)
        finally:
            model.vis.quality.offsamples = samples
        self.option = mujoco.MjvOption()
        self.free = mujoco.MjvCamera()
        self.free.type = mujoco.mjtCamera.mjCAMERA_FREE
        cx, cy, cz = cameras.lid_centre
        self.free.lookat[:] = (cx, cy, cz)
        self.free.distance = config.three_quarter_distance * cameras.lid_diagonal
        robot_to_box = math.degrees(math.atan2(cy, cx))  # the robot base is the world origin
        # a free camera looks along its azimuth: looking back at the robot, it stands beyond the box
        self.free.azimuth = robot_to_box + 180.0 + config.three_quarter_side
        self.free.elevation = config.three_quarter_elevation

    def pose(self, qpos: np.ndarray) -> None:
        """Put the model at the joint positions ``qpos`` (kinematics only: what the views show)."""
        self.data.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def render_view(self, view: str, qpos: np.ndarray | None = None, segmentation: bool = False) -> np.ndarray:
        """One view (at the joint positions ``qpos`` if given, else where :meth:`pose` left the model): RGB, or
        with ``segmentation`` the ``(h, w, 2)`` object ids and types of MuJoCo's segmentation rendering."""
        if qpos is not None:
            self.pose(qpos)
        camera = {"overview": self.cameras.overview, "wrist": self.cameras.wrist}.get(view, self.free)
        if segmentation:
            self.renderer.enable_segmentation_rendering()
        try:
            self.renderer.update_scene(self.data, camera, self.option)
            self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
            self.renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
            return self.renderer.render().copy()
        finally:
            if segmentation:
                self.renderer.disable_segmentation_rendering()

    def box_visibility(self, qpos: np.ndarray, box_prefix: str = BOX, arm_group: int = 1) -> dict[str, float]:
        """Evaluation: per view, the fraction of the box's pixels (lid and components: geoms of bodies named
        ``box_prefix...``) that are seen with the arm as it stands at ``qpos``, against the same view with the
        arm's visual geoms (group ``arm_group``) hidden: 1.0 unoccluded, 0.0 hidden. A view that shows no
        box at all without the arm (the wrist camera looking elsewhere) counts 0.0."""
        if not hasattr(self, "_box_geoms"):
            bodies = [b for b in range(self.model.nbody) if self.model.body(b).name.startswith(box_prefix)]
            self._box_geoms = np.flatnonzero(np.isin(self.model.geom_bodyid, bodies))
        self.pose(qpos)
        fractions = {}
        for view in VIEWS:
            seen = self._box_pixels(view)
            self.option.geomgroup[arm_group] = 0
            try:
                alone = self._box_pixels(view)
            finally:
                self.option.geomgroup[arm_group] = 1
            fractions[view] = seen / alone if alone else 0.0
        return fractions

    def _box_pixels(self, view: str) -> int:
        ids = self.render_view(view, segmentation=True)
        geoms = ids[..., 0][ids[..., 1] == mujoco.mjtObj.mjOBJ_GEOM]
        return int(np.isin(geoms, self._box_geoms).sum())

    def draw(self, frame: RolloutFrame) -> np.ndarray:
        """The tiled frame: views, caption strip, force plot."""
        c = self.config
        width, height = c.view_size
        tiles = []
        self.pose(frame.qpos)
        for view in VIEWS:
            image = np.ascontiguousarray(self.render_view(view))
            camera = {"overview": self.cameras.overview, "wrist": self.cameras.wrist}.get(view)
            if camera is not None:
                captured, found = frame.detections.get(camera, (-math.inf, []))
                if frame.time - captured <= c.detection_hold:
                    self._outline(image, found)
            cv2.rectangle(image, (0, 0), (8 + 9 * len(view), 22), (30, 30, 30), -1)
            cv2.putText(image, view, (5, 16), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1, cv2.LINE_AA)
            tiles.append(image)
        views = np.concatenate(tiles, axis=1)
        strip = self._caption(frame, views.shape[1])
        plot = self._plot(frame, views.shape[1])
        return np.concatenate([views, strip, plot], axis=0)

    def _outline(self, image: np.ndarray, detections: list[tuple[int, np.ndarray]]) -> None:
        """Outline the pipeline's detections, scaled from the capture size to the view size."""
        sx = self.config.view_size[0] / self.cameras.capture_size[0]
        sy = self.config.view_size[1] / self.cameras.capture_size[1]
        for marker_id, corners in detections:
            points = (np.asarray(corners, dtype=float) * (sx, sy)).astype(np.int32)
            cv2.polylines(image, [points], True, (0, 210, 0), 1, cv2.LINE_AA)
            x, y = points[0]
            cv2.putText(image, str(marker_id), (int(x), int(y) - 2), cv2.FONT_HERSHEY_SIMPLEX, 0.35, (0, 150, 0), 1)

    def _caption(self, frame: RolloutFrame, width: int) -> np.ndarray:
        c = frame.caption
        strip = np.full((self.config.caption_height, width, 3), 24, dtype=np.uint8)
        head = f"t = {frame.time:6.1f} s   action {c.action}" if c.action else f"t = {frame.time:6.1f} s   survey"
        if c.component:
            head += f": {c.component}"
        if c.phase:
            head += f"   ({c.phase})"
        cv2.putText(strip, head, (8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (240, 240, 240), 1, cv2.LINE_AA)
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
        cv2.putText(strip, "   ".join(values), (8, 44), cv2.FONT_HERSHEY_SIMPLEX, 0.45, colour, 1, cv2.LINE_AA)
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
        self.renderer.close()


def _serve(inbox, outbox) -> None:
    """The drawing process: one video per job, for as long as the trial's process lives. A job is
    ``(model_path, cameras, config, path)`` then its frames then ``None`` (publish) or :data:`ABORT` (discard);
    ``None`` instead of a job ends the process. A failed job ends it too (its parent starts another)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    os.environ["LP_NUM_THREADS"] = "1"  # one core for the drawing: the trial renders its cameras on the other
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
        with VideoWriter(path, fps=config.fps, preset="veryfast", faststart=False) as video:
            current["video"] = video
            while (frame := inbox.get()) is not None:
                if isinstance(frame, str):  # ABORT: the trial failed; publish nothing
                    raise VideoError("aborted by the trial")
                video.append(drawer.draw(frame))
                c = frame.caption
                index.append({"time": round(frame.time, 6), "action": c.action, "component": c.component,
                              "sensed": c.sensed, "truth": c.truth, "phase": c.phase,
                              "previous": c.previous})  # fmt: skip
            frames = video.frame_count
    finally:
        current["video"] = None
        drawer.close()
    sidecar = {"video": Path(path).name, "period_s": config.period, "fps": config.fps, "views": list(VIEWS),
               "view_size": list(config.view_size), "frames": index}  # fmt: skip
    write_text_atomically(frames_path(path), json.dumps(sidecar, indent=1))
    return frames


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
