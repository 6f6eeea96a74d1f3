"""The trial loop: any agent against any ``World``, with a result per run in the contract's form."""

from __future__ import annotations

import sqlite3
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from puzzlebox.learning.agents.base import Agent
from puzzlebox.learning.errors import AgentError, LearningError
from puzzlebox.models import World
from puzzlebox.models.errors import ModelsError
from puzzlebox.models.try_outcome import Cause, ReadsItsResult, TryResult

MAX_FAILURES_IN_A_ROW = 3
"""A run ends when one component fails this many tries in a row (each already retried by the world), or when every
component failed since the joint state last changed: a component the robot cannot try is a failed try for the agent
to weigh (the dual agents try something else), and the run goes on while anything else can be tried."""


@dataclass(frozen=True)
class ActionRecord(ReadsItsResult):
    """One try: which component (its ground-truth name when the world gives one), and the world's result as it
    was returned (the same frozen :class:`models.TryResult`, not a copy of its fields)."""

    component: str
    result: TryResult

    def to_dict(self) -> dict[str, Any]:
        """The ``actions[]`` entry of a run record (``give_up`` is the world's word to the agent, not recorded)."""
        return {"component": self.component, "moved": self.moved, "outcome": self.outcome, "reason": self.reason,
                "cause": self.cause}  # fmt: skip

    @classmethod
    def from_dict(cls, entry: dict[str, Any]) -> ActionRecord:
        """An ``actions[]`` entry (:meth:`to_dict`'s layout). One written before outcomes were kept is ``moved`` or
        ``blocked`` as it moved; one written before causes were kept gets the cause its reason text names, if that
        cause fits its outcome."""
        outcome = entry.get("outcome", "moved" if entry["moved"] else "blocked")
        reason = entry.get("reason", "")
        if "cause" in entry:
            cause = None if entry["cause"] is None else Cause(entry["cause"])
        else:
            cause = Cause.from_legacy(reason)
            if cause is not None and not cause.fits(outcome):
                cause = None
        return cls(entry["component"], TryResult(outcome, reason, cause=cause))


@dataclass(frozen=True)
class RunResult:
    """One run of one agent on one puzzle (the ``runs[]`` entries of ``results.json``)."""

    spec: str
    seed: int
    solved: bool
    num_actions: int
    wall_time_s: float
    actions: list[ActionRecord] = field(default_factory=list)
    ended: str = ""
    """Why an unsolved run stopped early (a component the world gave up on), else empty."""

    def to_dict(self) -> dict[str, Any]:
        """The ``runs[]`` entry of ``results.json``."""
        return {"spec": self.spec, "seed": self.seed, "solved": self.solved, "num_actions": self.num_actions,
                "wall_time_s": self.wall_time_s, "actions": [a.to_dict() for a in self.actions],
                "ended": self.ended}  # fmt: skip


def run_episode(
    agent: Agent,
    world: World,
    spec_name: str,
    seed: int,
    max_actions: int,
    on_action: Callable[[ActionRecord], None] | None = None,
) -> RunResult:
    """Let ``agent`` act on ``world`` until the goal is reached or ``max_actions`` tries are spent.

    The agent's random generator is ``default_rng(seed)``, so a run is reproducible from its seed.
    ``on_action`` is called after every try (progress bars: a decision on a 40-component box takes
    seconds, a try in the twin ten).
    """
    start = time.perf_counter()
    observation = world.observe()
    _from(agent, "begin_episode", agent.begin_episode, observation, np.random.default_rng(seed))
    name_of = getattr(world, "ground_truth_name", None)
    actions: list[ActionRecord] = []
    ended = ""
    failures_in_a_row = 0  # of the component tried last
    failed_here: set[str] = set()  # components whose last try failed since the joint state last changed
    while not observation.solved and len(actions) < max_actions:
        index = _part_chosen(agent, _from(agent, "choose", agent.choose, observation), len(observation.states))
        before = observation.states
        result = world.try_toggle(index)
        observation = world.observe()
        if not np.array_equal(before, observation.states):
            failed_here = set()
        _from(agent, "record", agent.record, index, result, observation)
        name = name_of(index) if name_of else str(index)
        actions.append(ActionRecord(name, result))
        if on_action is not None:
            on_action(actions[-1])
        repeated = len(actions) > 1 and actions[-2].component == name and actions[-2].outcome == "failed"
        failures_in_a_row = (failures_in_a_row + 1 if repeated else 1) if result.outcome == "failed" else 0
        if result.outcome == "failed":
            failed_here.add(name)
        if failures_in_a_row >= MAX_FAILURES_IN_A_ROW or len(failed_here) == len(observation.states):
            ended = f"could not try {name}: {result.reason}"
            break
    _from(agent, "end_episode", agent.end_episode, observation.solved)
    return RunResult(
        spec=spec_name,
        seed=seed,
        solved=observation.solved,
        num_actions=len(actions),
        wall_time_s=time.perf_counter() - start,
        actions=actions,
        ended=ended,
    )


def _agent_name(agent: Agent) -> str:
    return str(getattr(agent, "name", "") or type(agent).__name__)


def _from(agent: Agent, method: str, call: Callable[..., Any], *args: Any) -> Any:
    """``call(*args)``, one of ``agent``'s methods: what it raises (``SystemExit`` too: a user's agent must not end the
    command silently) is the agent's :class:`AgentError`, naming it — but a Ctrl-C, and the conditions the library's
    callers handle themselves (a full disk, a memory file, a kind: ``OSError``, ``sqlite3.Error``, ``LearningError``,
    ``ModelsError``), pass as they were raised."""
    try:
        return call(*args)
    except (OSError, sqlite3.Error, LearningError, ModelsError):
        raise
    except (Exception, SystemExit) as err:  # (a Ctrl-C or a stop request, BaseExceptions, pass as they are)  # noqa: BLE001 - the seam: whatever an agent raises is reported as the agent's
        raise AgentError(f"agent {_agent_name(agent)!r} raised {type(err).__name__} in {method}(): {err}") from err


def _part_chosen(agent: Agent, index: Any, parts: int) -> int:
    """``index`` if it names one of the ``parts`` parts; else the agent's :class:`AgentError`, before any arm moves."""
    if isinstance(index, bool) or not isinstance(index, int | np.integer) or not 0 <= index < parts:
        raise AgentError(f"agent {_agent_name(agent)!r} chose {index!r}: the box's parts are 0..{parts - 1}")
    return int(index)


def summarise(runs: list[RunResult | dict[str, Any]], max_actions: int) -> dict[str, Any]:
    """The ``results.json`` object: success rate, mean actions (an unsolved run counts ``max_actions``)
    and every run (``RunResult`` or its dict with extra keys, as twin trials give). With no run finished (stopped
    before the first ended) there is no rate: ``success_rate`` and ``mean_actions`` are None and ``ended`` says so."""
    rows = [r.to_dict() if isinstance(r, RunResult) else r for r in runs]
    if not rows:
        return {"success_rate": None, "mean_actions": None, "max_actions": max_actions, "runs": [],
                "ended": "no run finished"}  # fmt: skip
    counted = [r["num_actions"] if r["solved"] else max_actions for r in rows]
    return {
        "success_rate": float(np.mean([r["solved"] for r in rows])),
        "mean_actions": float(np.mean(counted)),
        "max_actions": max_actions,
        "runs": rows,
    }
