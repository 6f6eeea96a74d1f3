"""The model-based baseline learns preconditions and plans the optimal sequence on a small chain."""

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from puzzlebox.learning import SymbolicWorld, run_episode  # noqa: E402
from puzzlebox.learning.baselines import GraphNetworkConfig, ModelBasedAgent, ModelBasedConfig  # noqa: E402
from puzzlebox.models import LockTable  # noqa: E402
from puzzlebox.models.generator import generate_chain  # noqa: E402


def test_learned_preconditions_plan_a_three_component_chain_optimally():
    torch.set_num_threads(1)
    spec = generate_chain(["door", "slide", "wheel"], seed=0)
    config = ModelBasedConfig(
        network=GraphNetworkConfig(blocks=2, hidden=32), learning_rate=1e-3,
        epsilon_decay=0.97, epsilon_min=0.05, epsilon_eval=0.0,
    )  # fmt: skip
    agent = ModelBasedAgent(config)
    for episode in range(150):
        run_episode(agent, SymbolicWorld(spec, episode), spec.name, episode, 15)
    agent.training = False
    runs = [run_episode(agent, SymbolicWorld(spec, 1000 + s), spec.name, 1000 + s, 15) for s in range(10)]
    assert all(r.solved and r.num_actions == 3 for r in runs)
    # the learned preconditions match the lock table in the states the agent visits
    world = SymbolicWorld(spec, 0)
    observation = world.observe()
    free = agent.move_probabilities(observation)
    table = LockTable.from_spec(spec)
    spec_index = [world.env.spec_index(i) for i in range(3)]
    x_obs = 0  # all closed: only the first component of the chain can move
    truth = [table.can_move(0, spec_index[i]) for i in range(3)]
    assert np.array_equal(free[:, x_obs] > 0.5, np.array(truth))
