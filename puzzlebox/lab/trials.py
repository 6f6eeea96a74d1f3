"""Run a trial from Python: :func:`run_trial` (the agent acts until solved or out of actions, in the symbolic
simulator, the twin or a real cell; a record comes back) and :func:`open_world` (the world, for one's own loop)."""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

from puzzlebox.lab.cells import RealCell, TwinCell
from puzzlebox.lab.errors import TrialConfigError
from puzzlebox.lab.observers import TrialContext, TrialObserver
from puzzlebox.lab.trial_config import TrialConfig
from puzzlebox.lab.trial_record import TrialRecord
from puzzlebox.learning import Agent, SymbolicWorld, make_agent, run_episode
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models import PuzzleSpec, World

__all__ = ["open_world", "run_trial"]


def run_trial(
    spec: PuzzleSpec,
    config: TrialConfig | None = None,
    *,
    agent: Agent | None = None,
    observers: Sequence[TrialObserver] = (),
    memory: MemoryStore | None = None,
    video: str | Path | None = None,
    recording: str | Path | None = None,
    on_action: Callable[[Any], None] | None = None,
    cell: TwinCell | RealCell | None = None,
    on_record: Callable[[dict[str, Any]], None] | None = None,
    state_log: str | Path | None = None,
) -> TrialRecord:
    """One trial of ``agent`` on ``spec`` under ``config`` (default :class:`TrialConfig`: the twin, ``ideal``).

    ``agent``: any object with the ``puzzlebox.learning.Agent`` methods (default: the registered agent
    ``config.agent``, made for this spec; the memory agent reads ``memory``, or the file ``config.memory``).
    ``observers`` see every reading, wait and action of a twin trial (:mod:`puzzlebox.lab.observers`) without
    changing it. ``video`` (MP4), ``recording`` (Rerun ``.rrd``) and ``state_log`` (the state at every control
    tick, ``.npz``: :mod:`puzzlebox.lab.state_log`) are written there, twin only.
    ``on_action`` is called after every try with its :class:`~puzzlebox.learning.ActionRecord`.
    ``cell``: where the trial runs — a :class:`~puzzlebox.lab.cells.TwinCell` (its profile and calibration
    replace ``config.reality`` and ``config.calibration``) or a :class:`~puzzlebox.lab.cells.RealCell` (the arm
    in front of the box ``spec`` describes; the record holds only what was sensed, plus ``robot_time_s`` and
    ``stopped`` when the arm's safety limits stopped it). ``on_record`` is called with the record so far (its
    ``to_dict()``) after every try of a real trial and once at the end of any trial: write it as it grows.
    Raises :class:`~puzzlebox.lab.errors.TrialConfigError` for outputs or faults the chosen cell cannot make."""
    config = config or TrialConfig()
    if memory is None and agent is None and config.memory is not None:
        memory = MemoryStore.open_existing(config.memory)
    if isinstance(cell, RealCell):
        if video is not None or recording is not None or state_log is not None:
            raise TrialConfigError(
                "a video, a recording or a state log is of a twin trial: a real cell has no simulator to draw"
            )
        return _run_real(spec, config, cell, agent, memory, observers, on_action, on_record)
    if isinstance(cell, TwinCell):
        if config.sim != "twin":
            raise TrialConfigError("a TwinCell is the twin's: TrialConfig(sim='twin')")
        config = dataclasses.replace(config, reality=cell.profile, calibration=cell.calibration)
    record = _run_sim(spec, config, agent, memory, observers, video, recording, on_action, state_log)
    if on_record is not None:
        on_record(record.to_dict())
    return record


def _run_sim(
    spec: PuzzleSpec,
    config: TrialConfig,
    agent: Agent | None,
    memory: MemoryStore | None,
    observers: Sequence[TrialObserver],
    video: str | Path | None,
    recording: str | Path | None,
    on_action: Callable[[Any], None] | None,
    state_log: str | Path | None = None,
) -> TrialRecord:
    if config.sim == "twin":
        from puzzlebox.lab.twin_trial import run_twin_trial  # MuJoCo and rendering only when asked

        return run_twin_trial(
            spec, config, agent, memory, observers, None if video is None else Path(video),
            None if recording is None else Path(recording), on_action, None if state_log is None else Path(state_log),
        )  # fmt: skip
    if video is not None or recording is not None or state_log is not None:
        raise TrialConfigError("a video, a recording or a state log is of a twin trial (sim='twin')")
    if agent is None:
        checkpoint = None if config.checkpoint is None else str(config.checkpoint)
        agent = make_agent(config.agent, spec, memory, checkpoint, max_lockers=config.max_lockers)
    for observer in observers:
        observer.attach(TrialContext(spec, config.seed, None, None, agent))
    result = run_episode(agent, SymbolicWorld(spec, config.seed), spec.name, config.seed, config.max_actions, on_action)
    for observer in observers:
        observer.finish()
    return TrialRecord.of_run(result)


def _run_real(
    spec: PuzzleSpec,
    config: TrialConfig,
    cell: RealCell,
    agent: Agent | None,
    memory: MemoryStore | None,
    observers: Sequence[TrialObserver],
    on_action: Callable[[Any], None] | None,
    on_record: Callable[[dict[str, Any]], None] | None,
) -> TrialRecord:
    if config.sim != "twin" or config.misreport_kind:
        raise TrialConfigError("a real cell runs TrialConfig(sim='twin'), the default, without misreport_kind")
    from puzzlebox.lab.real_trial import run_real_trial  # the motion primitives only when a real trial is asked

    entry = run_real_trial(
        cell.robot, cell.calibration, spec, cell.config, config.agent, config.seed, config.max_actions,
        memory=memory, checkpoint=None if config.checkpoint is None else str(config.checkpoint),
        on_action=on_action, on_record=on_record, primitives=cell.primitives, max_lockers=config.max_lockers,
        agent=agent, observers=observers,
    )  # fmt: skip
    return TrialRecord.from_dict(entry)


@contextlib.contextmanager
def open_world(
    spec: PuzzleSpec, config: TrialConfig | None = None, observers: Sequence[TrialObserver] = ()
) -> Iterator[World]:
    """The world of a trial for one's own loop (a context manager): ``observe()`` gives the scene as the
    pipeline perceives it, ``try_toggle(i)`` tries component ``i`` and says what happened. In the twin
    (``config.sim``, default) the robot moves through perception and the motion primitives, under
    ``config``'s reality profile and calibration; the session closes when the block ends."""
    config = config or TrialConfig()
    if config.sim == "symbolic":
        yield SymbolicWorld(spec, config.seed)
        return
    from puzzlebox.lab.twin_trial import open_twin_world

    with open_twin_world(spec, config, observers) as world:
        yield world
