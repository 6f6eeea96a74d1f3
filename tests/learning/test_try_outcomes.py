"""Failures are not locks: a failed try leaves the agent's belief unchanged, and a component the world cannot try is
a failed try the agent weighs (it tries something else first), not the end of the run while anything can be tried."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.learning import AgentError, DualAgent, SymbolicWorld, run_episode
from puzzlebox.learning.trial import MAX_FAILURES_IN_A_ROW
from puzzlebox.models import TryResult
from puzzlebox.models.generator import paper_family


def _spec():
    return paper_family("test")[0]


def test_failed_try_leaves_the_belief_unchanged():
    world = SymbolicWorld(_spec(), 0)
    agent = DualAgent()
    observation = world.observe()
    agent.begin_episode(observation, np.random.default_rng(0))
    index = agent.choose(observation)
    before = agent.belief.probs.copy()
    agent.record(index, TryResult("failed", "GraspFailure: the gripper closed on nothing"), observation)
    np.testing.assert_array_equal(agent.belief.probs, before)
    agent.record(index, TryResult("blocked", "latched"), observation)
    assert not np.array_equal(agent.belief.probs, before), "a blocked try is evidence and must change the belief"


def test_blocked_and_failed_differ_in_what_the_agent_learns():
    """The same try read as blocked eliminates 'independent'; read as failed it keeps it."""
    world = SymbolicWorld(_spec(), 0)
    observation = world.observe()
    outcomes = {}
    for outcome in ("blocked", "failed"):
        agent = DualAgent()
        agent.begin_episode(observation, np.random.default_rng(0))
        agent.choose(observation)
        agent.record(0, TryResult(outcome), observation)
        outcomes[outcome] = agent.belief.probs[0, 0, 0]
    assert outcomes["blocked"] < 0.01 < outcomes["failed"]


class _NotGraspable(SymbolicWorld):
    """A symbolic world in which the components ``broken`` cannot be grasped for their first ``fails`` tries each
    (forever if None); the world gives each up every time."""

    def __init__(self, spec, seed, broken: set[int], fails: int | None) -> None:
        super().__init__(spec, seed)
        self.broken, self.fails, self.tries = broken, fails, dict.fromkeys(broken, 0)

    def try_toggle(self, index: int) -> TryResult:
        if index in self.broken and (self.fails is None or self.tries[index] < self.fails):
            self.tries[index] += 1
            return TryResult("failed", "GraspFailure: the gripper closed on nothing", give_up=True)
        return super().try_toggle(index)


def _goal(spec, seed: int) -> int:
    return SymbolicWorld(spec, seed).observe().goal_index


def test_a_part_the_robot_could_not_try_is_weighed_not_the_end_of_the_run():
    spec = _spec()
    goal = _goal(spec, 3)  # the goal must be tried eventually: the robot cannot grasp it twice
    world = _NotGraspable(spec, 3, broken={goal}, fails=2)
    result = run_episode(DualAgent(), world, spec.name, 3, max_actions=30)
    assert result.solved and result.ended == ""
    assert world.tries[goal] == 2
    names = [a.component for a in result.actions]
    failed = [k for k, a in enumerate(result.actions) if a.outcome == "failed"]
    assert len(failed) == 2
    for k in failed:  # never tried again in the state it failed in while another part could be tried
        assert names[k + 1] != names[k]


def test_a_run_ends_early_only_when_no_part_can_be_tried():
    spec = _spec()
    world = _NotGraspable(spec, 3, broken=set(range(len(spec.components))), fails=None)
    result = run_episode(DualAgent(), world, spec.name, 3, max_actions=30)
    assert not result.solved
    assert result.num_actions == len(spec.components)  # each tried once, in the one state there is
    assert sorted(world.tries.values()) == [1] * len(spec.components)
    assert "closed on nothing" in result.ended and result.actions[-1].outcome == "failed"


class _NeverGraspable(SymbolicWorld):
    """A symbolic world in which one component can never be grasped."""

    def __init__(self, spec, seed, broken: int) -> None:
        super().__init__(spec, seed)
        self.broken, self.tries = broken, 0

    def try_toggle(self, index: int) -> TryResult:
        if index == self.broken:
            self.tries += 1
            return TryResult("failed", "GraspFailure: the gripper closed on nothing", give_up=True)
        return super().try_toggle(index)


class _Stubborn(DualAgent):
    """Chooses the goal whatever happened (an agent that does not weigh a failed try)."""

    def choose(self, observation):
        return observation.goal_index


def test_an_agent_that_insists_on_a_part_that_cannot_be_tried_is_stopped_with_the_reason():
    spec = _spec()
    world = _NeverGraspable(spec, 3, broken=_goal(spec, 3))
    result = run_episode(_Stubborn(), world, spec.name, 3, max_actions=30)
    assert not result.solved
    assert world.tries == MAX_FAILURES_IN_A_ROW == result.num_actions
    assert "closed on nothing" in result.ended


class _Choosing:
    """A user's agent that chooses ``choice`` every time (or raises it, if it is an exception)."""

    name = "choosing"

    def __init__(self, choice) -> None:
        self.choice = choice

    def begin_episode(self, observation, rng):
        pass

    def choose(self, observation):
        if isinstance(self.choice, BaseException):
            raise self.choice
        return self.choice

    def record(self, index, result, observation):
        pass

    def end_episode(self, solved):
        pass


class _Counting(SymbolicWorld):
    def __init__(self, spec, seed) -> None:
        super().__init__(spec, seed)
        self.tries = 0

    def try_toggle(self, index: int) -> TryResult:
        self.tries += 1
        return super().try_toggle(index)


@pytest.mark.parametrize("choice", [-1, 5, 999, True, 1.0, "0", None])
def test_a_choice_that_is_not_a_part_is_the_agents_error_before_anything_is_tried(choice):
    spec = _spec()  # 5 parts
    world = _Counting(spec, 3)
    with pytest.raises(AgentError, match=r"agent 'choosing' chose .*: the box's parts are 0\.\.4"):
        run_episode(_Choosing(choice), world, spec.name, 3, max_actions=30)
    assert world.tries == 0


def test_an_agent_that_raises_is_named_and_a_ctrl_c_still_stops_the_run():
    spec = _spec()
    for raised in (SystemExit(0), RuntimeError("boom")):
        with pytest.raises(AgentError, match=f"agent 'choosing' raised {type(raised).__name__} in choose"):
            run_episode(_Choosing(raised), SymbolicWorld(spec, 3), spec.name, 3, max_actions=30)
    with pytest.raises(KeyboardInterrupt):
        run_episode(_Choosing(KeyboardInterrupt()), SymbolicWorld(spec, 3), spec.name, 3, max_actions=30)
    run = run_episode(_Choosing(np.int64(0)), SymbolicWorld(spec, 3), spec.name, 3, max_actions=2)
    assert run.num_actions == 2  # a numpy integer is a part
