"""The hypothesis space that fits the scene: how many lockers the belief agents allow one component when no one
says (``--max-lockers`` left out).

The paper's belief gives each component one locker per state (``max_lockers = 1``). A scene whose family holds
parts with several lockers — a computer's motherboard is held by four to six screws, panels and cables — or one
the agent's memory has learned such parts from needs sets of lockers: with one locker, every failed try that no
single locker explains is misread, and a third computer (lab-computer-b and its ten variants, after one episode on
lab-computer-a) took 13.1 actions, one variant never solved in 24; with sets of two, 10.1 (optimum 8.4). So the
default is :data:`SCENE_MAX_LOCKERS` where the scene's family has several lockers (:data:`FAMILY_MAX_LOCKERS`, told
by the kinds the agent sees, never by the scene's lock rules) or where the memory holds an episode that learned a
component held by several (:meth:`learning.memory.store.MemoryStore.learned_several_lockers`), else the paper's 1:
the paper's boxes, chains of one locker each, decide as before, bit for bit. Training follows the training
scenes (:func:`training_max_lockers`): their rules are the trainer's to read. An explicit ``max_lockers`` wins.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence

from puzzlebox.learning.agent_names import BELIEF_AGENT_NAMES
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.models import PuzzleSpec
from puzzlebox.models.disassembly_kinds import DISASSEMBLY_FAMILY

SCENE_MAX_LOCKERS = 2
"""The belief's most lockers where the scene has several: sets of two, chosen for the disassembly experiment on
validation (exact beliefs over every set took 13.0 actions on lab-computer-b and 10 s a run; sets of two 8.8), and
what multi-locker random boxes are generated with (two lockers at most)."""
FAMILY_MAX_LOCKERS: dict[str, int] = {DISASSEMBLY_FAMILY: SCENE_MAX_LOCKERS}
"""Kind families whose scenes hold parts with several lockers (``PuzzleSpec.family``), and the default for them."""


def held_by_several(spec: PuzzleSpec) -> bool:
    """Whether a lock rule of ``spec`` shares its locked part and state with another (a part with two lockers)."""
    held = Counter((rule.locked, rule.locked_state) for rule in spec.locks)
    return any(count > 1 for count in held.values())


def scene_max_lockers(spec: PuzzleSpec, memory: MemoryStore | None = None, agent: str = "memory") -> int:
    """The default ``max_lockers`` of ``agent`` on ``spec`` with ``memory`` (see the module docstring): 1 for an
    agent without a belief over lockers. Only the spec's kinds are read (its family), never its lock rules."""
    if agent not in BELIEF_AGENT_NAMES:
        return 1
    if spec.family in FAMILY_MAX_LOCKERS:
        return FAMILY_MAX_LOCKERS[spec.family]
    if memory is not None and memory.learned_several_lockers():
        return SCENE_MAX_LOCKERS
    return 1


def training_max_lockers(specs: Sequence[PuzzleSpec]) -> int:
    """The default ``max_lockers`` of symbolic training on ``specs``: :data:`SCENE_MAX_LOCKERS` if one is of a family
    with several lockers or has a part held by two, so that the memory learns (and later recalls) them; else 1."""
    several = any(spec.family in FAMILY_MAX_LOCKERS or held_by_several(spec) for spec in specs)
    return SCENE_MAX_LOCKERS if several else 1
