"""Recordings of twin trials for the Rerun viewer (``trial.py --record FILE.rrd``; the ``viz`` extra:
``pip install -e .[viz]``; ``rerun`` is imported only when a recording is made).

Everything is logged on the ``sim_time`` timeline (simulated seconds), under these entity paths:

- ``cameras/<camera>``: every image the pipeline captured (JPEG), when it captured it — never rendered again;
  ``cameras/<camera>/markers``: the markers the pipeline detected in it (outlines, labelled by id);
- ``world/arm``: the arm's bodies (positions [m], world frame) and ``world/arm/<body>`` their poses;
  ``world/components``: each component's body, labelled by its spec name; ``world/tcp``: the TCP, whose
  successive positions draw its path, and ``world/tcp_path`` the whole path (static, written at the end);
- ``robot/force/{x,y,z,norm}``: the wrist force the primitives sensed [N, base frame];
- ``agent/belief``: the agent's belief as a matrix image — row ``2c + s`` (component ``c`` in state ``s``),
  column 0 "held by nothing", column ``1 + 2m + s'``: P(held by ``m`` in state ``s'``) — after every try;
- ``agent/decisions``: one line per decision (component, ``w``, ``Q_info``, ``Q_exploit``) and per outcome
  (sensed, and the truth in evaluation); ``agent/w``: the exploration weight.

Poses and forces are sampled every :attr:`RecordConfig.period` of simulated time and written in columns when
the recording closes (one call per entity: logged one by one they made a 3 s trial 5.6 s). The file is written beside
its destination under a temporary name and renamed when the recording closes: a crash leaves no half file.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.models.atomic import PublishedOnExit, apply_umask
from puzzlebox.twin.errors import TwinError


class RecordingError(TwinError, RuntimeError):
    """A Rerun recording that cannot be made (the ``viz`` extra missing, a bad destination)."""


@dataclass(frozen=True)
class RecordConfig:
    """How often a recording samples the trial."""

    period: float = 0.1
    """Simulated time between pose and force samples [s]."""
    jpeg_quality: int = 75
    """JPEG quality of the camera images [0-100]."""


def _rerun() -> Any:
    try:
        import rerun
    except ImportError:
        raise RecordingError("--record needs the rerun-sdk package (the viz extra): pip install -e .[viz]") from None
    return rerun


class TrialRecording(PublishedOnExit):
    """One trial's Rerun recording (see the module docstring)."""

    def __init__(self, path: str | os.PathLike[str], name: str, config: RecordConfig | None = None) -> None:
        self.path = Path(path)
        if not self.path.parent.is_dir():
            raise RecordingError(f"cannot write {self.path}: directory {self.path.parent} does not exist")
        self.config = config or RecordConfig()
        self.rr = _rerun()
        handle, temporary = tempfile.mkstemp(prefix=f".{self.path.stem}.", suffix=".rrd", dir=self.path.parent)
        os.close(handle)
        self._temporary = Path(temporary)
        self.stream = self.rr.RecordingStream("puzzlebox", recording_id=name)
        self.stream.save(str(self._temporary))
        self._times: list[float] = []
        self._bodies: dict[str, tuple[list[str], list[np.ndarray], list[np.ndarray]]] = {}
        self._tcp_path: list[np.ndarray] = []
        self._forces: list[np.ndarray] = []

    def _log(self, entity: str, archetype: Any, static: bool = False) -> None:
        self.stream.log(entity, archetype, static=static)

    def at(self, time: float) -> None:
        """Set the ``sim_time`` of what is logged next [s]."""
        self.stream.set_time("sim_time", duration=float(time))

    def image(self, camera: str, rgb: np.ndarray) -> None:
        """A camera image the pipeline captured."""
        self._log(f"cameras/{_safe(camera)}", self.rr.Image(rgb).compress(jpeg_quality=self.config.jpeg_quality))

    def markers(self, camera: str, detections: list[tuple[int, np.ndarray]]) -> None:
        """The markers detected in a camera's image: (id, (4, 2) corners [px])."""
        strips = [np.vstack([c, c[:1]]).astype(np.float32) for _, c in detections]
        labels = [str(i) for i, _ in detections]
        self._log(f"cameras/{_safe(camera)}/markers", self.rr.LineStrips2D(strips, labels=labels, colors=[0, 200, 0]))

    def sample(
        self,
        time: float,
        bodies: dict[str, tuple[list[str], np.ndarray, np.ndarray]],
        tcp: np.ndarray,
        force: np.ndarray | None,
    ) -> None:
        """One sample of the trial at ``time`` [s]: per entity (``world/arm``, ``world/components``) its body
        names, positions ``(B, 3)`` [m] and orientations ``(B, 4)`` (w, x, y, z); the TCP position [m]; the wrist
        force the primitives sensed [N, base frame] (None before any). Buffered: written in columns at
        :meth:`close` (one call per entity, not one per sample: a log call costs ~40 us)."""
        self._times.append(float(time))
        for entity, (names, positions, quats) in bodies.items():
            self._bodies.setdefault(entity, (names, [], []))
            self._bodies[entity][1].append(np.array(positions, dtype=np.float32))
            self._bodies[entity][2].append(np.array(quats, dtype=np.float32))
        self._tcp_path.append(np.array(tcp, dtype=np.float32))
        self._forces.append(np.full(3, np.nan) if force is None else np.array(force, dtype=float))

    def _write_samples(self) -> None:
        rr, n = self.rr, len(self._times)
        if not n:
            return
        times = np.array(self._times)
        every = [rr.TimeColumn("sim_time", duration=times)]
        send = self.stream.send_columns
        for entity, (names, positions, quats) in self._bodies.items():
            p, q = np.stack(positions), np.stack(quats)  # (T, B, 3), (T, B, 4)
            send(entity, every, rr.Points3D.columns(positions=p.reshape(-1, 3)).partition([len(names)] * n))
            for b, name in enumerate(names):
                xyzw = q[:, b][:, [1, 2, 3, 0]]
                send(f"{entity}/{_safe(name)}", every, rr.Transform3D.columns(translation=p[:, b], quaternion=xyzw))
        send("world/tcp", every, rr.Points3D.columns(positions=np.stack(self._tcp_path)).partition([1] * n))
        forces = np.stack(self._forces)
        sensed = ~np.isnan(forces[:, 0])  # (no force before the primitives sensed one)
        if sensed.any():
            when = [rr.TimeColumn("sim_time", duration=times[sensed])]
            for axis, values in zip("xyz", forces[sensed].T, strict=True):
                send(f"robot/force/{axis}", when, rr.Scalars.columns(scalars=values))
            send("robot/force/norm", when, rr.Scalars.columns(scalars=np.linalg.norm(forces[sensed], axis=1)))

    def belief(self, single_locker_probs: np.ndarray) -> None:
        """The agent's belief ``(N, 2, 1 + 2N)`` as a ``(2N, 1 + 2N)`` grey image (white: probability 1)."""
        p = np.asarray(single_locker_probs, dtype=float)
        matrix = p.reshape(p.shape[0] * 2, p.shape[2])
        self._log("agent/belief", self.rr.Image(np.round(255 * np.clip(matrix, 0, 1)).astype(np.uint8)))

    def decision(self, text: str, weight_info: float | None = None) -> None:
        """One decision or outcome, and the exploration weight ``w``."""
        self._log("agent/decisions", self.rr.TextLog(text))
        if weight_info is not None:
            self._log("agent/w", self.rr.Scalars([float(weight_info)]))

    def close(self) -> Path:
        """Write the samples and the TCP path, flush, and publish the file at :attr:`path`."""
        self._write_samples()
        if self._tcp_path:
            self._log("world/tcp_path", self.rr.LineStrips3D([np.array(self._tcp_path)]), static=True)
        self.stream.flush()
        self.stream.disconnect()
        apply_umask(self._temporary)  # mkstemp made it private; the recording is not
        os.replace(self._temporary, self.path)
        return self.path

    def abort(self) -> None:
        """Stop and leave no file."""
        with contextlib.suppress(Exception):
            self.stream.disconnect()
        with contextlib.suppress(FileNotFoundError):
            self._temporary.unlink()


def _safe(name: str) -> str:
    """An entity path part: '/' would make a sub-path."""
    return name.replace("/", "_")


def read_counts(path: str | os.PathLike[str]) -> dict[str, int]:
    """Rows per entity path in a recording, read back with Rerun's own reader (``rerun.chunk.RrdReader``)."""
    from rerun.chunk import RrdReader

    counts: dict[str, int] = {}
    for chunk in RrdReader(str(path)).stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    return counts
