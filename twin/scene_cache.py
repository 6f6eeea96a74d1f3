"""Compiled scenes kept across the sessions of one process.

Building a spec's MJCF scene and compiling it takes ~0.1-0.15 s, and every trial of a spec builds the same
one (under a profile that places boxes, each placement is its own scene). Sessions take a *copy* of a
cached model — a session writes into its model (the cell's and the trial's physics draws, a widened camera),
so nothing one session does reaches another — and share the :class:`~models.scene.Scene` (names and poses,
read only).
"""

from __future__ import annotations

import collections
import copy
import threading

import mujoco

from puzzlebox.models import PuzzleSpec
from puzzlebox.models.scene import Scene, SceneConfig, build_scene

MAX_SCENES = 4
"""Compiled scenes kept (a paper scene's model holds ~18 MB, its meshes' collision data mostly; under a profile
that places boxes every trial is a new scene, so more would only hold memory)."""

_cache: collections.OrderedDict[str, tuple[Scene, mujoco.MjModel]] = collections.OrderedDict()
_lock = threading.Lock()


def compiled_scene(spec: PuzzleSpec, config: SceneConfig) -> tuple[Scene, mujoco.MjModel]:
    """The scene of ``spec`` and a fresh copy of its compiled model, as ``build_scene(spec, config)`` and
    ``.compile()`` give them."""
    key = spec.to_json() + "\n" + repr(config)
    with _lock:
        entry = _cache.get(key)
        if entry is not None:
            _cache.move_to_end(key)
    if entry is None:
        scene = build_scene(spec, config)
        entry = (scene, scene.compile())
        with _lock:
            _cache[key] = entry
            while len(_cache) > MAX_SCENES:
                _cache.popitem(last=False)
    return entry[0], copy.deepcopy(entry[1])


def clear() -> None:
    """Forget every cached scene (tests)."""
    with _lock:
        _cache.clear()


__all__ = ["MAX_SCENES", "clear", "compiled_scene"]
