"""MT-OPT for puzzles: episodes relabelled for every component's task, balanced batches, and the
multi-task agents still learn a small box."""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from puzzlebox.learning import SymbolicWorld, run_episode  # noqa: E402
from puzzlebox.learning.baselines import (  # noqa: E402
    DQNAgent,
    DQNConfig,
    GraphNetworkConfig,
    ModelBasedAgent,
    ModelBasedConfig,
    make_learner,
)
from puzzlebox.learning.baselines.multitask import GOAL_COLUMN, STATE_COLUMN, Step, relabel_episode  # noqa: E402
from puzzlebox.learning.errors import UnknownAgent  # noqa: E402
from puzzlebox.models.generator import generate_chain  # noqa: E402

SMALL = GraphNetworkConfig(blocks=1, hidden=16)


def _nodes(states, goal=2):
    nodes = np.zeros((len(states), GOAL_COLUMN + 1), dtype=np.float32)
    nodes[:, STATE_COLUMN] = states
    nodes[goal, GOAL_COLUMN] = 1.0
    return nodes


def _episode():
    """A 3-chain opened in order 0, 1 (fails once on 2 first), then 2: states after each try."""
    edges = np.zeros((3, 3, 4), dtype=np.float32)
    states = [[0, 0, 0], [0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1]]
    actions = [2, 0, 1, 2]
    return [Step(_nodes(states[t]), edges, actions[t], _nodes(states[t + 1]), edges) for t in range(4)]


def test_an_episode_is_relabelled_for_every_component_and_cut_when_that_task_is_done():
    tasks = {g: (steps, success) for g, steps, success in relabel_episode(_episode(), 2, 1, 1.0, -0.05)}
    assert sorted(tasks) == [0, 1, 2]
    for g, (steps, success) in tasks.items():
        assert success and steps[-1].done and not any(s.done for s in steps[:-1])
        assert all(s.nodes[:, GOAL_COLUMN].argmax() == g == s.next_nodes[:, GOAL_COLUMN].argmax() for s in steps)
        assert [s.reward for s in steps] == [-0.05] * (len(steps) - 1) + [1.0]
    assert [len(tasks[g][0]) for g in (0, 1, 2)] == [2, 3, 4]  # task 0 ends at the 2nd try, task 1 at the 3rd
    only_true = relabel_episode(_episode(), 2, 1, 1.0, -0.05, all_tasks=False)
    assert [g for g, _, _ in only_true] == [2]


def test_unreached_tasks_are_failures_and_tasks_already_at_their_goal_are_skipped():
    steps = _episode()[:2]  # component 0 opened, nothing else
    tasks = {g: success for g, _, success in relabel_episode(steps, 2, 1, 1.0, -0.05)}
    assert tasks == {0: True, 1: False, 2: False}
    assert relabel_episode(steps, 0, 0, 1.0, -0.05, all_tasks=False) == []  # the goal state holds at the start
    assert relabel_episode([], 2, 1, 1.0, -0.05) == []


def test_balanced_batches_are_half_successes_and_unbalanced_follow_the_data():
    for balance, expected in ((True, 8), (False, None)):
        agent = DQNAgent(DQNConfig(network=SMALL, batch_size=16, balance=balance))
        for i in range(200):
            agent.store(("s", i), 5, True) if i < 20 else agent.store(("f", i), 5, False)
        counts = [sum(tag == "s" for tag, _ in agent.sample_batch()) for _ in range(200)]
        if expected is not None:
            assert set(counts) == {expected}
        else:
            assert 1.0 < np.mean(counts) < 2.2  # 10% successes in the data -> 1.6 per batch of 16
    assert DQNAgent(DQNConfig(network=SMALL)).sample_batch() is None  # nothing stored yet


def test_mt_dqn_stores_every_task_of_an_episode_and_names_itself():
    agent = DQNAgent(DQNConfig.multitask(network=SMALL, batch_size=4))
    assert agent.name == "mt-dqn" and DQNAgent(DQNConfig(network=SMALL)).name == "dqn"
    spec = generate_chain(["door", "slide", "wheel"], seed=0)
    result = run_episode(agent, SymbolicWorld(spec, 0), spec.name, 0, 20)
    plain = DQNAgent(DQNConfig(network=SMALL, batch_size=4))
    run_episode(plain, SymbolicWorld(spec, 0), spec.name, 0, 20)
    assert result.solved
    assert agent.replay_size() > plain.replay_size() == result.num_actions  # every task got its copy
    assert agent.replay[(3, True)]  # ... and the solved tasks were filed as successes


def test_mt_model_based_stores_each_try_under_every_goal_balanced_by_outcome():
    agent = ModelBasedAgent(ModelBasedConfig.multitask(network=SMALL, batch_size=4))
    assert agent.name == "mt-model-based"
    spec = generate_chain(["door", "slide", "wheel"], seed=0)
    result = run_episode(agent, SymbolicWorld(spec, 0), spec.name, 0, 20)
    assert agent.replay_size() == 3 * result.num_actions
    moved = [e.moved for key, buffer in agent.replay.items() for e in buffer if key[1]]
    unmoved = [e.moved for key, buffer in agent.replay.items() for e in buffer if not key[1]]
    assert all(moved) and not any(unmoved)


def test_mt_dqn_learns_a_two_component_box_within_two_hundred_episodes():
    torch.set_num_threads(1)
    spec = generate_chain(["door", "slide"], seed=0)
    config = DQNConfig.multitask(
        network=GraphNetworkConfig(blocks=2, hidden=32), tau=0.01, learning_rate=1e-3,
        epsilon_decay=0.98, epsilon_min=0.05, epsilon_eval=0.0,
    )  # fmt: skip
    agent = DQNAgent(config)
    for episode in range(200):
        run_episode(agent, SymbolicWorld(spec, episode), spec.name, episode, 10)
    agent.training = False
    greedy = [run_episode(agent, SymbolicWorld(spec, 1000 + s), spec.name, 1000 + s, 10) for s in range(20)]
    assert all(r.solved and r.num_actions == 2 for r in greedy)


def test_learners_by_name_and_unknown_names_list_what_exists():
    assert {make_learner(n).name for n in ("dqn", "mt-dqn", "model-based", "mt-model-based")} == {
        "dqn", "mt-dqn", "model-based", "mt-model-based"
    }  # fmt: skip
    with pytest.raises(UnknownAgent, match="mt-dqn"):
        make_learner("ppo")
