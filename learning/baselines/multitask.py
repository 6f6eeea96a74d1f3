"""MT-OPT's cross-task data sharing (Kalashnikov et al. 2021) for puzzles: tasks are "bring component g
to its goal state", one per component, and an episode collected for one task is relabelled for every
other task whose reward can be computed from the recorded states.

The node features carry the task as a goal flag (``graph_network.observation_tensors``), so relabelling
moves the flag; rewards and episode ends follow from the state column. The true task of a paper box is
"open the last component of the chain"; its relabelled siblings are "open component g" for every other
g, which teaches the network what opens each component in any state — the shared structure MT-OPT
exploits.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from puzzlebox.models import KIND_NAMES

STATE_COLUMN = len(KIND_NAMES)
"""Node-feature column of the component state (0/1) for the puzzle-box family; in general
``GraphNetworkConfig.state_column`` (the columns follow the network's kinds)."""
GOAL_COLUMN = len(KIND_NAMES) + 1
"""Node-feature column of the goal flag for the puzzle-box family (``GraphNetworkConfig.goal_column``)."""


def with_goal(nodes: np.ndarray, goal: int, goal_column: int = GOAL_COLUMN) -> np.ndarray:
    """A copy of node features ``(N, F)`` with the goal flag (column ``goal_column``) on component
    ``goal`` only."""
    relabelled = nodes.copy()
    relabelled[:, goal_column] = 0.0
    relabelled[goal, goal_column] = 1.0
    return relabelled


@dataclass
class Step:
    """One try of an episode: features before, the component tried, features after."""

    nodes: np.ndarray
    edges: np.ndarray
    action: int
    next_nodes: np.ndarray
    next_edges: np.ndarray


@dataclass
class RelabelledStep:
    """A step for one task: its reward and whether it ended that task."""

    nodes: np.ndarray
    edges: np.ndarray
    action: int
    reward: float
    next_nodes: np.ndarray
    next_edges: np.ndarray
    done: bool


def relabel_episode(
    steps: Sequence[Step],
    goal_index: int,
    goal_state: int,
    goal_reward: float,
    step_reward: float,
    all_tasks: bool = True,
    progress_reward: float = 0.0,
    columns: tuple[int, int] = (STATE_COLUMN, GOAL_COLUMN),
) -> list[tuple[int, list[RelabelledStep], bool]]:
    """Per task ``g``: the episode's steps as seen by task g, cut after g reached its goal, and whether
    it did (a success episode for that task). The true task keeps ``goal_state``; every other
    component's goal is the opposite of its state at the start (a task never starts solved).
    ``all_tasks=False`` returns the true task only (no sharing). ``progress_reward`` is added to a
    non-final step that moved its component (:func:`progress`); ``columns`` are the network's
    ``(state_column, goal_column)``."""
    if not steps:
        return []
    state_column, goal_column = columns
    start = steps[0].nodes[:, state_column]
    tasks = range(len(start)) if all_tasks else [goal_index]
    relabelled = []
    for g in tasks:
        target = goal_state if g == goal_index else 1.0 - start[g]
        if start[g] == target:
            continue
        episode: list[RelabelledStep] = []
        for step in steps:
            done = bool(step.next_nodes[g, state_column] == target)
            shaping = progress_reward * progress(step.nodes, step.next_nodes, step.action, state_column)
            episode.append(
                RelabelledStep(
                    with_goal(step.nodes, g, goal_column),
                    step.edges,
                    step.action,
                    goal_reward if done else step_reward + shaping,
                    with_goal(step.next_nodes, g, goal_column),
                    step.next_edges,
                    done,
                )
            )
            if done:
                break
        relabelled.append((g, episode, episode[-1].done))
    return relabelled


def progress(nodes: np.ndarray, next_nodes: np.ndarray, action: int, state_column: int) -> int:
    """+1 if the try removed (opened) component ``action`` (state 0 -> 1), -1 if it put it back
    (1 -> 0), 0 if it did not move. Paying the dense reward with this sign, not on every move, makes
    a remove-and-reinsert cycle earn nothing, so the agent cannot farm it."""
    return int(next_nodes[action, state_column]) - int(nodes[action, state_column])
