"""A user's agent class named on the command line as ``package.module:Class`` (``trial.py --agent``)."""

from __future__ import annotations

import importlib
import inspect
from os import PathLike
from typing import Any

from puzzlebox.lab.errors import AgentClassError, TrialConfigError

__all__ = ["AGENT_METHODS", "check_agent", "is_agent_class_name", "load_agent_class", "make_agent_object"]

AGENT_METHODS = ("begin_episode", "choose", "record", "end_episode")
"""What the trial loop calls of an agent (``puzzlebox.learning.Agent``)."""


def is_agent_class_name(name: str) -> bool:
    """Whether ``name`` names a class (``package.module:Class``) rather than a registered agent."""
    return ":" in name


def load_agent_class(name: str) -> type:
    """The class ``package.module:Class`` names, checked against the ``Agent`` protocol: constructible with no
    argument, with a ``name`` and the methods :data:`AGENT_METHODS`. Raises :class:`AgentClassError` naming what
    is missing (the module, the class, or the methods)."""
    module_name, _, class_name = name.partition(":")
    if not module_name or not class_name:
        raise AgentClassError(f"agent {name!r}: give it as package.module:Class")
    try:
        module = importlib.import_module(module_name)
    except ImportError as err:
        raise AgentClassError(f"agent {name!r}: cannot import module {module_name!r} ({err})") from err
    cls = getattr(module, class_name, None)
    if cls is None:
        found = sorted(k for k, v in vars(module).items() if inspect.isclass(v) and not k.startswith("_"))
        raise AgentClassError(f"agent {name!r}: module {module_name!r} has no {class_name!r}; its classes: {found}")
    if not inspect.isclass(cls):
        raise AgentClassError(f"agent {name!r}: {class_name!r} is not a class")
    missing = [m for m in AGENT_METHODS if not callable(getattr(cls, m, None))]
    if missing:
        raise AgentClassError(
            f"agent {name!r} does not satisfy the Agent protocol: no method {', '.join(missing)} "
            f"(an agent has {', '.join(AGENT_METHODS)})"
        )
    required = [
        p.name
        for p in list(inspect.signature(cls).parameters.values())
        if p.default is inspect.Parameter.empty and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    ]
    if required:
        raise AgentClassError(f"agent {name!r} must be constructible with no argument (it needs {required})")
    return cls


def make_agent_object(name: str) -> Any:
    """A fresh instance of the agent class ``name`` names (:func:`load_agent_class`), with a ``name``."""
    agent = load_agent_class(name)()
    if not isinstance(getattr(agent, "name", None), str):
        agent.name = name.partition(":")[2]
    return agent


def check_agent(
    agent: str, memory: str | PathLike[str] | None, checkpoint: str | None, max_lockers: int | None
) -> bool:
    """Refuse an agent that cannot run as asked (``trial.py``'s ``--agent``, ``--memory``, ``--checkpoint``,
    ``--max-lockers``): :class:`AgentClassError` for a class of one's own that is not an agent,
    :class:`TrialConfigError` for the rest (``max_lockers`` None: not given). True for an agent class of one's own."""
    from puzzlebox.learning import AGENT_NAMES, LearningError
    from puzzlebox.learning.agents.factory import BELIEF_AGENT_NAMES
    from puzzlebox.learning.dual_controller import DualControllerConfig

    own = is_agent_class_name(agent)
    if own:
        load_agent_class(agent)
        if memory or checkpoint or max_lockers is not None:
            raise TrialConfigError(
                f"--memory, --checkpoint and --max-lockers are for the project's agents, not {agent!r}"
            )
    elif agent not in AGENT_NAMES:
        raise TrialConfigError(
            f"unknown agent {agent!r}. Available agents: {sorted(AGENT_NAMES)}, or package.module:Class"
        )
    if (agent == "memory") != (memory is not None):
        raise TrialConfigError("--memory goes with --agent memory (and only with it): train one with scripts/train.py")
    if max_lockers is not None and max_lockers != 1:
        if agent not in BELIEF_AGENT_NAMES:
            raise TrialConfigError(f"--max-lockers is for the agents {list(BELIEF_AGENT_NAMES)}, not {agent!r}")
        try:
            DualControllerConfig(max_lockers=max_lockers)
        except LearningError as err:
            raise TrialConfigError(f"--max-lockers: {err}") from err
    return own
