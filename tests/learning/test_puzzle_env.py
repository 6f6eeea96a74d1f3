import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from puzzlebox.learning import ConfigError, FaultConfig, InvalidAction, PuzzleEnv, PuzzleEnvConfig
from puzzlebox.models import KIND_NAMES, Box, Component, Goal, LockRule, PuzzleSpec, kind_code
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_random, paper_family

SYMBOLIC_BOX = BoxConfig(realizable=False)
"""Random boxes as drawn before lock mechanisms existed: these symbolic tests chose their seeds for their graphs."""


@pytest.fixture
def paper_spec():
    return paper_family("test")[0]


def two_locker_spec():
    """Slide s is held closed by both d1 and d2 (doors); goal: s open."""
    components = (
        Component("d1", "door", (-0.1, 0.0, 0.0), 0),
        Component("d2", "door", (0.1, 0.0, 0.0), 1),
        Component("s", "slide", (-0.03, 0.1, 0.0), 2),
    )
    locks = (LockRule("d1", 0, "s", 0), LockRule("d2", 0, "s", 0))
    return PuzzleSpec("two-lockers", components, locks, Goal("s"), Box((0.4, 0.4, 0.08)))


def spec_index_of(env, obs_index):
    return env.spec_index(obs_index)


def obs_index_of(env, name):
    j = env.puzzle.index_of(name)
    return int(np.flatnonzero(env.order == j)[0])


def test_passes_gymnasium_check_env(paper_spec):
    check_env(PuzzleEnv(paper_spec), skip_render_check=True)
    check_env(
        PuzzleEnv(generate_random(RandomGraphConfig(9, multi_locker=True), seed=2, box=SYMBOLIC_BOX)),
        skip_render_check=True,
    )


def test_two_locker_component_moves_only_when_both_lockers_are_open():
    env = PuzzleEnv(two_locker_spec())
    env.reset(seed=0)
    s, d1, d2 = (obs_index_of(env, n) for n in ("s", "d1", "d2"))
    assert not env.step(s)[4]["moved"]
    assert env.step(d1)[4]["moved"]
    assert not env.step(s)[4]["moved"]
    assert env.step(d2)[4]["moved"]
    _, reward, terminated, truncated, info = env.step(s)
    assert info["moved"] and terminated and not truncated and reward == 1.0


def test_paper_chain_opens_only_in_order_and_terminates_on_the_goal(paper_spec):
    env = PuzzleEnv(paper_spec)
    obs, _ = env.reset(seed=3)
    names = paper_spec.component_names
    for k, name in enumerate(names):
        later = [obs_index_of(env, n) for n in names[k + 1 :]]
        for i in later:  # everything after the first closed component is still locked
            assert not env.step(i)[4]["moved"]
        obs, _, terminated, _, info = env.step(obs_index_of(env, name))
        assert info["moved"]
        assert terminated == (k == len(names) - 1)
    assert obs["states"].tolist() == [1] * 5


def test_observation_order_is_shuffled_per_seeded_reset_and_reproducible(paper_spec):
    env = PuzzleEnv(paper_spec)
    orders = {tuple(env.reset(seed=s)[0]["kinds"]) + tuple(env.order) for s in range(10)}
    assert len(orders) > 1
    a, _ = env.reset(seed=42)
    b, _ = PuzzleEnv(paper_spec).reset(seed=42)
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])


def test_observation_holds_kinds_poses_and_goal_but_no_names_or_locks(paper_spec):
    env = PuzzleEnv(paper_spec)
    obs, info = env.reset(seed=0)
    assert set(obs) == {"states", "kinds", "poses", "goal"}
    assert set(info) == {"moved", "num_actions"}
    goal = int(obs["goal"])
    assert env.spec_index(goal) == env.puzzle.index_of(paper_spec.goal.component)
    for i in range(5):
        j = env.spec_index(i)
        assert KIND_NAMES[obs["kinds"][i]] == paper_spec.components[j].kind


def test_poses_are_in_the_world_frame_of_the_box_pose(paper_spec):
    env = PuzzleEnv(paper_spec)
    obs, _ = env.reset(seed=0)
    bx, by, _ = paper_spec.box.pose
    for i in range(5):
        lid_x, lid_y, lid_yaw = paper_spec.components[env.spec_index(i)].pose
        np.testing.assert_allclose(obs["poses"][i][:2], [bx + lid_x, by + lid_y], atol=1e-12)
        yaw_error = (obs["poses"][i][2] - lid_yaw + np.pi) % (2 * np.pi) - np.pi
        assert abs(yaw_error) < 1e-6
        assert -np.pi <= obs["poses"][i][2] < np.pi


def test_truncates_at_the_action_budget(paper_spec):
    env = PuzzleEnv(paper_spec, PuzzleEnvConfig(max_actions=3))
    env.reset(seed=0)
    locked = obs_index_of(env, paper_spec.components[-1].name)
    flags = [env.step(locked)[2:4] for _ in range(3)]
    assert flags == [(False, False), (False, False), (False, True)]


def test_same_seed_and_actions_give_identical_episodes_with_jams(paper_spec):
    config = PuzzleEnvConfig(faults=FaultConfig(jam_probability=0.3))

    def episode(seed):
        env = PuzzleEnv(paper_spec, config)
        env.reset(seed=seed)
        rng = np.random.default_rng(0)
        return [env.step(int(rng.integers(5)))[4]["moved"] for _ in range(40)]

    assert episode(11) == episode(11)


def test_jams_stop_unlocked_components_at_the_configured_rate():
    spec = paper_family("test")[0]
    env = PuzzleEnv(spec, PuzzleEnvConfig(max_actions=10_000, faults=FaultConfig(jam_probability=0.25)))
    env.reset(seed=1)
    first = obs_index_of(env, spec.components[0].name)  # never locked
    moved = [env.step(first)[4]["moved"] for _ in range(2000)]
    assert abs((1 - np.mean(moved)) - 0.25) < 0.04


def test_misreported_kinds_change_exactly_that_many_components(paper_spec):
    env = PuzzleEnv(paper_spec, PuzzleEnvConfig(faults=FaultConfig(misreported_kinds=2)))
    for seed in range(5):
        obs, _ = env.reset(seed=seed)
        true = np.array([kind_code(paper_spec.components[env.spec_index(i)].kind) for i in range(5)])
        assert int((obs["kinds"] != true).sum()) == 2


def test_pose_noise_has_the_configured_spread(paper_spec):
    faults = FaultConfig(position_noise_std=0.01, yaw_noise_std=0.05)
    clean = PuzzleEnv(paper_spec)
    noisy = PuzzleEnv(paper_spec, PuzzleEnvConfig(faults=faults))
    errors_xy, errors_yaw = [], []
    for seed in range(200):
        a, _ = clean.reset(seed=seed)
        b, _ = noisy.reset(seed=seed)
        errors_xy.append(b["poses"][:, :2] - a["poses"][:, :2])
        errors_yaw.append((b["poses"][:, 2] - a["poses"][:, 2] + np.pi) % (2 * np.pi) - np.pi)
    assert abs(np.std(errors_xy) - 0.01) < 0.001
    assert abs(np.std(errors_yaw) - 0.05) < 0.005


def test_invalid_actions_and_configs_are_clear_errors(paper_spec):
    env = PuzzleEnv(paper_spec)
    env.reset(seed=0)
    for bad in (5, -1, 1.5, "0"):
        with pytest.raises(InvalidAction, match="0..4"):
            env.step(bad)
    with pytest.raises(ConfigError):
        PuzzleEnv(paper_spec, PuzzleEnvConfig(faults=FaultConfig(jam_probability=1.5)))
    with pytest.raises(ConfigError):
        PuzzleEnv(paper_spec, PuzzleEnvConfig(faults=FaultConfig(misreported_kinds=6)))
    with pytest.raises(ConfigError):
        PuzzleEnv(paper_spec, PuzzleEnvConfig(max_actions=0))


def test_ansi_render_lists_every_component(paper_spec):
    env = PuzzleEnv(paper_spec, render_mode="ansi")
    env.reset(seed=0)
    text = env.render()
    assert text.count("state 0") == 5 and "(goal)" in text


def test_a_turned_box_turns_the_observed_poses(paper_spec):
    from dataclasses import replace

    turned = replace(paper_spec, box=replace(paper_spec.box, pose=(0.3, 0.2, np.pi / 2)))
    env = PuzzleEnv(turned)
    obs, _ = env.reset(seed=0)
    for i in range(5):
        lid_x, lid_y, _ = turned.components[env.spec_index(i)].pose
        np.testing.assert_allclose(obs["poses"][i][:2], [0.3 - lid_y, 0.2 + lid_x], atol=1e-12)


def test_boxes_with_new_kinds_code_kinds_in_the_registry_family_and_pass_check_env():
    from puzzlebox.models.generator import generate_chain
    from puzzlebox.models.kinds import registry_family

    spec = generate_chain(["door", "drawer", "lever", "wheel"], seed=1)
    env = PuzzleEnv(spec)
    check_env(env, skip_render_check=True)
    assert env.kind_names == registry_family().kinds
    obs, _ = env.reset(seed=0)
    assert sorted(env.kind_names[k] for k in obs["kinds"]) == sorted(spec.kinds)
