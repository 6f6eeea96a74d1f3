"""The deep baselines on computer disassembly (the paper's disassembly experiment; PAPER_NOTES.md):
train a deep agent on one measured lab computer, evaluate it on the others at fixed episode counts.

The graph network is built for the training scene's kind family and pose size (disassembly kinds,
6-DOF poses: ``GraphNetworkConfig.for_spec``). As in the puzzle-box protocol, every episode shuffles
the component order (``SymbolicWorld``'s reset) and world seeds are derived from the training seed
and the episode index, so a call is deterministic for a given seed. Evaluation is the agent's
greedy policy with ``epsilon_eval`` (0.1), without learning, on the same test worlds at every
checkpoint; it does not touch the training random streams, so a checkpoint's numbers do not depend
on which other checkpoints were evaluated.

The DQN agents learn with a dense reward (``progress_reward`` per component removed): the paper's deep
agents needed dense rewards on this task. The model-based agent is a precondition classifier, which
has no reward.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.experiments.scene_evaluation import evaluate_on_scenes
from puzzlebox.learning.symbolic_world import SymbolicWorld
from puzzlebox.learning.trial import run_episode
from puzzlebox.models import PuzzleSpec

DEFAULT_PROGRESS_REWARD = 1.0
"""Dense reward of the DQN agents per component removed (a goal is worth 1, a try -0.05; 0: sparse). Chosen on
validation: DQN trained on lab-computer-a (seed 0), evaluated on 10 variants of lab-computer-a (seeds
5000-5009, never lab-computer-b) after 50 / 100 / 200 episodes: 1.0 solved 100 / 90 / 100 % (10.7, 11.5, 10.7
actions); 0.5: 100 / 90 / 70 %; 0.3: 100 / 70 / 100 %; 0.1: 10 / 0 / 80 %; 0 never removes the motherboard (a
random 24-action episode never gets there, so the goal reward is never seen)."""
TRAIN_SEED_STRIDE = 100_000
"""World seed of training episode ``e`` with training seed ``s``: ``s * TRAIN_SEED_STRIDE + e``."""


def train_deep_on_scene(
    agent: str,
    train_spec: PuzzleSpec,
    test_specs: Sequence[PuzzleSpec],
    checkpoints: Sequence[int],
    seed: int,
    runs_per_test: int = 5,
    max_actions: int = 24,
    progress_reward: float = DEFAULT_PROGRESS_REWARD,
) -> list[dict[str, Any]]:
    """Train deep ``agent`` (``dqn``, ``model-based`` or their ``mt-`` variants) on ``train_spec`` with
    ``seed`` and evaluate it ``runs_per_test`` times on every test spec at each training-episode count
    in ``checkpoints`` (increasing, >= 0; 0 is the untrained network).

    ``max_actions`` is the budget of every episode (the paper: 24); ``progress_reward`` the DQN agents'
    dense reward per component removed (ignored by the model-based agents; 0: sparse reward).

    Returns one record per checkpoint: ``{"episodes", "solved" (fraction of all test runs solved
    within max_actions), "mean_actions" (unsolved runs count max_actions), "per_test": {name: {"solved",
    "mean_actions"}}, "training_solved" (training episodes solved so far)}``.

    Raises:
        ConfigError: bad checkpoints, runs or budget; UnknownAgent: an agent name no factory knows;
        SceneMismatch: a test scene of another kind family or pose size than the training scene.
    """
    import torch  # the baselines extra, only when asked

    from puzzlebox.learning.baselines import GraphNetworkConfig, make_learner

    if not checkpoints or list(checkpoints) != sorted(set(checkpoints)) or checkpoints[0] < 0:
        raise ConfigError(f"checkpoints must be non-empty, increasing and >= 0, got {list(checkpoints)}")
    if max(checkpoints) >= TRAIN_SEED_STRIDE:
        raise ConfigError(f"at most {TRAIN_SEED_STRIDE - 1} training episodes, got {max(checkpoints)}")
    if not 1 <= runs_per_test <= 1000 or max_actions < 1:
        raise ConfigError(f"runs_per_test must be in 1..1000 and max_actions >= 1, got {runs_per_test}, {max_actions}")
    if not test_specs or len({s.name for s in test_specs}) != len(test_specs):
        raise ConfigError(f"test specs must be non-empty with distinct names, got {[s.name for s in test_specs]}")
    network = GraphNetworkConfig.for_spec(train_spec)
    for spec in test_specs:  # fail before training, not at the first evaluation
        network.check_scene(spec.kinds, int(spec.poses_in_world().shape[1]))
    overrides = {"progress_reward": progress_reward} if "dqn" in agent else {}
    torch.set_num_threads(1)  # the networks are small: threads cost more than they give
    learner = make_learner(agent, seed, network, **overrides)

    records, solved_in_training, done = [], 0, 0
    for checkpoint in checkpoints:
        for episode in range(done, checkpoint):
            world_seed = seed * TRAIN_SEED_STRIDE + episode
            world = SymbolicWorld(train_spec, world_seed)
            solved_in_training += run_episode(learner, world, train_spec.name, world_seed, max_actions).solved
        done = checkpoint
        records.append({"episodes": checkpoint, **_evaluate(learner, test_specs, runs_per_test, max_actions),
                        "training_solved": int(solved_in_training)})  # fmt: skip
    return records


def _evaluate(learner: Any, test_specs: Sequence[PuzzleSpec], runs: int, max_actions: int) -> dict[str, Any]:
    """Greedy-with-epsilon_eval runs without learning, on the worlds every agent of the experiment meets."""
    learner.training = False
    try:
        return evaluate_on_scenes(lambda: learner, test_specs, runs, max_actions)
    finally:
        learner.training = True
