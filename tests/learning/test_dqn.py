"""DQN on the graph network learns a small box within a small budget."""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from puzzlebox.learning import RandomAgent, SymbolicWorld, run_episode  # noqa: E402
from puzzlebox.learning.baselines import DQNAgent, DQNConfig, GraphNetworkConfig  # noqa: E402
from puzzlebox.models.generator import generate_chain  # noqa: E402


def test_dqn_learns_a_two_component_box_within_two_hundred_episodes():
    torch.set_num_threads(1)
    spec = generate_chain(["door", "slide"], seed=0)
    config = DQNConfig(
        network=GraphNetworkConfig(blocks=2, hidden=32), tau=0.01, learning_rate=1e-3,
        epsilon_decay=0.98, epsilon_min=0.05, epsilon_eval=0.0,
    )  # fmt: skip
    agent = DQNAgent(config)
    fresh = DQNAgent(config)
    fresh.training = False  # acting only: an evaluation of the untrained network
    untrained = [run_episode(fresh, SymbolicWorld(spec, 1000 + s), "", 1000 + s, 10) for s in range(20)]
    for episode in range(200):
        run_episode(agent, SymbolicWorld(spec, episode), spec.name, episode, 10)
    agent.training = False
    greedy = [run_episode(agent, SymbolicWorld(spec, 1000 + s), spec.name, 1000 + s, 10) for s in range(20)]
    assert all(r.solved and r.num_actions == 2 for r in greedy)  # the optimal plan, in any component order
    random_mean = np.mean(
        [run_episode(RandomAgent(), SymbolicWorld(spec, s), "", s, 10).num_actions for s in range(20)]
    )
    assert random_mean > 2.5 and agent.epsilon < 0.1
    # the untrained network acts without learning anything (no replay needed), and worse than the trained one
    assert fresh.replay_size() == 0 and fresh.episodes == 0
    assert np.mean([r.num_actions for r in untrained]) > np.mean([r.num_actions for r in greedy]) == 2.0


def test_replay_only_updates_once_a_batch_is_available():
    agent = DQNAgent(DQNConfig(network=GraphNetworkConfig(blocks=1, hidden=8), batch_size=4))
    assert agent.update() is None
    spec = generate_chain(["door", "slide"], seed=0)
    run_episode(agent, SymbolicWorld(spec, 0), spec.name, 0, 10)
    assert sum(len(b) for b in agent.replay.values()) >= 2
