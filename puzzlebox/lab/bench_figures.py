"""The figures ``bench.py`` measures, in the order it measures them, each with where it goes in the results file
and the lines it prints: the symbolic figures (``puzzlebox.lab.symbolic_speed``), the twin's
(``puzzlebox.lab.twin_speed``), the manipulation environment's (``puzzlebox.lab.manipulation_speed``), then the
scale figures (``puzzlebox.lab.bench_scale``). Each figure is measured
when its generator is advanced, so a caller can print and keep it before the next one starts."""

from __future__ import annotations

import platform
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from puzzlebox.lab.cli import versions
from puzzlebox.lab.manipulation_speed import step_figures, vector_figures
from puzzlebox.lab.symbolic_speed import (
    SIZES,
    decision_latency,
    disassembly_latency,
    env_steps_per_second,
    multi_locker_latency,
)
from puzzlebox.lab.twin_speed import box_visibility_figures, rollout_figures, twin_figures, twin_trial_figures


@dataclass(frozen=True)
class Figure:
    """One measured figure: ``value`` goes under ``key`` (a path of nested keys) in the results; ``lines`` are
    printed."""

    key: tuple[str, ...]
    value: Any
    lines: list[str]

    def keep(self, results: dict[str, Any]) -> None:
        """Put the value in ``results`` under its key (making the nested dicts on the way)."""
        *parents, last = self.key
        for key in parents:
            results = results.setdefault(key, {})
        results[last] = self.value


def bench_header() -> dict[str, Any]:
    """What the results file starts with: the command, the machine and the versions."""
    return {"command": "bench", "machine": platform.processor() or platform.machine(), "versions": versions()}


def default_scale_trials(quick: bool) -> int:
    """Twin trials per executor for the scale figures when not given: 40 (``quick``: 4)."""
    return 4 if quick else 40


def _latency_line(what: str, stats: dict[str, float]) -> str:
    return (
        f"{what}: median {stats['median_ms']:.3f} ms, p90 {stats['p90_ms']:.3f} ms over {stats['decisions']} decisions"
    )


def measured_figures(quick: bool) -> Iterator[Figure]:
    """Every figure but the scale ones, one at a time (``quick``: fewer episodes and repeats, a CI smoke run)."""
    episodes = 1 if quick else 5
    for n in SIZES:
        stats = decision_latency(n, episodes, max_decisions=3 * n)
        yield Figure(("decision_latency", f"N={n}"), stats, [_latency_line(f"decision latency N={n:>2}", stats)])
    multi = multi_locker_latency(episodes=episodes)
    what = "decision + update N=8 two-locker boxes, {}"
    yield Figure(("multi_locker_latency_n8",), multi, [_latency_line(what.format(k), s) for k, s in multi.items()])
    scene = disassembly_latency(episodes=episodes)
    what = "decision + update, disassembly scene (lab-computer-b), {}"
    lines = [_latency_line(what.format(k), s) for k, s in (scene or {}).items()]
    yield Figure(("disassembly_latency",), scene, lines)
    rate = env_steps_per_second(0.3 if quick else 2.0)
    yield Figure(("symbolic_env_steps_per_s",), rate, [f"symbolic env: {rate:,.0f} steps/s"])
    twin = twin_figures(quick)
    yield Figure(("twin",), twin, [
        f"twin: build+compile {twin['scene_build_compile_s_median']:.3f} s; bare mj_step "
        f"{twin['bare_mj_step_per_call_per_s']:,.0f}/s per call, {twin['bare_mj_step_nstep_per_s']:,.0f}/s nstep; "
        f"twin {twin['twin_step_per_s']:,.0f}/s (x{twin['twin_over_bare_per_call']:.2f} per call, "
        f"x{twin['twin_over_bare_nstep']:.2f} nstep); overview render {twin['overview_render_ms_no_shadows']:.1f} ms "
        f"({twin['overview_render_ms_shadows']:.1f} ms with shadows)"
    ])  # fmt: skip
    trial = twin_trial_figures(quick)
    yield Figure(("twin_trial",), trial, [
        "twin trial (oracle, ideal): "
        + "; ".join(
            f"{label} x{trial[f'{label}_sim_over_wall']:.1f} ({trial[f'{label}_sim_s']:.0f} s simulated in "
            f"{trial[f'{label}_wall_s']:.2f} s, {trial[f'{label}_actions']} actions)"
            for label in ("first", "second")
            if f"{label}_sim_s" in trial
        )
    ])  # fmt: skip
    yield from output_figures(quick)
    yield from lock_check_figures(quick)
    seen = box_visibility_figures(quick)
    yield Figure(("box_visibility",), seen, [
        f"rollout views: over {seen['frames']} frames of {seen['trials']} trials the best view showed at least "
        f"{seen['worst_frame_best_view']:.1%} of the box ({seen['frames_below_0.9']} frames below 90 %)"
    ])  # fmt: skip
    yield from manipulation_figures(quick)


def output_figures(quick: bool) -> Iterator[Figure]:
    """The twin trial's outputs (video, Rerun recording, state log) against the plain trial (``--only outputs``:
    this figure alone)."""
    rollout = rollout_figures(quick)
    yield Figure(("rollout",), rollout, [
        f"twin trial outputs (oracle, ideal, median of {rollout['repeats']}): plain {rollout['plain_wall_s']:.2f} s, "
        f"--video {rollout['video_wall_s']:.2f} s (x{rollout['video_over_plain']:.2f}), --record "
        f"{rollout['record_wall_s']:.2f} s (x{rollout['record_over_plain']:.2f}), --state-log "
        f"{rollout['state_log_wall_s']:.2f} s (x{rollout['state_log_over_plain']:.3f}, "
        f"{rollout['state_log_bytes'] / 1e6:.2f} MB)"
    ])  # fmt: skip


def lock_check_figures(quick: bool) -> Iterator[Figure]:
    """``generate.py check-locks``'s check (the band check, box alone) on the 12 paper boxes (quick: 2), one push
    after another against every push of a box as one batch (``mujoco.batch``), in turn per box: their times, the
    ratio and whether every transition is the same."""
    import time

    from puzzlebox.lab.lock_checks import compiled_model
    from puzzlebox.models.generator import paper_family
    from puzzlebox.models.lock_check import BAND_OFFSETS, check_locks

    times = {"one_by_one": 0.0, "batched": 0.0}
    same, transitions = True, 0
    for spec in paper_family("all")[: 2 if quick else 12]:
        model, joints = compiled_model(spec, "contact", False)
        checks = {}
        for label in times:
            start = time.perf_counter()
            checks[label] = check_locks(spec, model, joints, offsets=BAND_OFFSETS, batched=label == "batched")
            times[label] += time.perf_counter() - start
        same = same and checks["batched"].transitions == checks["one_by_one"].transitions
        transitions += len(checks["batched"].transitions)
    out = {"boxes": 2 if quick else 12, "transitions": transitions, "one_by_one_s": times["one_by_one"],
           "batched_s": times["batched"], "speedup": times["one_by_one"] / times["batched"],
           "identical": same}  # fmt: skip
    yield Figure(("lock_check",), out, [
        f"check-locks, band check, {out['boxes']} paper boxes ({transitions} transitions): push after push "
        f"{out['one_by_one_s']:.1f} s, batched {out['batched_s']:.1f} s (x{out['speedup']:.2f}), "
        f"{'identical' if same else 'DIFFERENT'}"
    ])  # fmt: skip


def manipulation_figures(quick: bool) -> Iterator[Figure]:
    """``BoxManipulation-v0`` against bare ``mj_step`` over the same simulated time, and two async workers against
    one (``puzzlebox.lab.manipulation_speed``)."""
    from puzzlebox.models.generator import paper_family

    for key, spec in (("step", None), ("step_paper_test_0", paper_family("test")[0])):
        step = step_figures(quick, spec)
        per_call = step["bare_mj_step_per_call_control_steps_per_s"]
        nstep = step["bare_mj_step_nstep_control_steps_per_s"]
        yield Figure(("manipulation", key), step, [
            f"BoxManipulation-v0 (state obs, ideal, {step['spec']}): {step['env_step_control_steps_per_s']:,.0f} "
            f"steps/s at 20 Hz; bare mj_step over the same simulated time {per_call:,.0f}/s per call, {nstep:,.0f}/s "
            f"nstep (env x{step['env_over_bare_per_call']:.2f}, x{step['env_over_bare_nstep']:.2f}; in CPU time "
            f"x{step['env_over_bare_per_call_cpu']:.2f}, x{step['env_over_bare_nstep_cpu']:.2f}; load "
            f"{step['load_average_1min'][0]:.1f})"
        ])  # fmt: skip
    vector = vector_figures(quick)
    yield Figure(("manipulation", "vector"), vector, [
        f"BoxManipulation-v0 make_vec async: 1 worker {vector['async_1_steps_per_s']:,.0f} steps/s, 2 workers "
        f"{vector['async_2_steps_per_s']:,.0f} steps/s (x{vector['async_2_over_async_1']:.2f}; one env in-process "
        f"{vector['one_env_steps_per_s']:,.0f}/s, x{vector['async_2_over_one_env']:.2f})"
    ])  # fmt: skip


def scale_figures(trials: int, quick: bool) -> Iterator[Figure]:
    """The scale figures (``puzzlebox.lab.bench_scale``): each executor's overhead per no-op task, then twin trials
    per hour of ``trials`` oracle trials on each executor, start-up included and warm."""
    from puzzlebox.lab.bench_scale import overhead_ms, twin_throughput  # Ray only when asked

    overhead = overhead_ms(50 if quick else 200)
    line = "per-task overhead on no-op tasks: " + ", ".join(f"{k} {v:.2f} ms" for k, v in overhead.items())
    yield Figure(("executor_overhead_ms_per_noop_task",), overhead, [line])
    scale = twin_throughput(trials)
    lines = []
    for key, label in (("trials_per_hour", "start-up included"), ("warm_trials_per_hour", "warm")):
        speedup = key.replace("trials_per_hour", "speedup_over_one_worker")
        lines.append(f"twin trials per hour ({trials} oracle trials, ideal, paper test boxes; {label}): " + "; ".join(
            f"{k} {v[key]:.0f}" + (f" (x{v[speedup]:.2f})" if speedup in v else "")
            for k, v in scale.items() if isinstance(v, dict)
        ))  # fmt: skip
    yield Figure(("twin_throughput",), scale, lines)
