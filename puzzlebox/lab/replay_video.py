"""A rollout video drawn after the trial, from its state log (:func:`replay_video`): the trial's own frames at its
own rate (the same frames it would have drawn live, :func:`puzzlebox.lab.state_log.replay_frames`), or at another
rate, without the trial's physics."""

from __future__ import annotations

from pathlib import Path

from puzzlebox.lab.rollout_observers import scene_cameras
from puzzlebox.lab.state_log import load_state_log, replay_frames, replay_session
from puzzlebox.twin.rollout_video import BackgroundRollout, RolloutConfig


def replay_video(log: str | Path, out: str | Path, config: RolloutConfig | None = None) -> int:
    """Draw the rollout video of the trial logged in ``log`` (a state log, ``trial.py --state-log``) to ``out``
    (MP4), at ``config``'s frame period and playback rate (default: the trial's own, 0.1 s and 30 frames/s);
    returns the number of frames. The scene is built again from the log (the same model, the box placed alike);
    published when all are drawn, nothing left on an error."""
    config = config or RolloutConfig()
    arrays, meta = load_state_log(log)
    frames = replay_frames(arrays, meta, config.period, config.plot_window)
    with (
        replay_session(meta) as session,
        BackgroundRollout(out, session.model, scene_cameras(session), config) as video,
    ):
        for frame in frames:
            video.add(frame)
    return len(frames)


__all__ = ["replay_video"]
