"""Speed figures of ``puzzlebox/BoxManipulation-v0``, for ``bench.py``: the environment's step (state observations,
dense reward, ideal cell; the default one-part slide box and a paper test box) against bare ``mujoco.mj_step`` over
the same simulated time, and ``make_vec`` with two asynchronous workers against one.

The bare figure replays the environment's own run: the same model, from the same state, the same servo targets
written at every control step, 25 ``mj_step`` per control step (one call each, as a Python user steps, and
``nstep`` in C): the same physics, bit for bit, without the environment's IK, sensors, observations and rewards.
Actions are seeded random ones, small enough (30 % of the limits) that the hand wanders without striking the box.
Rates are given per second of wall time and per second of this process's CPU time: on a shared machine the second
leaves out the time other processes held the cores (the load average is recorded beside them).
"""

from __future__ import annotations

import os
import time
from typing import Any

import numpy as np

from puzzlebox.models import PuzzleSpec

ACTION_SCALE = 0.3
"""Random actions are uniform in ``+-ACTION_SCALE`` (the gripper command in ``+-1``)."""
CHUNK = 20
"""Control steps each run takes in turn (1 s of simulated time): every run meets the same load."""


def _actions(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    actions = rng.uniform(-ACTION_SCALE, ACTION_SCALE, shape)
    actions[..., -1] = rng.uniform(-1.0, 1.0, shape[:-1])
    return actions.astype(np.float32)


def step_figures(quick: bool, spec: PuzzleSpec | None = None) -> dict[str, Any]:
    """Control steps per second of the environment on ``spec`` (default the one-part slide) and the bare ``mj_step``
    rates over the same simulated time, interleaved (medians), with their ratios (``env_over_bare_*``: the throughput
    target is >= 0.75)."""
    import mujoco

    from puzzlebox.lab.box_manipulation_env import BoxManipulationEnv
    from puzzlebox.lab.manipulation_control import CONTROL_PERIOD

    steps = 100 if quick else 400
    env = BoxManipulationEnv(spec, max_steps=10 * steps)
    actions = _actions(np.random.default_rng(0), (steps, 5))
    env.reset(seed=0)
    session = env.session
    assert session is not None
    model, substeps = session.model, round(CONTROL_PERIOD / session.timestep)
    signature = mujoco.mjtState.mjSTATE_INTEGRATION
    start = np.empty(mujoco.mj_stateSize(model, signature))
    mujoco.mj_getState(model, session.data, start, signature)
    controls = []
    for action in actions:  # the run to replay: every control step's servo targets
        _, _, terminated, truncated, _ = env.step(action)
        controls.append(session.data.ctrl.copy())
        if terminated or truncated:
            raise RuntimeError("the bench's random walk ended its episode: the figures would mix in a reset")
    end = session.data.qpos.copy()
    bare = {way: mujoco.MjData(model) for way in ("per_call", "nstep")}

    def environment(k: slice) -> None:
        for action in actions[k]:
            env.step(action)

    def per_call(k: slice) -> None:
        d = bare["per_call"]
        for ctrl in controls[k]:
            d.ctrl[:] = ctrl
            for _ in range(substeps):
                mujoco.mj_step(model, d)

    def nstep(k: slice) -> None:
        d = bare["nstep"]
        for ctrl in controls[k]:
            d.ctrl[:] = ctrl
            mujoco.mj_step(model, d, nstep=substeps)

    runs = {"env_step": environment, "bare_mj_step_per_call": per_call, "bare_mj_step_nstep": nstep}
    samples: dict[str, list[float]] = {}
    load = os.getloadavg()[0]
    for _ in range(3 if quick else 7):  # medians of runs interleaved every CHUNK control steps: the load changes
        env.reset(seed=0)
        for d in bare.values():
            mujoco.mj_setState(model, d, start, signature)
        spent = {label: np.zeros(2) for label in runs}  # wall, CPU [s]
        for k in range(0, steps, CHUNK):
            for label, run in runs.items():
                wall, cpu = time.perf_counter(), time.process_time()
                run(slice(k, k + CHUNK))
                spent[label] += (time.perf_counter() - wall, time.process_time() - cpu)
        for label, (wall, cpu) in spent.items():
            samples.setdefault(f"{label}_control_steps_per_s", []).append(steps / wall)
            samples.setdefault(f"{label}_control_steps_per_cpu_s", []).append(steps / cpu)
    env.close()
    rates = {key: float(np.median(v)) for key, v in samples.items()}  # control steps per second
    out: dict[str, Any] = {
        "spec": env.puzzle.name,
        "control_steps": steps,
        "substeps": substeps,
        "replay_is_the_same_physics": all(bool(np.array_equal(d.qpos, end)) for d in bare.values()),
        "load_average_1min": [load, os.getloadavg()[0]],
        **rates,
    }
    for clock, suffix in (("s", ""), ("cpu_s", "_cpu")):  # the ratios in wall time, then in CPU time
        env_rate = rates[f"env_step_control_steps_per_{clock}"]
        for way in ("per_call", "nstep"):
            out[f"env_over_bare_{way}{suffix}"] = env_rate / rates[f"bare_mj_step_{way}_control_steps_per_{clock}"]
    return out


def vector_figures(quick: bool) -> dict[str, Any]:
    """Environment steps per second (all workers together) of ``gymnasium.make_vec(..., vectorization_mode="async")``
    with one and with two workers, and of one environment in this process, with the speed-ups of two workers."""
    import gymnasium

    import puzzlebox  # noqa: F401  (registers the environment)
    from puzzlebox.lab.box_manipulation_env import BoxManipulationEnv

    steps = 100 if quick else 400
    rates: dict[str, list[float]] = {"one_env": [], "async_1": [], "async_2": []}
    for _ in range(1 if quick else 3):
        for label in rates:
            n = 2 if label == "async_2" else 1
            actions = _actions(np.random.default_rng(1), (steps, n, 5))
            if label == "one_env":
                env = BoxManipulationEnv(max_steps=10 * steps)
                env.reset(seed=0)
                began = time.perf_counter()
                for action in actions:
                    env.step(action[0])
                rates[label].append(steps / (time.perf_counter() - began))
                env.close()
                continue
            envs = gymnasium.make_vec("puzzlebox/BoxManipulation-v0", num_envs=n, vectorization_mode="async",
                                      max_steps=10 * steps)  # fmt: skip
            envs.reset(seed=0)  # workers seeded 0, 1, ...
            envs.step(actions[0])  # warm: the workers have stepped once
            began = time.perf_counter()
            for action in actions:
                envs.step(action)
            rates[label].append(n * steps / (time.perf_counter() - began))
            envs.close()
    medians = {f"{label}_steps_per_s": float(np.median(v)) for label, v in rates.items()}
    return {
        "steps_per_worker": steps,
        **medians,
        "async_2_over_async_1": medians["async_2_steps_per_s"] / medians["async_1_steps_per_s"],
        "async_2_over_one_env": medians["async_2_steps_per_s"] / medians["one_env_steps_per_s"],
    }


__all__ = ["step_figures", "vector_figures"]
