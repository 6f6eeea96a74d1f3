"""puzzlebox/BoxManipulation-v0: the xArm-7 at 20 Hz by end-effector deltas over a puzzle box in the twin, checked by
gymnasium's env checker, seeded, vectorised; a scripted policy opens a free slide through it; the force limit ends
an episode; bad arguments are refused clearly."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env, data_equivalence

import puzzlebox  # noqa: F401  (registers the environment)
from puzzlebox.lab.box_manipulation_env import BoxManipulationEnv
from puzzlebox.lab.errors import ManipulationEnvError
from puzzlebox.lab.manipulation_control import READY_QPOS
from puzzlebox.lab.manipulation_ik import DifferentialIK
from puzzlebox.models.generator.single import single_part
from puzzlebox.skills.kinematics import top_down
from puzzlebox.twin import renderer_pool


def _same(a, b) -> bool:
    """Bit for bit: gymnasium's own comparison of observations (dicts, tuples, arrays and their dtypes)."""
    return data_equivalence(a, b, exact=True)


def open_slide(env: BoxManipulationEnv, obs: dict, slide_yaw: float) -> tuple[dict, list[float]]:
    """A scripted policy through the low-level API alone: turn the fingers to close along the slide's axis while
    moving 6 cm above its handle, descend onto it, close, pull along the axis (``slide_yaw`` [rad], world)."""
    limits = env.controller.limits
    phase, closing, rewards = "above", 0, []
    for _ in range(env.max_steps):
        tcp, handle = obs["tcp_pose"][:3].astype(float), obs["handle_pos"][0].astype(float)
        turn = math.remainder(slide_yaw + math.pi / 2 - env.controller.yaw, math.pi)  # fingers close along gripper y
        goal, grip = handle + (0.0, 0.0, 0.06), -1.0
        if phase == "above" and np.linalg.norm(goal - tcp) < 0.004 and abs(turn) < 0.02:
            phase = "descend"
        if phase == "descend":
            goal = handle
            phase = "close" if np.linalg.norm(goal - tcp) < 0.003 else phase
        if phase == "close":
            goal, grip, closing = handle, 1.0, closing + 1
            phase = "pull" if closing > 20 else phase  # 1/s: 20 steps close the fingers on the post
        if phase == "pull":
            goal = tcp + 0.02 * np.array([math.cos(slide_yaw), math.sin(slide_yaw), 0.0])
        move = np.clip((goal - tcp) / limits.max_translation, -1, 1)
        action = np.array([*move, np.clip(turn / limits.max_yaw, -1, 1), grip], dtype=np.float32)
        obs, reward, terminated, truncated, info = env.step(action)
        rewards.append(reward)
        if terminated or truncated:
            return info, rewards
    raise AssertionError("the episode did not end")


def test_gymnasium_makes_it_and_its_checker_passes():
    env = gymnasium.make("puzzlebox/BoxManipulation-v0", render_mode="rgb_array")
    assert env.action_space == gymnasium.spaces.Box(-1, 1, (5,), np.float32)
    space = env.observation_space
    assert isinstance(space, gymnasium.spaces.Dict)
    assert set(space.keys()) == {"joint_pos", "joint_vel", "tcp_pose", "gripper", "wrench", "part_pos", "handle_pos"}
    check_env(env.unwrapped, skip_render_check=True)
    env.reset(seed=0)
    frame = env.render()
    assert isinstance(frame, np.ndarray) and frame.shape == (480, 640, 3) and frame.dtype == np.uint8
    assert frame.std() > 5
    env.close()


def test_camera_observations_are_small_frames_and_closing_releases_the_renderers():
    env = BoxManipulationEnv(obs_mode="rgb", image_size=64, control_yaw=False)
    check_env(env, skip_render_check=True)
    obs, _ = env.reset(seed=1)
    obs, *_ = env.step(np.zeros(4, dtype=np.float32))
    for key in ("overview", "wrist"):
        assert obs[key].shape == (64, 64, 3) and obs[key].dtype == np.uint8 and obs[key].std() > 5
    assert "part_pos" not in obs and env.observation_space.contains(obs)
    env.close()
    assert env.session is None and not renderer_pool._idle  # nothing of the episode's GL state kept


def _rollout(env: BoxManipulationEnv, seed: int, steps: int) -> list:
    actions = np.random.default_rng(seed).uniform(-1, 1, (steps, 5)).astype(np.float32)
    return [env.reset(seed=seed), *(env.step(a) for a in actions)]


def test_a_seeded_reset_and_the_same_actions_give_the_same_observations_bit_for_bit():
    first = _rollout(BoxManipulationEnv(reality="realistic"), 4, 15)
    again = _rollout(BoxManipulationEnv(reality="realistic"), 4, 15)
    assert _same(first, again)
    other = _rollout(BoxManipulationEnv(reality="realistic"), 5, 0)
    assert first[0][1]["box_pose"] != other[0][1]["box_pose"]  # realistic places the box anew per seed
    assert not np.array_equal(first[-1][0]["wrench"], _rollout(BoxManipulationEnv(), 4, 15)[-1][0]["wrench"])
    ideal = BoxManipulationEnv()  # a session drawing nothing from its seed is reset in place: the same again
    assert _same(_rollout(ideal, 7, 10), _rollout(ideal, 7, 10))


def test_two_async_workers_step_together():
    envs = gymnasium.make_vec("puzzlebox/BoxManipulation-v0", num_envs=2, vectorization_mode="async",
                              reward_mode="sparse", max_steps=5)  # fmt: skip
    obs, _ = envs.reset(seed=0)  # workers seeded 0 and 1
    assert obs["joint_pos"].shape == (2, 7) and obs["handle_pos"].shape == (2, 1, 3)
    for _ in range(6):  # past the time limit: the workers reset themselves
        obs, reward, terminated, truncated, info = envs.step(np.zeros((2, 5), dtype=np.float32))
    assert reward.shape == (2,) and envs.observation_space.contains(obs)
    envs.close()


@pytest.mark.parametrize("reality", ["ideal", "realistic"])
def test_a_scripted_policy_opens_a_free_slide_through_the_low_level_api(reality):
    env = BoxManipulationEnv(reality=reality, reward_mode="sparse" if reality == "ideal" else "dense", max_steps=120)
    obs, info = env.reset(seed=3)
    slide_yaw = info["box_pose"][2] + env.puzzle.components[0].pose[2]  # the slide opens along its +x
    end, rewards = open_slide(env, obs, slide_yaw)
    assert end["success"] and end["reason"] == "goal" and env.session is not None
    assert env.session.component_states()[0] == 1 and len(rewards) < 80
    if reality == "ideal":  # sparse: one reward, on the goal
        assert rewards[-1] == 1.0 and not any(rewards[:-1])
    else:  # dense: the potential's rise plus the goal's 1
        assert sum(rewards) > 1.5 and rewards[-1] > 1.0
    env.close()


def test_one_ik_step_lands_within_a_fraction_of_a_millimetre_of_a_step_away_target():
    ik = DifferentialIK(READY_QPOS)
    start = ik.reset(np.array(READY_QPOS))
    target = start[:3, 3] + (0.01, -0.01, -0.01)  # the largest move of one action, and a 0.1 rad turn
    q = ik.step(target, math.pi + 0.1)
    assert np.linalg.norm(ik.kinematics.tcp_pose()[:3, 3] - target) < 5e-4
    for _ in range(5):
        q = ik.step(target, math.pi + 0.1)
    reached = ik.kinematics.tcp_pose()
    assert np.linalg.norm(reached[:3, 3] - target) < 1e-5
    assert np.allclose(reached[:3, :3], top_down(target, math.pi + 0.1)[:3, :3], atol=1e-4)
    assert np.all(q >= ik.kinematics.model.jnt_range[:7, 0]) and np.all(q <= ik.kinematics.model.jnt_range[:7, 1])


def test_driving_the_hand_into_the_box_ends_the_episode_at_the_force_limit():
    env = BoxManipulationEnv(max_steps=60)
    env.reset(seed=0)
    for _ in range(60):
        _, _, terminated, truncated, info = env.step(np.array([0, 0, -1, 0, 1], dtype=np.float32))  # fingers shut
        if terminated or truncated:
            break
    assert terminated and not truncated and not info["success"]
    assert info["reason"].startswith("force limit") and info["force"] > 60.0
    env.close()


def test_bad_arguments_are_one_clear_error_naming_the_choices():
    cases: list[tuple[dict[str, Any], tuple[str, ...]]] = [
        ({"obs_mode": "pixels"}, ("obs_mode", "'state'", "'rgb'")),
        ({"reward_mode": "shaped"}, ("reward_mode", "'sparse'", "'dense'")),
        ({"spec": 42}, ("spec", "PuzzleSpec", "'slide'")),
        ({"spec": "no/such/box.json"}, ("spec", "no/such/box.json")),
        ({"spec": replace(single_part(), box=None)}, ("disassembly",)),
        ({"reality": "sunny"}, ("reality", "realistic", "harsh")),
        ({"max_steps": 0}, ("max_steps",)),
    ]
    for kwargs, words in cases:
        with pytest.raises(ManipulationEnvError) as err:
            BoxManipulationEnv(**kwargs)
        assert isinstance(err.value, ValueError) and all(w in str(err.value) for w in words), str(err.value)
    env = BoxManipulationEnv(spec="wheel")  # a kind's name: a one-part box of it
    assert [c.kind for c in env.puzzle.components] == ["wheel"]
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(np.zeros(5, dtype=np.float32))
    env.reset(seed=0)
    with pytest.raises(ManipulationEnvError, match="5 finite numbers"):
        env.step(np.array([0, 0, np.nan, 0, 0]))
    env.close()
