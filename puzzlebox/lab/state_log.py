"""A twin trial's state log (:class:`StateLog`): what a replay needs and a learner wants, at every control tick.

One row per robot wait (each 10 ms control tick of a motion, every settle and look), sampled from the twin's
physics and from what the pipeline commanded and sensed, never by sensing anything itself: a trial is the same
trial, to the bit (its ``sensed_sha256``), with or without its log. Written when the trial ends as one
``.npz`` (:func:`save_state_log`), read back with :func:`load_state_log`. The arrays, ``n`` rows:

- ``time`` (n,) simulated time [s];
- ``qpos`` (n, nq) and ``qvel`` (n, nv): the model's generalized positions and velocities (MuJoCo's order:
  the arm's seven joints, the gripper's, then every part's joint), float64 so that a replay poses the model
  exactly as it stood;
- ``joint_command`` (n, 7) [rad]: the arm's last commanded joint targets (the action), NaN before the first;
- ``gripper_command`` (n,) [0 open .. 1 closed]: the gripper's last command, NaN before the first;
- ``wrench`` (n, 6) [N, N·m]: the last wrist wrench the pipeline read (tared, in the sensor's frame, as sensed:
  noise, bias and delay included), NaN before the first reading;
- ``part_states`` (n, parts) 0/1: each part's state as the twin counts it, in spec order (the truth: privileged);
- ``action`` (n,): how many tries had ended at that tick (the try running is ``action`` while ``in_try``);
- ``in_try`` (n,) bool: a try was running (between the agent's choice and its outcome);
- ``phase`` (n,): what the hand was doing, an index in :data:`puzzlebox.models.toggle_log.PHASES` (-1: surveying,
  before the world existed);
- ``force_sensed`` (n,) [N]: the magnitude of the wrist force the hand sensed (filtered, in the base frame: the
  rollout's force plot), NaN while surveying.

``meta`` (JSON) holds the scene to replay it in (``scene``: the spec as given, the reality profile, the locks and
the seed, from which the twin builds the same model and places the box alike), the spec's name, the model's sizes,
the time the trial ended, and the events between ticks (``events``: each try's caption as it began and ended, and
each look the pipeline took, with the markers it found and the state it looked at), stamped with the number of
ticks before them. :func:`replay_frames` folds a log into the rollout video's frames, the same frames the trial
made live (:mod:`puzzlebox.lab.rollout_frames`).
"""

from __future__ import annotations

import collections
import dataclasses
import io
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from puzzlebox.lab.observers import TrialContext, TrialObserver
from puzzlebox.lab.rollout_frames import CapturedLooks, hand_phase, sensed_force
from puzzlebox.models.atomic import write_atomically
from puzzlebox.models.toggle_log import PHASES

if TYPE_CHECKING:
    from puzzlebox.lab.rollout_observers import RecordingDetector
    from puzzlebox.lab.trial_config import TrialConfig
    from puzzlebox.models import PuzzleSpec
    from puzzlebox.skills.robot_world import RobotWorld
    from puzzlebox.twin.rollout_video import Caption, RolloutFrame
    from puzzlebox.twin.session import TwinSession

FORMAT = "puzzlebox-state-log/1"
"""The ``format`` of a state log's ``meta``."""
ARRAYS = ("time", "qpos", "qvel", "joint_command", "gripper_command", "wrench", "part_states", "action", "in_try",
          "phase", "force_sensed")  # fmt: skip
"""The per-tick arrays of a state log (module docstring)."""
SURVEYING = -1
"""The ``phase`` of a tick before the world existed (the survey of the scene)."""


class StateLog(TrialObserver):
    """Collects a twin trial's state at every robot wait, from the start (the survey of the scene included), in
    ``session``'s physics (see the module docstring); :meth:`arrays` gives them."""

    def __init__(self, session: TwinSession, scene: dict[str, Any], detector: RecordingDetector | None = None) -> None:
        """``scene``: what rebuilds the session (:func:`scene_of`); ``detector``: the pipeline's, telling its
        looks (none: no looks logged)."""
        self._session, self._scene = session, scene
        self._world: RobotWorld | None = None
        self._events: list[dict[str, Any]] = []
        self._end_phase = "surveying"
        self._looks = CapturedLooks(lambda: session.data.qpos)
        if detector is not None:
            detector.listeners.append(self._look)
        self._rows: dict[str, list[Any]] = {name: [] for name in ARRAYS}
        self._joint_command = np.full(7, np.nan)
        self._gripper_command = np.nan
        self._wrench = np.full(6, np.nan)
        self._in_try = False

    def attach(self, trial: TrialContext) -> None:
        self._world = trial.world

    def commanded(self, what: str, value: Any) -> None:
        if what == "joint_positions":
            self._joint_command = np.array(value, dtype=float)
        elif what == "gripper":
            self._gripper_command = float(value)

    def sensed(self, what: str, value: Any) -> None:
        if what == "wrench":
            self._wrench = np.array(value, dtype=float)
        elif what.startswith("capture:") and value is not None:
            self._looks.captured(value.camera, value.time)

    def _look(self, camera: str, time: float, found: list[tuple[int, np.ndarray]]) -> None:
        look = self._looks.look(camera, time, found)
        qpos = None if look.qpos is None else look.qpos.tolist()
        self._event("look", camera=camera, time=time, found=[[int(m), c.tolist()] for m, c in found], qpos=qpos)

    def _event(self, event: str, **fields: Any) -> None:
        self._events.append({"after": len(self._rows["time"]), "event": event, **fields})

    def action_begins(self, caption: Caption) -> None:
        self._in_try = True
        self._event("begin", caption=dataclasses.asdict(caption))

    def action_ended(self, caption: Caption) -> None:
        self._in_try = False
        self._event("end", caption=dataclasses.asdict(caption))

    def waited(self, now: float) -> None:
        data, world, rows = self._session.data, self._world, self._rows
        rows["time"].append(now)
        rows["qpos"].append(data.qpos.copy())
        rows["qvel"].append(data.qvel.copy())
        rows["joint_command"].append(self._joint_command)
        rows["gripper_command"].append(self._gripper_command)
        rows["wrench"].append(self._wrench)
        rows["part_states"].append(self._session.component_states())
        rows["action"].append(len(world.log) if world is not None else 0)
        rows["in_try"].append(self._in_try)
        rows["phase"].append(SURVEYING if world is None else PHASES.index(hand_phase(world)))
        force = sensed_force(world)  # (as the rollout's force plot)
        rows["force_sensed"].append(np.nan if force is None else force)

    def finish(self) -> None:
        self._end_phase = hand_phase(self._world)

    def arrays(self) -> dict[str, np.ndarray]:
        """The log so far, one array per name of :data:`ARRAYS` (``n`` rows each)."""
        model, rows = self._session.model, self._rows
        nq, nv, parts = model.nq, model.nv, len(self._session.spec.components)
        return {
            "time": np.asarray(rows["time"], dtype=np.float64),
            "qpos": np.asarray(rows["qpos"], dtype=np.float64).reshape(-1, nq),
            "qvel": np.asarray(rows["qvel"], dtype=np.float32).reshape(-1, nv),
            "joint_command": np.asarray(rows["joint_command"], dtype=np.float64).reshape(-1, 7),
            "gripper_command": np.asarray(rows["gripper_command"], dtype=np.float32),
            "wrench": np.asarray(rows["wrench"], dtype=np.float32).reshape(-1, 6),
            "part_states": np.asarray(rows["part_states"], dtype=np.int8).reshape(-1, parts),
            "action": np.asarray(rows["action"], dtype=np.int16),
            "in_try": np.asarray(rows["in_try"], dtype=bool),
            "phase": np.asarray(rows["phase"], dtype=np.int8),
            "force_sensed": np.asarray(rows["force_sensed"], dtype=np.float64),
        }

    def meta(self) -> dict[str, Any]:
        """What the log is of (module docstring): the format, the scene, the spec's name, the seed, the model's
        sizes, the phase names, when the trial ended and what the hand was doing then, and the events."""
        model = self._session.model
        return {
            "format": FORMAT, "spec": self._session.spec.name, "seed": self._scene["seed"], "nq": model.nq,
            "nv": model.nv, "phases": list(PHASES), "end_time": self._session.time, "end_phase": self._end_phase,
            "scene": self._scene, "events": self._events,
        }  # fmt: skip

    def save(self, path: str | Path) -> Path:
        """Write the log to ``path`` (:func:`save_state_log`)."""
        return save_state_log(path, self.arrays(), self.meta())


def save_state_log(path: str | Path, arrays: dict[str, np.ndarray], meta: dict[str, Any]) -> Path:
    """Write ``arrays`` and ``meta`` (JSON) to ``path`` as one ``.npz``, atomically. Not compressed: the arm's
    floating-point states hardly compress (3.06 MB compressed of ~3.3 MB for a 92 s trial) and zlib took 0.25 s,
    3 % of the trial."""
    buffer = io.BytesIO()
    savez: Any = np.savez  # (its stubs take a dict's keys for its own keywords)
    savez(buffer, meta=np.array(json.dumps(meta)), **arrays)
    return write_atomically(path, lambda tmp: tmp.write_bytes(buffer.getvalue()))


def load_state_log(path: str | Path) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
    """A state log's arrays and meta (``ValueError`` if the file is not one)."""
    with np.load(path, allow_pickle=False) as npz:
        if "meta" not in npz.files:
            raise ValueError(f"{path}: not a state log (no meta)")
        meta = json.loads(str(npz["meta"]))
        if meta.get("format") != FORMAT:
            raise ValueError(f"{path}: not a state log (format {meta.get('format')!r}, expected {FORMAT!r})")
        missing = [name for name in ARRAYS if name not in npz.files]
        if missing:
            raise ValueError(f"{path}: a state log without {missing}")
        return {name: npz[name] for name in ARRAYS}, meta


def scene_of(spec: PuzzleSpec, config: TrialConfig) -> dict[str, Any]:
    """What rebuilds a trial's twin session (:func:`replay_session`): ``spec`` as given (the profile places the
    box from the seed), the reality profile, the locks and the seed."""
    from puzzlebox.twin.reality import load_profile

    return {"spec": spec.to_dict(), "reality": load_profile(config.reality).to_dict(), "locks": config.locks,
            "seed": config.seed}  # fmt: skip


def replay_session(meta: dict[str, Any]) -> TwinSession:
    """The twin session a state log was made in, built again from its ``meta["scene"]`` (the same model, the box
    placed alike): a context manager, as :class:`~puzzlebox.twin.session.TwinSession` is."""
    from puzzlebox.models import spec_from_dict
    from puzzlebox.models.scene import SceneConfig
    from puzzlebox.twin.reality import RealityProfile
    from puzzlebox.twin.session import TwinConfig, TwinSession

    scene = meta["scene"]
    return TwinSession(spec_from_dict(scene["spec"]), seed=scene["seed"],
                       reality=RealityProfile.from_dict(scene["reality"]),
                       config=TwinConfig(scene=SceneConfig(locks=scene["locks"])))  # fmt: skip


def replay_frames(
    arrays: dict[str, np.ndarray], meta: dict[str, Any], period: float = 0.1, plot_window: float = 15.0
) -> list[RolloutFrame]:
    """The rollout video's frames of a logged trial, every ``period`` of simulated time [s] with the force plot
    over ``plot_window`` [s]: at the trial's own ``RolloutConfig`` (the defaults), the very frames it made live
    (:class:`puzzlebox.lab.rollout_frames.FrameMaker` fed the same events in the same order)."""
    from puzzlebox.lab.rollout_frames import FrameMaker
    from puzzlebox.twin.rollout_video import Caption, Look

    parts = [c["name"] for c in meta["scene"]["spec"]["components"]]
    maker = FrameMaker(parts, period, plot_window)
    events = collections.defaultdict(list)
    for event in meta["events"]:
        events[event["after"]].append(event)

    def apply(stamp: int) -> None:
        for e in events.get(stamp, []):
            if e["event"] == "look":
                found = [(int(m), np.array(c, dtype=float)) for m, c in e["found"]]
                qpos = None if e["qpos"] is None else np.array(e["qpos"], dtype=float)
                maker.look(e["camera"], Look(e["time"], found, qpos))
            elif e["event"] == "begin":
                maker.action_begins(Caption(**e["caption"]))
            else:
                maker.action_ended(Caption(**e["caption"]))

    def phase_of(code: int) -> str:
        return "surveying" if code == SURVEYING else PHASES[code]

    frames: list[RolloutFrame] = []
    n = len(arrays["time"])
    for i in range(n):
        apply(i)
        force = float(arrays["force_sensed"][i])
        frames += maker.waited(float(arrays["time"][i]), arrays["qpos"][i], None if math.isnan(force) else force,
                               phase_of(int(arrays["phase"][i])))  # fmt: skip
    apply(n)
    if n:
        frames.append(maker.frame(meta["end_time"], arrays["qpos"][-1], meta["end_phase"]))
    return frames


__all__ = [
    "ARRAYS",
    "FORMAT",
    "SURVEYING",
    "StateLog",
    "load_state_log",
    "replay_frames",
    "replay_session",
    "save_state_log",
    "scene_of",
]
