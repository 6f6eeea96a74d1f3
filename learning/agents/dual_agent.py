"""Agents built on the dual controller: ``dual`` (uninformed prior) and ``memory`` (prior from memory)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from puzzlebox.learning.belief import default_prior
from puzzlebox.learning.dual_controller import Decision, DualControllerConfig, decide, max_entropy_for, new_belief
from puzzlebox.learning.holding_pairs import holding_pairs, restrict_single_prior
from puzzlebox.learning.lock_belief import LockBelief
from puzzlebox.learning.memory.keys import se3_pose_keys
from puzzlebox.learning.memory.prior import MemoryConfig, episode_record, recall_memberships, recall_prior
from puzzlebox.learning.memory.store import MemoryStore
from puzzlebox.learning.multi_belief import MultiBelief
from puzzlebox.models import SceneObservation, TryResult


class DualAgent:
    """The paper's dual controller starting every task from the uninformed prior.

    The belief is over one locker per component and state (``config.max_lockers = 1``, the paper's) or over
    sets of up to ``max_lockers`` (:func:`learning.dual_controller.new_belief`); the prior is given in the
    one-locker form either way (:meth:`initial_prior`), with no mass on lockers that cannot hold (:meth:`holding`).
    A world that finds a part's kind wrong (a misread marker: ``skills.robot_world``) observes it by the kind that
    moved it from then on: the belief is then made again from the prior of the kinds observed, and the episode's
    evidence replayed into it (:meth:`record`).

    A component the robot could not try (a ``failed`` try: no evidence about locks) is not chosen again in the same
    joint state while another may be: the agent tries something else and comes back to it once a state changed.
    """

    name = "dual"

    def __init__(self, config: DualControllerConfig | None = None) -> None:
        self.config = config or DualControllerConfig()
        self.belief: LockBelief | None = None
        self.decisions: list[Decision] = []
        self._rng = np.random.default_rng(0)
        self._states = np.zeros(0, dtype=np.int64)
        self._h_max = 1.0
        self._kinds: tuple[str, ...] = ()
        self._evidence: list[tuple[np.ndarray, int, bool]] = []
        """The episode's informative tries: the joint state before the try, the component, whether it moved."""
        self._failed: set[int] = set()
        """Components whose last try failed in :attr:`_failed_in` (the joint state it was made in)."""
        self._failed_in = np.zeros(0, dtype=np.int64)

    def initial_prior(self, observation: SceneObservation) -> np.ndarray:
        """The one-locker prior ``(N, 2, 1 + 2N)`` of a new task."""
        return default_prior(len(observation), self.config.belief.prior_independent)

    def holding(self, observation: SceneObservation) -> np.ndarray | None:
        """``(2N,)`` bool: the pairs that can hold in this scene by its kinds' family rule
        (:mod:`learning.holding_pairs`), or None when every pair can (puzzle boxes, or the rule turned off by
        ``BeliefConfig.family_holding_states``)."""
        if not self.config.belief.family_holding_states:
            return None
        holding = holding_pairs(observation.kinds)
        return None if holding.all() else holding

    def initial_belief(self, observation: SceneObservation) -> LockBelief:
        """The belief a new task starts from: :func:`learning.dual_controller.new_belief` of :meth:`initial_prior`
        (no mass on the pairs that cannot hold, :meth:`holding`)."""
        prior = self.initial_prior(observation)
        holding = self.holding(observation)
        return new_belief(prior if holding is None else restrict_single_prior(prior, holding), self.config)

    def begin_episode(self, observation: SceneObservation, rng: np.random.Generator) -> None:
        self.belief = self.initial_belief(observation)
        self._h_max = max_entropy_for(len(observation), self.config)
        self._rng = rng
        self.decisions = []
        self._kinds = observation.kinds
        self._evidence = []
        self._failed = set()

    def choose(self, observation: SceneObservation) -> int:
        assert self.belief is not None, "begin_episode() first"
        self._states = observation.states.copy()
        avoid = None
        if self._failed and np.array_equal(self._failed_in, self._states):
            avoid = np.zeros(len(self._states), dtype=bool)
            avoid[sorted(self._failed)] = True
        decision = decide(
            self.belief,
            self._states,
            observation.goal_index,
            observation.goal_state,
            self._rng,
            self.config,
            self._h_max,
            avoid,
        )
        self.decisions.append(decision)
        return decision.action

    def record(self, index: int, result: TryResult, observation: SceneObservation) -> None:
        assert self.belief is not None
        if result.informative:  # a failed try (no grasp, IK, marker lost) says nothing about locks
            self.belief.update(self._states, index, result.moved)  # the state in which the try was made
            self._evidence.append((self._states.copy(), index, result.moved))
            self._failed.discard(index)
        else:  # not chosen again in this state while another may be (choose)
            if not np.array_equal(self._failed_in, self._states):
                self._failed = set()
            self._failed.add(index)
            self._failed_in = self._states.copy()
        if observation.kinds != self._kinds:  # the world found a part's kind: its prior, the same evidence
            self._kinds = observation.kinds
            self.belief = self.initial_belief(observation)
            for states, component, moved in self._evidence:
                self.belief.update(states, component, moved)

    def end_episode(self, solved: bool) -> None:
        pass


class MemoryAgent(DualAgent):
    """The dual controller with its prior recalled from a memory of past graphs (the paper's method).

    With ``learn=True`` every finished episode's learned graph is added to the memory (training), and
    the controller explores more (``MemoryConfig.training_entropy_scale``); evaluation leaves the
    memory untouched. An episode is stored under the kinds last observed: a part whose kind the world found
    wrong is remembered as the kind that moved it, never as the misread one (:meth:`DualAgent.record`).
    """

    name = "memory"

    def __init__(
        self,
        store: MemoryStore,
        config: DualControllerConfig | None = None,
        memory_config: MemoryConfig | None = None,
        learn: bool = False,
    ) -> None:
        super().__init__(config)
        self.store = store
        self.memory_config = memory_config or MemoryConfig()
        if learn and self.memory_config.training_entropy_scale is not None:
            self.config = replace(self.config, entropy_scale=self.memory_config.training_entropy_scale)
        self.learn = learn
        self.episode_label = ""
        """Spec name stored with the episode (the training log)."""
        self.episode_seed: int | None = None
        """World seed stored with the episode (the training log)."""
        self.training_run: int | None = None
        """Training-run id from ``MemoryStore.begin_training_run`` the episode belongs to."""
        self.episode_source = "symbolic"
        """Where the episode is experienced (``learning.memory.SOURCES``), stored as its provenance."""
        self.episode_profile: str | None = None
        """The twin's reality profile of the episode (twin episodes), stored as its provenance."""
        self.robot_clock: Callable[[], float] | None = None
        """Reads the simulated robot time the episode has taken so far [s] (twin episodes): stored with it."""
        self._observation: SceneObservation | None = None

    def initial_prior(self, observation: SceneObservation) -> np.ndarray:
        self._observation = observation
        return recall_prior(
            self.store, observation.kinds, observation.poses, self.memory_config, self.config.belief.prior_independent
        )

    def initial_belief(self, observation: SceneObservation) -> LockBelief:
        """With one locker, the recalled prior itself; over sets of lockers, the set prior of the recalled
        memberships (:func:`learning.memory.prior.recall_memberships`), so a memory of "held by both screws"
        starts the belief on the pair of screws (a memory with nothing to recall gives the uninformed prior, read
        as memberships). Both without mass on the lockers that cannot hold (:meth:`holding`)."""
        k = self.config.max_lockers
        if k == 1:
            return super().initial_belief(observation)
        self._observation = observation
        memberships = recall_memberships(
            self.store, observation.kinds, observation.poses, self.memory_config, self.config.belief.prior_independent
        )
        floor, holding = self.memory_config.uniform_mass, self.holding(observation)
        return MultiBelief.from_memberships(memberships, k, self.config.belief, floor, holding)

    def end_episode(self, solved: bool) -> None:
        if not self.learn or self.belief is None or self._observation is None:
            return
        observation = self._observation
        # a belief over sets of lockers is stored as each pair's probability of being among the lockers
        pair_values, independence = episode_record(self.belief.locker_memberships(), self.belief.block_confidence())
        keys = se3_pose_keys(observation.poses, self.store.position_scale, self.store.rotation_weight)
        self.store.add_episode(
            observation.kinds,
            keys,
            pair_values,
            independence,
            spec=self.episode_label,
            solved=solved,
            num_actions=len(self.decisions),
            seed=self.episode_seed,
            training_run=self.training_run,
            source=self.episode_source,
            profile=self.episode_profile,
            robot_time=None if self.robot_clock is None else float(self.robot_clock()),
        )
