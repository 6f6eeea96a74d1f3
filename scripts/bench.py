"""Speed figures, measured in one run on this machine (ratios matter more than absolutes here).

    python scripts/bench.py --out FILE [--quick] [--scale-trials T]

- agent decision latency: median and 90th percentile milliseconds per dual-controller decision on
  random lock graphs of N = 5, 10, 16, 32 components (beliefs as they evolve during real episodes;
  boxes beyond the robot's reach are generated for the symbolic simulator, as ``generate.py --anywhere``);
- belief over sets of lockers: median and 90th percentile milliseconds per decision and belief update
  (``choose`` + ``record``) of the dual agent on 8-component two-locker boxes, with ``max_lockers`` 1 (the
  paper's belief) and 2 (sets of up to two lockers), one after the other in this run;
- symbolic environment: steps per second of ``PuzzleEnv.step`` with random actions;
- twin: scene build + compile time; bare ``mj_step`` rate on the compiled paper scene (one step per
  call, as a Python user steps, and ``nstep`` in C) beside the twin's rate on the same model, with
  their ratio; overview render time per 640x480 frame without and with shadows;
- twin trial: simulated/wall time of one oracle twin trial on a paper test box (ideal cell, no video), the
  first in the process (renderer, scene and IK model built) and a second one (kept from the first);
- twin trial outputs: wall time of the same oracle trial plain, with ``--video`` and with ``--record``, in turn
  (medians of 3), and the ratios to plain; the rollout views' box visibility over every frame of 5 trials;
- scale (``puzzlebox/lab/bench_scale.py``): each executor's overhead per no-op task, and twin trials per hour of
  the same T oracle trials on one worker, on a local pool (one worker per core) and on a local Ray cluster,
  one after the other in this run, with each one's speed-up over one worker: start-up included, and warm
  (after one trial per worker).
Single-threaded numpy is enforced for the agent figures (one core).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one core, before numpy loads

import argparse  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from puzzlebox.lab.cli import fail, versions, write_json  # noqa: E402
from puzzlebox.learning import DualAgent, PuzzleEnv, PuzzleEnvConfig, SymbolicWorld  # noqa: E402
from puzzlebox.learning.dual_controller import DualControllerConfig  # noqa: E402
from puzzlebox.models.generator import RandomGraphConfig, generate_random  # noqa: E402
from puzzlebox.models.generator.chain import MAX_REACHABLE_COMPONENTS, BoxConfig  # noqa: E402
from puzzlebox.models.spec_loading import load_spec  # noqa: E402

SIZES = (5, 10, 16, 32)


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


DISASSEMBLY_SCENE = Path(__file__).resolve().parents[2] / "shared" / "data" / "disassembly" / "lab-computer-b.json"
"""The 8-component disassembly scene of the paper's second domain (``../shared/data``), when present."""


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


def twin_figures(quick: bool) -> dict[str, float]:
    import mujoco

    from puzzlebox.models.generator import paper_family
    from puzzlebox.models.scene import build_scene
    from puzzlebox.twin.rendering import RenderConfig, Renderer
    from puzzlebox.twin.session import TwinSession

    specs = paper_family("test")
    build_times = []
    for spec in specs * (1 if quick else 3):
        start = time.perf_counter()
        build_scene(spec).compile()
        build_times.append(time.perf_counter() - start)
    steps = 2000 if quick else 10000
    session = TwinSession(specs[0], seed=0)
    model, data = session.model, mujoco.MjData(session.model)
    mujoco.mj_resetData(model, data)
    data.qpos[session.arm_qpos] = data.ctrl[session.arm_actuators] = session.config.home_qpos
    runs = {
        "bare_mj_step_per_call": lambda: [mujoco.mj_step(model, data) for _ in range(steps)],
        "bare_mj_step_nstep": lambda: mujoco.mj_step(model, data, nstep=steps),
        "twin_step": lambda: session.step(steps),
    }
    samples: dict[str, list[float]] = {label: [] for label in runs}
    for _ in range(3 if quick else 7):  # interleaved, medians: the machine is shared and noisy
        for label, run in runs.items():
            start = time.perf_counter()
            run()
            samples[label].append(steps / (time.perf_counter() - start))
    rates = {label: float(np.median(v)) for label, v in samples.items()}
    out = {
        "scene_build_compile_s_median": float(np.median(build_times)),
        **{f"{k}_per_s": v for k, v in rates.items()},
        "twin_over_bare_per_call": rates["twin_step"] / rates["bare_mj_step_per_call"],
        "twin_over_bare_nstep": rates["twin_step"] / rates["bare_mj_step_nstep"],
    }
    for shadows in (False, True):
        with Renderer(model, RenderConfig(shadows=shadows)) as renderer:
            renderer.render(session.data, "overview")  # warm-up: first frame compiles shaders
            times = []
            for _ in range(5 if quick else 30):
                start = time.perf_counter()
                renderer.render(session.data, "overview")
                times.append(time.perf_counter() - start)
        out[f"overview_render_ms_{'shadows' if shadows else 'no_shadows'}"] = 1000 * float(np.median(times))
    session.close()
    return out


def twin_trial_figures(quick: bool) -> dict[str, float]:
    """Simulated over wall time of oracle twin trials on the first paper test box, ideal cell: a first trial
    in this process and, unless ``quick``, a second one with what the process kept from the first. Quick: one
    try after the survey instead of the whole box."""
    from puzzlebox.lab import TrialConfig, run_trial
    from puzzlebox.models.generator import paper_family

    spec = paper_family("test")[0]
    out: dict[str, float] = {}
    for label in ("first", "second")[: 1 if quick else 2]:
        start = time.perf_counter()
        record = run_trial(spec, TrialConfig(agent="oracle", seed=0, max_actions=1 if quick else 30)).to_dict()
        wall = time.perf_counter() - start
        out[f"{label}_sim_s"], out[f"{label}_wall_s"] = record["sim_time_s"], wall
        out[f"{label}_sim_over_wall"] = record["sim_time_s"] / wall
        out[f"{label}_actions"] = record["num_actions"]
    return out


def rollout_figures(quick: bool) -> dict[str, float]:
    """Wall time of the same oracle twin trial (first paper test box, ideal cell) plain, with ``--video`` (the
    multi-view rollout, drawn in a second process) and with ``--record`` (a Rerun recording), in turn after a
    warm-up trial, ``repeats`` times each: medians and the ratios to plain (targets x1.5 and x1.3)."""
    import tempfile

    from puzzlebox.lab import TrialConfig, run_trial
    from puzzlebox.models.generator import paper_family

    spec = paper_family("test")[0]
    repeats = 1 if quick else 3
    walls: dict[str, list[float]] = {"plain": [], "video": [], "record": []}
    with tempfile.TemporaryDirectory() as tmp:
        run_trial(
            spec, TrialConfig(agent="oracle", seed=0, max_actions=30)
        ).to_dict()  # warm-up: renderer, scene, IK model built
        for k in range(repeats):
            for label in walls:
                video = Path(tmp, f"v{k}.mp4") if label == "video" else None
                record = Path(tmp, f"r{k}.rrd") if label == "record" else None
                start = time.perf_counter()
                run_trial(
                    spec, TrialConfig(agent="oracle", seed=0, max_actions=30), video=video, recording=record
                ).to_dict()
                walls[label].append(time.perf_counter() - start)
    out = {f"{label}_wall_s": float(np.median(times)) for label, times in walls.items()}
    out["video_over_plain"] = out["video_wall_s"] / out["plain_wall_s"]
    out["record_over_plain"] = out["record_wall_s"] / out["plain_wall_s"]
    out["repeats"] = repeats
    return out


def box_visibility_figures(quick: bool) -> dict[str, float]:
    """The rollout video's views against the target "every frame shows the box unoccluded in one view": oracle
    trials (the 3 paper test boxes and two five-kind chains; quick: one), every frame's state kept, and per frame
    the best view's share of the box's pixels seen with the arm against the same view without it (MuJoCo's
    segmentation rendering, :meth:`twin.rollout_video.RolloutDrawer.box_visibility`)."""
    from puzzlebox.lab import TrialConfig, run_trial
    from puzzlebox.lab import twin_trial as _twin_trial
    from puzzlebox.models.generator import generate_chain, paper_family
    from puzzlebox.twin.rollout_video import FrameCollector, RolloutDrawer

    specs = [*paper_family("test"), generate_chain(["lever", "slide", "door", "drawer", "wheel"], seed=0),
             generate_chain(["wheel", "drawer", "lever", "door", "slide"], seed=3)][: 1 if quick else 5]  # fmt: skip
    drawing = _twin_trial.BackgroundRollout
    _twin_trial.BackgroundRollout = FrameCollector  # the frames' states kept, not drawn
    best: list[float] = []
    try:
        for spec in specs:
            run_trial(spec, TrialConfig(agent="oracle", seed=0, max_actions=12), video=Path("unused.mp4")).to_dict()
            kept = FrameCollector.last
            drawer = RolloutDrawer(kept.model, kept.cameras, kept.config)
            best += [max(drawer.box_visibility(f.qpos).values()) for f in kept.frames]
            drawer.close()
    finally:
        _twin_trial.BackgroundRollout = drawing
    return {"trials": len(specs), "frames": len(best), "worst_frame_best_view": float(min(best)),
            "frames_below_0.9": int(sum(b < 0.9 for b in best))}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", required=True, help="output JSON file")
    parser.add_argument("--quick", action="store_true", help="fewer episodes (CI smoke run)")
    parser.add_argument(
        "--scale-trials", type=int, default=None,
        help="twin trials per executor for the scale figures (default 40; --quick 4; 0 skips them)",
    )  # fmt: skip
    args = parser.parse_args(argv)
    if args.scale_trials is not None and args.scale_trials < 0:
        fail(f"--scale-trials must be >= 0, got {args.scale_trials}")
    episodes = 1 if args.quick else 5
    results = {"command": "bench", "machine": platform.processor() or platform.machine(), "versions": versions()}
    results["decision_latency"] = {}
    for n in SIZES:
        results["decision_latency"][f"N={n}"] = stats = decision_latency(n, episodes, max_decisions=3 * n)
        print(f"decision latency N={n:>2}: median {stats['median_ms']:.3f} ms, p90 {stats['p90_ms']:.3f} ms "
              f"over {stats['decisions']} decisions")  # fmt: skip
    results["multi_locker_latency_n8"] = multi = multi_locker_latency(episodes=episodes)
    for label, stats in multi.items():
        print(f"decision + update N=8 two-locker boxes, {label}: median {stats['median_ms']:.3f} ms, "
              f"p90 {stats['p90_ms']:.3f} ms over {stats['decisions']} decisions")  # fmt: skip
    results["disassembly_latency"] = scene = disassembly_latency(episodes=episodes)
    for label, stats in (scene or {}).items():
        print(f"decision + update, disassembly scene (lab-computer-b), {label}: median {stats['median_ms']:.3f} ms, "
              f"p90 {stats['p90_ms']:.3f} ms over {stats['decisions']} decisions")  # fmt: skip
    results["symbolic_env_steps_per_s"] = rate = env_steps_per_second(0.3 if args.quick else 2.0)
    print(f"symbolic env: {rate:,.0f} steps/s")
    results["twin"] = twin = twin_figures(args.quick)
    print(
        f"twin: build+compile {twin['scene_build_compile_s_median']:.3f} s; bare mj_step "
        f"{twin['bare_mj_step_per_call_per_s']:,.0f}/s per call, {twin['bare_mj_step_nstep_per_s']:,.0f}/s nstep; "
        f"twin {twin['twin_step_per_s']:,.0f}/s (x{twin['twin_over_bare_per_call']:.2f} per call, "
        f"x{twin['twin_over_bare_nstep']:.2f} nstep); overview render {twin['overview_render_ms_no_shadows']:.1f} ms "
        f"({twin['overview_render_ms_shadows']:.1f} ms with shadows)"
    )
    results["twin_trial"] = trial = twin_trial_figures(args.quick)
    print(
        "twin trial (oracle, ideal): "
        + "; ".join(
            f"{label} x{trial[f'{label}_sim_over_wall']:.1f} ({trial[f'{label}_sim_s']:.0f} s simulated in "
            f"{trial[f'{label}_wall_s']:.2f} s, {trial[f'{label}_actions']} actions)"
            for label in ("first", "second")
            if f"{label}_sim_s" in trial
        )
    )
    results["rollout"] = rollout = rollout_figures(args.quick)
    print(
        f"twin trial outputs (oracle, ideal, median of {rollout['repeats']}): plain {rollout['plain_wall_s']:.2f} s, "
        f"--video {rollout['video_wall_s']:.2f} s (x{rollout['video_over_plain']:.2f}), --record "
        f"{rollout['record_wall_s']:.2f} s (x{rollout['record_over_plain']:.2f})"
    )
    results["box_visibility"] = seen = box_visibility_figures(args.quick)
    print(
        f"rollout views: over {seen['frames']} frames of {seen['trials']} trials the best view showed at least "
        f"{seen['worst_frame_best_view']:.1%} of the box ({seen['frames_below_0.9']} frames below 90 %)"
    )
    path = write_json(Path(args.out), results)  # what is measured so far is kept if the scale part fails
    trials = args.scale_trials if args.scale_trials is not None else (4 if args.quick else 40)
    if trials:
        from puzzlebox.lab.bench_scale import overhead_ms, twin_throughput

        results["executor_overhead_ms_per_noop_task"] = overhead = overhead_ms(50 if args.quick else 200)
        print("per-task overhead on no-op tasks: " + ", ".join(f"{k} {v:.2f} ms" for k, v in overhead.items()))
        results["twin_throughput"] = scale = twin_throughput(trials)
        for key, label in (("trials_per_hour", "start-up included"), ("warm_trials_per_hour", "warm")):
            speedup = key.replace("trials_per_hour", "speedup_over_one_worker")
            print(f"twin trials per hour ({trials} oracle trials, ideal, paper test boxes; {label}): " + "; ".join(
                f"{k} {v[key]:.0f}" + (f" (x{v[speedup]:.2f})" if speedup in v else "")
                for k, v in scale.items() if isinstance(v, dict)
            ))  # fmt: skip
        path = write_json(Path(args.out), results)
    print(f"-> {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
