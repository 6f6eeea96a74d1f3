"""Renderers kept across the sessions of one process.

Making a render context costs ~0.1-0.2 s on llvmpipe (uploading meshes and textures, allocating the
offscreen buffers) and the first frame of a new context another ~0.05 s (shader compilation), yet every
trial builds a new session whose model has the same render resources as the last one of its spec (a box
placed elsewhere changes poses, not meshes). A session's cameras take a renderer here and give it back when
the session closes; one whose :func:`~twin.rendering.render_resources_key` matches is rebound to the new
model (:meth:`~twin.rendering.Renderer.rebind`: frames identical to a new renderer's), so nothing of one
trial reaches the next but uploaded geometry. A renderer is lent to one user at a time; idle ones beyond
:data:`MAX_IDLE` are closed, oldest first. A child process (fork) never uses its parent's: EGL contexts do
not survive a fork.
"""

from __future__ import annotations

import os
import threading

import mujoco

from puzzlebox.twin.rendering import RenderConfig, Renderer, render_resources_key

MAX_IDLE = 2
"""Idle renderers kept (each holds ~10-20 MB of buffers and uploaded meshes)."""

_idle: list[tuple[int, str, Renderer]] = []  # (pid, resources key, renderer), oldest first
_lock = threading.Lock()


def acquire(model: mujoco.MjModel, config: RenderConfig) -> Renderer:
    """A renderer of ``model``: an idle one with the same render resources, rebound, or a new one."""
    key = render_resources_key(model, config)
    pid = os.getpid()
    with _lock:
        _idle[:] = [entry for entry in _idle if entry[0] == pid]  # a forked child's copies: dropped unfreed
        found = next((i for i, (_, k, r) in enumerate(_idle) if k == key and not r.closed), None)
        renderer = _idle.pop(found)[2] if found is not None else None
    if renderer is None:
        return Renderer(model, config)
    renderer.rebind(model)
    return renderer


def release(renderer: Renderer) -> None:
    """Give a renderer back for a later :func:`acquire` (the caller must not use it any more)."""
    if renderer.closed:
        return
    with _lock:
        _idle.append((os.getpid(), renderer.resources_key, renderer))
        evicted = [entry[2] for entry in _idle[:-MAX_IDLE]] if len(_idle) > MAX_IDLE else []
        del _idle[: len(evicted)]
    for old in evicted:
        old.close()


def clear() -> None:
    """Close every idle renderer (tests; a process about to fork)."""
    with _lock:
        idle = [entry[2] for entry in _idle if entry[0] == os.getpid()]
        _idle.clear()
    for renderer in idle:
        renderer.close()


__all__ = ["MAX_IDLE", "acquire", "clear", "release"]
