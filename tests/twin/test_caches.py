"""What a process keeps across twin sessions changes nothing a session senses: a pooled renderer rebound to
another session's model draws the pixels a new renderer draws, a cached scene gives a session its own model
with the trajectory a fresh build gives, and sensing only on the last physics step of a run (or before an F/T
sample) changes no bit."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from puzzlebox.models.generator import generate_chain, paper_family  # noqa: E402
from puzzlebox.twin import renderer_pool, scene_cache  # noqa: E402
from puzzlebox.twin import rendering as rendering_module  # noqa: E402
from puzzlebox.twin.errors import RenderingError  # noqa: E402
from puzzlebox.twin.rendering import RenderConfig, Renderer  # noqa: E402
from puzzlebox.twin.session import TwinSession  # noqa: E402

CAMERAS = ("overview", "xarm7/gripper/wrist_camera")


@pytest.fixture(scope="module")
def spec():
    return paper_family("test")[0]


def _drive(session: TwinSession, ticks: int, seed: int = 0) -> None:
    """Random small joint commands, one per 10 ms tick."""
    rng = np.random.default_rng(seed)
    limits = session.robot.joint_limits().T
    for _ in range(ticks):
        q = session.robot.joint_positions() + rng.normal(0, 0.01, 7)
        session.robot.command_joint_positions(np.clip(q, *limits))
        session.robot.wait(0.01)


def test_a_pooled_renderer_draws_the_pixels_of_a_new_one_for_another_placement(spec):
    renderer_pool.clear()
    pooled, lent = {}, None
    for seed in (0, 1):  # realistic placements: the box elsewhere, the same meshes and textures
        with TwinSession(spec, seed=seed, reality="realistic") as session:
            _drive(session, 20, seed)
            pooled[seed] = [session.robot.capture(camera) for camera in CAMERAS]
            if seed == 1:
                assert session.cameras._renderer is lent  # the first session's, rebound
            lent = session.cameras._renderer
    for seed in (0, 1):
        with TwinSession(spec, seed=seed, reality="realistic") as session:
            _drive(session, 20, seed)
            session.cameras._renderer = Renderer(session.model, session.cameras.render_config)  # a new one
            try:
                fresh = [session.robot.capture(camera) for camera in CAMERAS]
            finally:
                session.cameras._renderer.close()
                session.cameras._renderer = None
        for a, b in zip(pooled[seed], fresh, strict=True):
            assert a is not None and b is not None
            np.testing.assert_array_equal(a.rgb, b.rgb)


def test_a_rebound_render_context_holds_what_a_new_one_would(spec):
    first = TwinSession(spec, seed=0, reality="realistic")
    second = TwinSession(spec, seed=3, reality="realistic")
    config = RenderConfig()
    with Renderer(first.model, config) as rebound, Renderer(second.model, config) as new:
        rebound.rebind(second.model)
        for field in ("fogStart", "fogEnd", "shadowClip", "shadowScale", "lineWidth", "offWidth", "offHeight",
                      "offSamples", "shadowSize", "ntexture"):  # fmt: skip
            assert getattr(rebound._mjr_context, field) == getattr(new._mjr_context, field), field
        np.testing.assert_array_equal(rebound._mjr_context.mat_texid, new._mjr_context.mat_texid)
    first.close()
    second.close()


def test_a_renderer_refuses_to_draw_a_model_with_other_meshes_or_textures(spec):
    other = generate_chain(["slide", "wheel"], seed=3)
    with TwinSession(spec) as a, TwinSession(other) as b, Renderer(a.model) as renderer:
        with pytest.raises(RenderingError, match="same meshes"):
            renderer.rebind(b.model)


def test_two_open_sessions_never_share_a_renderer(spec):
    renderer_pool.clear()
    with TwinSession(spec) as a, TwinSession(spec) as b:
        a.robot.capture("overview")
        b.robot.capture("overview")
        assert a.cameras._renderer is not b.cameras._renderer


def test_idle_renderers_beyond_the_bound_are_closed_oldest_first():
    renderer_pool.clear()
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><camera name="c" pos="0 0 1"/><geom size="0.1"/></worldbody></mujoco>'
    )
    renderers = [Renderer(model, RenderConfig(width=32, height=24)) for _ in range(renderer_pool.MAX_IDLE + 1)]
    for renderer in renderers:
        renderer_pool.release(renderer)
    assert renderers[0].closed, "the oldest idle renderer is closed, not kept"
    assert not any(r.closed for r in renderers[1:])
    assert renderer_pool.acquire(model, RenderConfig(width=32, height=24)) is renderers[1]  # the oldest kept
    renderer_pool.clear()
    assert all(r.closed for r in renderers[2:])
    renderers[1].close()


def test_the_scene_cache_keeps_its_bound_and_builds_again_a_scene_it_forgot(monkeypatch):
    scene_cache.clear()
    monkeypatch.setattr(scene_cache, "MAX_SCENES", 1)
    built = []
    build = scene_cache.build_scene
    monkeypatch.setattr(scene_cache, "build_scene", lambda spec, config: built.append(spec.name) or build(spec, config))
    first, second = (generate_chain(["slide", "door"], seed=s) for s in (0, 1))
    config = scene_cache.SceneConfig()
    for spec in (first, second, second, first):
        scene_cache.compiled_scene(spec, config)
    assert built == [first.name, second.name, first.name]  # the second kept, the first forgotten and rebuilt
    assert len(scene_cache._cache) == 1
    scene_cache.clear()


def test_the_small_shadow_map_changes_no_pixel_without_shadows_and_leaves_the_model_its_own(spec, monkeypatch):
    with TwinSession(spec) as session:
        model_size = session.model.vis.quality.shadowsize
        with Renderer(session.model) as small:
            assert small._mjr_context.shadowSize == 1 and session.model.vis.quality.shadowsize == model_size
            image = small.render(session.data, "overview")
        with Renderer(session.model, RenderConfig(shadows=True)) as shadows:  # made after: the model's map
            assert shadows._mjr_context.shadowSize == model_size
        full = rendering_module._bound_visual
        monkeypatch.setattr(rendering_module, "_bound_visual", lambda m, c: (*full(m, c)[:2], model_size))
        with Renderer(session.model) as default:
            assert default._mjr_context.shadowSize == model_size
            np.testing.assert_array_equal(default.render(session.data, "overview"), image)


def test_a_cached_scene_gives_each_session_its_own_model_and_a_fresh_builds_trajectory(spec):
    scene_cache.clear()
    fresh = TwinSession(spec, seed=2, reality="realistic")  # builds and caches; realistic writes its draws in
    cached = TwinSession(spec, seed=2, reality="realistic")
    assert cached.model is not fresh.model
    ideal = TwinSession(spec, seed=2)  # the same spec, cached: none of the realistic draws
    scene_cache.clear()
    rebuilt = TwinSession(spec, seed=2)
    for name in ("geom_friction", "body_mass", "dof_damping", "cam_pos", "cam_fovy"):
        np.testing.assert_array_equal(getattr(ideal.model, name), getattr(rebuilt.model, name), err_msg=name)
    for a, b in ((fresh, cached), (ideal, rebuilt)):
        _drive(a, 100)
        _drive(b, 100)
        np.testing.assert_array_equal(a.data.qpos, b.data.qpos)
        np.testing.assert_array_equal(a.robot.wrench(), b.robot.wrench())
    for session in (fresh, cached, ideal, rebuilt):
        session.close()


@pytest.mark.parametrize("reality", ["ideal", "realistic"])
def test_sensing_on_the_last_step_of_a_run_only_changes_no_bit(spec, reality):
    fast = TwinSession(spec, seed=3, reality=reality)
    every = TwinSession(spec, seed=3, reality=reality)
    every._steps = lambda k, sense=True: mujoco.mj_step(every.model, every.data, nstep=k)  # sensors at every step
    rng = np.random.default_rng(0)
    for _ in range(150):
        q = np.clip(fast.robot.joint_positions() + rng.normal(0, 0.02, 7), *fast.robot.joint_limits().T)
        for session in (fast, every):
            session.robot.command_joint_positions(q)
            session.robot.wait(0.01)
        np.testing.assert_array_equal(fast.data.qpos, every.data.qpos)
        np.testing.assert_array_equal(fast.data.sensordata, every.data.sensordata)
        np.testing.assert_array_equal(fast.robot.wrench(), every.robot.wrench())
    fast.close()
    every.close()
