"""Observers that show a trial: a rollout video (:class:`RolloutVideo`) and a Rerun recording
(:class:`RerunRecording`), fed by the trial's events (:mod:`puzzlebox.lab.observers`) and by the pipeline's own
marker detections (:class:`RecordingDetector`). Neither senses anything: the trial is the same with or without.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from puzzlebox.lab.observers import TrialContext, TrialObserver
from puzzlebox.lab.rollout_frames import CapturedLooks, FrameMaker, hand_phase, sensed_force
from puzzlebox.models.kinds import get_kind
from puzzlebox.skills import MarkerDetector
from puzzlebox.twin.rerun_log import TrialRecording
from puzzlebox.twin.rollout_video import BackgroundRollout, Caption, SceneCameras
from puzzlebox.twin.session import TwinSession

__all__ = ["RecordingDetector", "RerunRecording", "RolloutVideo", "agent_belief", "scene_cameras"]


class RecordingDetector(MarkerDetector):
    """The pipeline's marker detector, telling its listeners what it detected in every look (the rollout video
    and the Rerun recording show what the pipeline detected, never detecting again)."""

    def __init__(self) -> None:
        super().__init__()
        self.listeners: list[Callable[[str, float, list[tuple[int, np.ndarray]]], None]] = []
        """Called with (camera, capture time [s], detections: marker id and corners [px]) after every look."""

    def detect(self, image, camera, T_base_tcp=None):
        found = super().detect(image, camera, T_base_tcp)
        if image is not None:
            seen = [(d.marker_id, d.corners_px.copy()) for d in found]
            for listener in self.listeners:
                listener(image.camera, image.time, seen)
        return found


def scene_cameras(session: TwinSession) -> SceneCameras:
    """What the rollout video's views look at in ``session``: its cameras, and its box where it was placed — the
    shell's corners, each part's footprint on the lid and its handle's top (the views frame them) — and the
    parts' bodies (the part tried is highlighted)."""
    spec, scene = session.spec, session.scene
    box = spec.box
    assert box is not None  # the twin builds puzzle boxes only (models.scene refuses a spec with none)
    length, width, height = box.size
    names, render, T = scene.names, session.config.render, scene.T_world_lid
    in_lid = [[sx * length / 2, sy * width / 2, z] for sx in (-1, 1) for sy in (-1, 1) for z in (0.0, -height)]
    for c in spec.components:
        in_lid += [[x, y, 0.0] for x, y in get_kind(c.kind).footprint_in_lid(c.pose[:3])]
    points = np.asarray(in_lid) @ T[:3, :3].T + T[:3, 3]
    tops = [session.data.site(names.components[c.name].handle_site).xpos for c in spec.components]
    lid = T[:3, 3]
    return SceneCameras(
        overview=names.overview_camera,
        wrist=names.wrist_camera,
        lid_centre=(float(lid[0]), float(lid[1]), float(lid[2])),
        lid_diagonal=float(np.hypot(length, width)),
        capture_size=(render.width, render.height),
        box_points=tuple((float(x), float(y), float(z)) for x, y, z in [*points, *tops]),
        parts={c.name: names.components[c.name].body for c in spec.components},
    )


def agent_belief(agent: Any) -> np.ndarray | None:
    """The agent's belief as one-locker categoricals ``(N, 2, 1 + 2N)``, or None for an agent without one."""
    belief = getattr(agent, "belief", None)
    return None if belief is None else np.array(belief.single_locker_probs(), dtype=float)


class RolloutVideo(TrialObserver):
    """Hands a :class:`~puzzlebox.twin.rollout_video.RolloutFrame` to the background drawer every
    ``RolloutConfig.period`` of simulated time (:class:`puzzlebox.lab.rollout_frames.FrameMaker`: the joint
    positions, the caption of the action under way and the part it tries, the looks the pipeline took since the
    previous frame, what ``detector`` found, with the state at each capture, and the recent wrist force the
    primitives sensed). Drawing happens in the other process."""

    def __init__(self, session: TwinSession, rollout: BackgroundRollout, detector: RecordingDetector) -> None:
        self._session, self._rollout = session, rollout
        self._frames = FrameMaker([c.name for c in session.spec.components], rollout.config.period,
                                  rollout.config.plot_window)  # fmt: skip
        self._world: Any = None
        self._looks = CapturedLooks(lambda: session.data.qpos)
        detector.listeners.append(
            lambda camera, time, found: self._frames.look(camera, self._looks.look(camera, time, found))
        )

    def sensed(self, what: str, value: Any) -> None:
        if what.startswith("capture:") and value is not None:
            self._looks.captured(value.camera, value.time)

    def _look(self, camera: str, time: float, found: list[tuple[int, np.ndarray]]) -> None:
        self._frames.look(camera, self._looks.look(camera, time, found))

    def attach(self, trial: TrialContext) -> None:
        self._world = trial.world

    def waited(self, now: float) -> None:
        world = self._world
        for frame in self._frames.waited(now, self._session.data.qpos, sensed_force(world), hand_phase(world)):
            self._rollout.add(frame)

    def action_begins(self, caption: Caption) -> None:
        self._frames.action_begins(caption)

    def action_ended(self, caption: Caption) -> None:
        self._frames.action_ended(caption)

    def finish(self) -> None:  # the last frame, whatever the time: how the last action ended
        self._rollout.add(self._frames.frame(self._session.time, self._session.data.qpos, hand_phase(self._world)))


class RerunRecording(TrialObserver):
    """Logs the trial into a :class:`~puzzlebox.twin.rerun_log.TrialRecording`: every image the pipeline captured
    (as captured), the markers it detected, and every ``RecordConfig.period`` of simulated time the arm's and the
    components' poses, the TCP and the wrist force the primitives sensed; every decision, outcome and the agent's
    belief after it."""

    def __init__(self, session: TwinSession, recording: TrialRecording, detector: RecordingDetector) -> None:
        self._session, self.recording = session, recording
        m = session.model
        names = session.scene.names
        self._arm = [b for b in range(m.nbody) if m.body(b).name.startswith("xarm7/")]
        self._arm_names = [m.body(b).name.removeprefix("xarm7/") for b in self._arm]
        self._components = [m.body(c.body).id for c in names.components.values()]
        self._component_names = list(names.components)
        self._tcp = m.site(names.tcp_site).id
        self._next = 0.0
        self._world: Any = None
        self._agent: Any = None
        detector.listeners.append(self._markers)

    def attach(self, trial: TrialContext) -> None:
        self._world, self._agent = trial.world, trial.agent

    def sensed(self, what: str, value: Any) -> None:
        if what.startswith("capture:") and value is not None:
            self.recording.at(value.time)
            self.recording.image(value.camera, value.rgb)

    def _markers(self, camera: str, time: float, detections: list) -> None:
        self.recording.at(time)
        self.recording.markers(camera, detections)

    def waited(self, now: float) -> None:
        if now < self._next:
            return
        while self._next <= now:  # on the grid 0, period, 2 period, ... (a long wait skips points)
            self._next += self.recording.config.period
        d = self._session.data
        bodies = {
            "world/arm": (self._arm_names, d.xpos[self._arm], d.xquat[self._arm]),
            "world/components": (self._component_names, d.xpos[self._components], d.xquat[self._components]),
        }
        force = None if self._world is None else np.array(self._world.toggler.force_in_base, dtype=float)
        self.recording.sample(now, bodies, d.site_xpos[self._tcp], force)

    def action_begins(self, caption: Caption) -> None:
        self.recording.at(self._session.time)
        values = "" if caption.q_info is None else f": w {caption.weight_info:.3f}, Q_info {caption.q_info:.4f}, "
        values += "" if caption.q_exploit is None else f"Q_exploit {caption.q_exploit:.4f}"
        self.recording.decision(f"action {caption.action}: try {caption.component}{values}", caption.weight_info)

    def action_ended(self, caption: Caption) -> None:
        self.recording.at(self._session.time)
        truth = f" (truth: {caption.truth})" if caption.truth else ""
        self.recording.decision(f"action {caption.action} {caption.component}: {caption.sensed}{truth}")
        belief = agent_belief(self._agent)
        if belief is not None:
            self.recording.belief(belief)
