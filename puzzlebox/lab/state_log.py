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
- ``phase`` (n,): what the hand was doing, an index in :data:`puzzlebox.models.toggle_log.PHASES`.

The scene the log replays in is named by the trial's record (spec as placed, box pose, reality profile, seed)
and its ``config.json`` (calibration); ``meta`` in the file repeats the spec's name, the seed and the model's
sizes.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from puzzlebox.lab.observers import TrialContext, TrialObserver
from puzzlebox.models.atomic import write_atomically
from puzzlebox.models.toggle_log import PHASES

if TYPE_CHECKING:
    from puzzlebox.skills.robot_world import RobotWorld
    from puzzlebox.twin.session import TwinSession

FORMAT = "puzzlebox-state-log/1"
"""The ``format`` of a state log's ``meta``."""
ARRAYS = ("time", "qpos", "qvel", "joint_command", "gripper_command", "wrench", "part_states", "action", "in_try",
          "phase")  # fmt: skip
"""The per-tick arrays of a state log (module docstring)."""


class StateLog(TrialObserver):
    """Collects a twin trial's state at every robot wait, from the start (the survey of the scene included), in
    ``session``'s physics (see the module docstring); :meth:`arrays` gives them."""

    def __init__(self, session: TwinSession, spec_name: str, seed: int) -> None:
        self._session, self._spec_name, self._seed = session, spec_name, seed
        self._world: RobotWorld | None = None
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

    def action_begins(self, caption: Any) -> None:
        self._in_try = True

    def action_ended(self, caption: Any) -> None:
        self._in_try = False

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
        phase = world.toggler.phase if world is not None else "moving"  # (surveying: moving and looking)
        rows["phase"].append(PHASES.index(phase) if phase in PHASES else 0)

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
        }

    def meta(self) -> dict[str, Any]:
        """What the log is of: the format, the spec's name, the seed, the model's sizes, the phase names."""
        model = self._session.model
        return {"format": FORMAT, "spec": self._spec_name, "seed": self._seed, "nq": model.nq, "nv": model.nv,
                "phases": list(PHASES)}  # fmt: skip

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


__all__ = ["ARRAYS", "FORMAT", "StateLog", "load_state_log", "save_state_log"]
