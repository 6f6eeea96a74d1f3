"""One trial as a runner task (``puzzlebox.lab.runner.Task``): a pure function of JSON settings — the spec, the
seed, the agent and what it learned (memory or checkpoint, by path and content hash), the simulator, the
reality profile and calibration, the budget — returning the contract's run entry. The same settings give
the same record in-process, in a worker pool, on Ray and after a resume (wall times aside).

What is costly to load and the same for every task of a run (the memory) is opened once per worker."""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from functools import lru_cache
from pathlib import Path
from typing import Any, Protocol

from puzzlebox.lab.agent_class import is_agent_class_name, make_agent_object
from puzzlebox.lab.runner import Task
from puzzlebox.lab.trial_config import TrialConfig
from puzzlebox.lab.trials import run_trial as run_trial_of
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.learning.scene_lockers import scene_max_lockers
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.spec_loading import spec_from_dict

TIMING_KEYS = ("wall_time", "wall_time_s", "wall_time_per_trial_s_max", "wall_time_per_trial_s_mean", "sim_over_wall")
"""Record and summary fields that measure this machine's speed, not the trial: the only ones that differ
between two executions of one task."""


def file_sha256(path: str | Path) -> str:
    """SHA-256 of a file's bytes (a memory or checkpoint is part of a task's settings by content)."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def trial_task(
    key: str,
    spec: PuzzleSpec,
    seed: int,
    *,
    sim: str,
    agent: str,
    max_actions: int,
    memory: str | None = None,
    checkpoint: str | None = None,
    reality: dict[str, Any] | None = None,
    calibration: dict[str, Any] | None = None,
    video: str | None = None,
    misreport_kind: bool = False,
    max_lockers: int | None = None,
    record: str | None = None,
    locks: str = "contact",
    state_log: str | None = None,
) -> Task:
    """The task of one run (``reality`` and ``calibration`` as their ``to_dict()``; twin only;
    ``misreport_kind``: one component's kind told wrong, drawn from the seed; ``max_lockers``: the most
    lockers the memory and dual agents' belief allows a component (None: what fits the scene and the memory,
    resolved here, so that a task says what it runs); ``locks``: the twin box's locks,
    ``contact`` mechanisms or ``latch``)."""
    settings = {
        "sim": sim, "spec": spec.to_dict(), "seed": seed, "agent": agent, "max_actions": max_actions,
        "memory": str(Path(memory).resolve()) if memory else None,
        "memory_sha256": file_sha256(memory) if memory else None,
        "checkpoint": str(Path(checkpoint).resolve()) if checkpoint else None,
        "checkpoint_sha256": file_sha256(checkpoint) if checkpoint else None,
        "reality": reality, "calibration": calibration,
    }  # fmt: skip
    if misreport_kind:  # only then: the settings (and hashes) of every other task stay as they were
        settings["misreport_kind"] = True
    if max_lockers is None:
        store = _memory(settings["memory"], settings["memory_sha256"]) if memory else None
        max_lockers = scene_max_lockers(spec, store, agent)
    if max_lockers != 1:  # likewise: a k = 1 task is the task it was before k existed
        settings["max_lockers"] = max_lockers
    if sim == "twin" and locks != "latch":  # a latch task is the task it was before mechanisms existed
        settings["locks"] = locks
    outputs = (("video", video), ("record", record), ("state_log", state_log))
    context = {k: v for k, v in outputs if v}  # outputs: not part of the record
    return Task(key, run_trial, settings, context=context or None)


@lru_cache(maxsize=4)
def _memory(path: str, sha256: str) -> MemoryStore:
    """The memory at ``path`` opened once per process and content (trials only read it)."""
    return MemoryStore.open_existing(path)


def run_trial(settings: Mapping[str, Any], context: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Run the trial ``settings`` describe (see :func:`trial_task`); returns its run entry. ``context`` may name
    a ``video`` file, a Rerun ``record`` file and a ``state_log`` file to write (where they go does not change the
    record)."""
    spec = spec_from_dict(settings["spec"])
    if _hook is not None:
        _hook.start(f"{spec.name} seed {settings['seed']}")
    try:
        outputs = context or {}
        return _run(spec, settings, outputs.get("video"), outputs.get("record"), outputs.get("state_log"))
    finally:
        if _hook is not None:
            _hook.close()


def _run(
    spec: PuzzleSpec,
    settings: Mapping[str, Any],
    video: str | None,
    record: str | None = None,
    state_log: str | None = None,
) -> dict[str, Any]:
    memory = _memory(settings["memory"], settings["memory_sha256"]) if settings["memory"] else None
    name = settings["agent"]
    agent = make_agent_object(name) if is_agent_class_name(name) else None
    if settings["sim"] == "twin":
        from puzzlebox.models.calibration import CellCalibration  # MuJoCo and rendering only when asked
        from puzzlebox.twin.reality import IDEAL, RealityProfile

        config = TrialConfig(
            sim="twin", agent=name, seed=settings["seed"], max_actions=settings["max_actions"],
            reality=RealityProfile.from_dict(settings["reality"]) if settings["reality"] else IDEAL,
            calibration=CellCalibration.from_dict(settings["calibration"]) if settings["calibration"] else None,
            checkpoint=settings["checkpoint"], misreport_kind=settings.get("misreport_kind", False),
            max_lockers=settings.get("max_lockers", 1), locks=settings.get("locks", "latch"),
        )  # fmt: skip
        return run_trial_of(spec, config, agent=agent, memory=memory, video=video, recording=record,
                         on_action=_on_action, state_log=state_log).to_dict()  # fmt: skip
    config = TrialConfig(sim="symbolic", agent=name, seed=settings["seed"], max_actions=settings["max_actions"],
                         checkpoint=settings["checkpoint"], max_lockers=settings.get("max_lockers", 1))  # fmt: skip
    return run_trial_of(spec, config, agent=agent, memory=memory, on_action=_on_action).to_dict()


class ActionHook(Protocol):
    """Follows the actions of trials run in this process (trial.py's inner progress bar)."""

    def start(self, name: str) -> None: ...
    def __call__(self, action: Any, /) -> None: ...  # called with the action alone
    def close(self) -> None: ...


_hook: ActionHook | None = None


def set_action_hook(hook: ActionHook | None) -> None:
    """Follow every action of the trials run in this process with ``hook`` (None: stop following)."""
    global _hook
    _hook = hook


def _on_action(action: Any) -> None:
    if _hook is not None:
        _hook(action)


def without_timing(value: Any) -> Any:
    """``value`` (a record or a summary) without the fields that measure the machine's speed."""
    if isinstance(value, dict):
        return {k: without_timing(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [without_timing(v) for v in value]
    return value
