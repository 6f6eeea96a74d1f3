"""puzzlebox/TwinPuzzle-v0: the twin at the option level as a gymnasium environment, with the symbolic
environment's spaces, seeded, checked by gymnasium's env checker."""

from __future__ import annotations

from dataclasses import replace

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env, data_equivalence

import puzzlebox  # noqa: F401  (registers the environment)
from puzzlebox.lab import TrialConfig, TrialConfigError
from puzzlebox.lab.twin_puzzle_env import TwinPuzzleEnv
from puzzlebox.learning import PuzzleEnv
from puzzlebox.models.generator import paper_family

SPEC = paper_family("test")[0]


def test_gymnasium_makes_it_with_the_symbolic_environments_spaces_and_its_checker_passes():
    env = gymnasium.make("puzzlebox/TwinPuzzle-v0", spec=SPEC, render_mode="rgb_array")
    symbolic = PuzzleEnv(SPEC)
    assert env.observation_space == symbolic.observation_space and env.action_space == symbolic.action_space
    check_env(env.unwrapped)
    env.reset(seed=0)
    frame = env.render()
    assert frame.shape == (480, 640, 3) and frame.dtype == np.uint8 and frame.std() > 5
    env.close()


def _episode(seed: int, actions: list[int]) -> list:
    env = TwinPuzzleEnv(SPEC, TrialConfig(reality="realistic"), ground_truth=True)
    out = [env.reset(seed=seed)]
    out += [env.step(a) for a in actions]
    env.close()
    return out


def _same(a, b) -> bool:
    """Bit for bit: gymnasium's own comparison of observations (dicts, tuples, arrays and their dtypes)."""
    return data_equivalence(a, b, exact=True)


def test_a_seeded_reset_and_the_same_actions_give_the_same_observations_bit_for_bit():
    first, again = _episode(4, [0, 1]), _episode(4, [0, 1])
    assert _same(first, again)
    (_, info), (obs, reward, terminated, truncated, step) = first[0], first[1]
    assert info["sim_time_s"] > 0 and step["outcome"] in ("moved", "blocked") and "true_moved" in step
    assert reward == 0.0 and not terminated and not truncated  # one try does not open a paper box
    assert obs["states"].sum() == int(step["moved"]) and step["moved"] == step["true_moved"]
    assert not _same(first[0][0]["poses"], _episode(5, [])[0][0]["poses"])  # another seed: another placement


def test_what_cannot_run_is_refused_clearly():
    with pytest.raises(TrialConfigError, match="disassembly scene"):
        TwinPuzzleEnv(replace(SPEC, box=None))
    with pytest.raises(TrialConfigError, match="render_mode"):
        TwinPuzzleEnv(SPEC, render_mode="human")
    with pytest.raises(TrialConfigError, match="sim must be 'twin'"):
        TwinPuzzleEnv(SPEC, TrialConfig(sim="symbolic"))
    env = TwinPuzzleEnv(SPEC)
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(0)


def test_gymnasium_make_with_arguments_of_the_wrong_type_is_a_typed_error_naming_what_is_wanted():
    """A spec given as a number or a path, a config of the wrong class: a library error saying what is wanted (a
    raw ``AttributeError: 'int' object has no attribute 'components'`` before), before any physics is built."""
    from puzzlebox.learning import ConfigError

    for wrong in (5, "paper-test-0.json"):
        with pytest.raises(ConfigError, match="spec must be a PuzzleSpec, got"):
            gymnasium.make("puzzlebox/Puzzle-v0", spec=wrong)
        with pytest.raises(TrialConfigError, match="spec must be a PuzzleSpec, got"):
            gymnasium.make("puzzlebox/TwinPuzzle-v0", spec=wrong)
    with pytest.raises(ConfigError, match="config must be a PuzzleEnvConfig"):
        gymnasium.make("puzzlebox/Puzzle-v0", spec=SPEC, config=3)
    with pytest.raises(TrialConfigError, match="config must be a TrialConfig"):
        gymnasium.make("puzzlebox/TwinPuzzle-v0", spec=SPEC, config={"sim": "twin"})
    with pytest.raises(TrialConfigError, match="max_actions must be an integer"):
        gymnasium.make("puzzlebox/TwinPuzzle-v0", spec=SPEC, max_actions=2.5)


def test_an_agent_acting_through_the_environment_makes_the_trials_tries():
    """The project's dual agent driven through the gymnasium API (observations rebuilt by the world, outcomes
    from ``info``) tries what ``run_trial`` tries for the same seed, with the same sensed outcomes."""
    from puzzlebox.lab import run_trial
    from puzzlebox.learning import make_agent
    from puzzlebox.learning.belief import CELL_BELIEF
    from puzzlebox.models import TryResult

    config = TrialConfig(agent="dual", seed=1, max_actions=5)
    record = run_trial(SPEC, config)
    env = TwinPuzzleEnv(SPEC, config, max_actions=5)
    env.reset(seed=1)
    assert env.world is not None
    agent = make_agent("dual", SPEC, belief=CELL_BELIEF)
    scene = env.world.observe()
    agent.begin_episode(scene, np.random.default_rng(1))
    tries, done = [], False
    while not done:
        action = agent.choose(scene)
        _, _, terminated, truncated, info = env.step(action)
        scene = env.world.observe()
        agent.record(action, TryResult(info["outcome"], info["reason"], info["give_up"]), scene)
        tries.append((env.world.ground_truth_name(action), info["moved"], info["outcome"], info["reason"]))
        done = terminated or truncated
    env.close()
    assert len(tries) == record.num_actions == 5 and {t[2] for t in tries} == {"moved", "blocked"}
    assert tries == [(a.component, a.moved, a.outcome, a.reason) for a in record.actions]
