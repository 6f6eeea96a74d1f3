"""Failures are not locks: a failed try leaves the agent's belief unchanged, and a component the world
cannot try is reported, not looped on."""

from __future__ import annotations

import numpy as np
import pytest

from puzzlebox.learning import DualAgent, SymbolicWorld, run_episode
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


class _NeverGraspable(SymbolicWorld):
    """A symbolic world in which one component can never be grasped."""

    def __init__(self, spec, seed, broken: int, give_up: bool) -> None:
        super().__init__(spec, seed)
        self.broken, self.give_up, self.tries = broken, give_up, 0

    def try_toggle(self, index: int) -> TryResult:
        if index == self.broken:
            self.tries += 1
            return TryResult("failed", "GraspFailure: the gripper closed on nothing", give_up=self.give_up)
        return super().try_toggle(index)


@pytest.mark.parametrize("give_up", [True, False])
def test_a_component_that_cannot_be_tried_ends_the_run_with_its_reason(give_up):
    spec = _spec()
    probe = SymbolicWorld(spec, 3)
    goal = probe.observe().goal_index  # the goal must be tried eventually: make it the broken one
    world = _NeverGraspable(spec, 3, broken=goal, give_up=give_up)
    result = run_episode(DualAgent(), world, spec.name, 3, max_actions=30)
    assert not result.solved
    assert result.num_actions < 30, "the run looped on a component it cannot try"
    assert world.tries == (1 if give_up else MAX_FAILURES_IN_A_ROW)
    assert "closed on nothing" in result.ended
    assert result.actions[-1].outcome == "failed"
