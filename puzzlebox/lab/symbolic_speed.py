"""Speed figures of the symbolic side, for ``bench.py``: the dual agent's decision latency on random lock graphs
of growing size, its decision and belief update with a belief over sets of lockers (on two-locker boxes and on the
disassembly scene), and the symbolic environment's steps per second. Single-threaded numpy is the caller's to
enforce (``bench.py`` does, before numpy loads)."""

from __future__ import annotations

import time

import numpy as np

from puzzlebox.learning import DualAgent, PuzzleEnv, PuzzleEnvConfig, SymbolicWorld
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.experiments.disassembly import DATA_DIR as DISASSEMBLY_DATA
from puzzlebox.models.generator import RandomGraphConfig, generate_random
from puzzlebox.models.generator.chain import MAX_REACHABLE_COMPONENTS, BoxConfig
from puzzlebox.models.spec_loading import load_spec

SIZES = (5, 10, 16, 32)
"""The numbers of components whose decision latency is measured."""


def _timed_episode(agent: DualAgent, spec, episode: int, max_decisions: int, with_update: bool) -> list[float]:
    """Seconds of each decision of ``agent`` over one episode of ``spec`` (seed ``episode``): ``choose``, plus the
    belief update (``record``) if ``with_update`` — never the world's own step."""
    world = SymbolicWorld(spec, episode)
    observation = world.observe()
    agent.begin_episode(observation, np.random.default_rng(episode))
    times = []
    for _ in range(max_decisions):
        if observation.solved:
            break
        start = time.perf_counter()
        index = agent.choose(observation)
        spent = time.perf_counter() - start
        result = world.try_toggle(index)
        observation = world.observe()
        start = time.perf_counter()
        agent.record(index, result, observation)
        times.append(spent + (time.perf_counter() - start if with_update else 0.0))
    return times


def _latency(times: list[float]) -> dict[str, float]:
    """Median and 90th percentile of ``times`` in milliseconds, and how many there are."""
    ms = 1000.0 * np.array(times)
    return {"median_ms": float(np.median(ms)), "p90_ms": float(np.percentile(ms, 90)), "decisions": len(ms)}


def decision_latency(n: int, episodes: int, max_decisions: int) -> dict[str, float]:
    """Time every ``choose`` of the dual agent over a few episodes on random N-component graphs."""
    times = []
    for episode in range(episodes):
        # past the robot's reach only the layout check differs; smaller boxes keep their seeds' graphs
        box = BoxConfig(fit_reach=False) if n > MAX_REACHABLE_COMPONENTS else None
        spec = generate_random(RandomGraphConfig(n, multi_locker=n >= 4), seed=episode, box=box)
        times += _timed_episode(DualAgent(), spec, episode, max_decisions, with_update=False)
    return _latency(times)


def multi_locker_latency(n: int = 8, episodes: int = 5, max_decisions: int = 40) -> dict[str, dict[str, float]]:
    """Milliseconds per decision and belief update (``choose`` + ``record``) of the dual agent on
    two-locker random boxes of ``n`` components, per ``max_lockers`` (1 and 2), on the same boxes."""
    out = {}
    for k in (1, 2):
        times = []
        for episode in range(episodes):
            spec = generate_random(RandomGraphConfig(n, multi_locker=True), seed=episode)
            times += _timed_episode(DualAgent(DualControllerConfig(max_lockers=k)), spec, episode, max_decisions,
                                    with_update=True)  # fmt: skip
        out[f"max_lockers={k}"] = _latency(times)
    return out


DISASSEMBLY_SCENE = DISASSEMBLY_DATA / "lab-computer-b.json"
"""The 8-component disassembly scene of the paper's second domain (shipped with the package)."""


def disassembly_latency(episodes: int = 5, max_decisions: int = 24) -> dict[str, dict[str, float]] | None:
    """As :func:`multi_locker_latency`, on the disassembly scene :data:`DISASSEMBLY_SCENE` (seeds shuffle its
    order); None when the data is not there."""
    if not DISASSEMBLY_SCENE.is_file():
        return None
    spec = load_spec(DISASSEMBLY_SCENE)
    out = {}
    for k in (1, 2):
        times = []
        for episode in range(episodes):
            times += _timed_episode(DualAgent(DualControllerConfig(max_lockers=k)), spec, episode, max_decisions,
                                    with_update=True)  # fmt: skip
        out[f"max_lockers={k}"] = _latency(times)
    return out


def env_steps_per_second(seconds: float = 1.0) -> float:
    """Steps per second of ``PuzzleEnv.step`` with random actions on a 5-component random box, over ``seconds``."""
    spec = generate_random(RandomGraphConfig(5), seed=0)
    env = PuzzleEnv(spec, PuzzleEnvConfig(max_actions=10**9))
    env.reset(seed=0)
    actions = np.random.default_rng(0).integers(5, size=1_000_000)
    steps, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        for a in actions[steps % 900_000 : steps % 900_000 + 1000]:
            env.step(int(a))
        steps += 1000
    return steps / (time.perf_counter() - start)
