"""Speed figures of the twin, for ``bench.py``: scene build and compile, bare ``mj_step`` against the twin's step,
overview rendering with and without shadows; oracle twin trials (the first in the process and a second one); the
cost of a trial's ``--video`` and ``--record`` outputs; and the rollout views' box visibility over every frame."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np


def twin_figures(quick: bool) -> dict[str, float]:
    """Scene build + compile time on the paper test boxes; bare ``mj_step`` (per call and ``nstep``) and the twin's
    step rate on the first one, interleaved (medians), with their ratios; overview render time per frame without
    and with shadows. ``quick``: fewer repeats."""
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
    multi-view rollout, drawn in a second process), with ``--record`` (a Rerun recording) and with ``--state-log``
    (the state at every control tick, :mod:`puzzlebox.lab.state_log`), in turn after a warm-up trial, ``repeats``
    times each: medians and the ratios to plain (targets x1.5, x1.3 and x1.05), and the state log's size."""
    import tempfile

    from puzzlebox.lab import TrialConfig, run_trial
    from puzzlebox.models.generator import paper_family

    spec = paper_family("test")[0]
    repeats = 1 if quick else 3
    walls: dict[str, list[float]] = {"plain": [], "video": [], "record": [], "state_log": []}
    log_bytes: list[int] = []
    with tempfile.TemporaryDirectory() as tmp:
        run_trial(
            spec, TrialConfig(agent="oracle", seed=0, max_actions=30)
        ).to_dict()  # warm-up: renderer, scene, IK model built
        for k in range(repeats):
            for label in walls:
                video = Path(tmp, f"v{k}.mp4") if label == "video" else None
                record = Path(tmp, f"r{k}.rrd") if label == "record" else None
                states = Path(tmp, f"s{k}.npz") if label == "state_log" else None
                start = time.perf_counter()
                run_trial(
                    spec, TrialConfig(agent="oracle", seed=0, max_actions=30), video=video, recording=record,
                    state_log=states,
                ).to_dict()  # fmt: skip
                walls[label].append(time.perf_counter() - start)
                if states is not None:
                    log_bytes.append(states.stat().st_size)
    out = {f"{label}_wall_s": float(np.median(times)) for label, times in walls.items()}
    out["video_over_plain"] = out["video_wall_s"] / out["plain_wall_s"]
    out["record_over_plain"] = out["record_wall_s"] / out["plain_wall_s"]
    out["state_log_over_plain"] = out["state_log_wall_s"] / out["plain_wall_s"]
    out["state_log_bytes"] = int(np.median(log_bytes))
    out["repeats"] = repeats
    return out


def box_visibility_figures(quick: bool) -> dict[str, float]:
    """The rollout video's views against the target "every frame shows the box unoccluded in one view": oracle
    trials (the 3 paper test boxes and two five-kind chains; quick: one), the frames' states kept, and per frame
    (one per simulated second: every tenth of the video's) the best view's share of the box's pixels seen with the
    arm against the same view without it (MuJoCo's segmentation rendering,
    :meth:`twin.rollout_video.RolloutDrawer.box_visibility`)."""
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
            assert kept is not None  # the trial's video made one (BackgroundRollout, patched above)
            drawer = RolloutDrawer(kept.model, kept.cameras, kept.config)
            every = max(1, round(1.0 / kept.config.period))
            best += [max(drawer.box_visibility(f.qpos).values()) for f in kept.frames[::every]]
            drawer.close()
    finally:
        _twin_trial.BackgroundRollout = drawing
    return {"trials": len(specs), "frames": len(best), "worst_frame_best_view": float(min(best)),
            "frames_below_0.9": int(sum(b < 0.9 for b in best))}  # fmt: skip
