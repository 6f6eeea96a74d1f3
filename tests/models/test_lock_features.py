"""Visible lock features (issue 15 part 4): one bolt, notch or catch per locked pair, on the locker, reaching into
the locked component, clear of every marker; visual only in the MJCF; carried by the mesh export."""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest
import trimesh

from puzzlebox.models.generator import RandomGraphConfig, generate_random, paper_family
from puzzlebox.models.geometry import polygon_gap, rectangle, transform_points
from puzzlebox.models.kinds import MARKER_SIZE, get_kind
from puzzlebox.models.kinds.parts import PLATE_THICKNESS
from puzzlebox.models.lock_features import FEATURE_RGBA, layout_lock_features, lock_features
from puzzlebox.models.mesh_export import BOX_PART, component_meshes, export_meshes
from puzzlebox.models.puzzle_box import build_puzzle_box, component_prefixes
from puzzlebox.models.spec import Box, Component, Goal, LockRule, PuzzleSpec

SPECS = {s.name: s for s in paper_family("all")} | {
    s.name: s for s in (generate_random(RandomGraphConfig(num_components=6), seed) for seed in range(10))
}
NAMES = sorted(SPECS)


@functools.cache
def layout(name):
    return layout_lock_features(SPECS[name])


def pairs(spec):
    """(locker, locked) -> rules, in order of first appearance."""
    out = {}
    for rule in spec.locks:
        out.setdefault((rule.locker, rule.locked), []).append(rule)
    return out


def hull(points):
    """Counter-clockwise convex hull of 2-D points (monotone chain)."""
    pts = sorted(set(map(tuple, np.round(points, 12))))

    def half(seq):
        out = []
        for p in seq:
            while len(out) >= 2 and _turn(out[-2], out[-1], p) <= 0:
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def _turn(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def depth_inside(polygon, point):
    """Signed distance of ``point`` inside a convex counter-clockwise ``polygon`` (negative outside)."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    normals = np.stack([-edges[:, 1], edges[:, 0]], 1) / np.linalg.norm(edges, axis=1, keepdims=True)
    return float(np.min(np.sum((point - polygon) * normals, axis=1)))


def ccw(polygon):
    x, y = polygon[:, 0], polygon[:, 1]
    return polygon if np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y) >= 0 else polygon[::-1]


def footprint(spec, name):
    c = spec.components[spec.index_of(name)]
    return ccw(get_kind(c.kind).footprint_in_lid(c.pose))


@pytest.mark.parametrize("name", NAMES)
def test_one_feature_per_distinct_locked_pair(name):
    spec = SPECS[name]
    placed = layout(name)
    assert not placed.skipped, placed.skipped  # every pair of these boxes finds a clear strip
    expected = pairs(spec)
    assert [(f.locker, f.locked) for f in placed.features] == list(expected)
    for f in placed.features:
        assert f.name == f"{f.locker}-locks-{f.locked}"
        assert list(f.rules) == expected[(f.locker, f.locked)]
        kinds = {spec.components[spec.index_of(c)].kind for c in (f.locker, f.locked)}
        assert f.kind == ("notch" if "wheel" in kinds else "bolt")
        assert f.rgba == FEATURE_RGBA[f.kind]
    assert lock_features(spec) == list(placed.features)


def test_identical_pairs_share_one_feature_naming_both_rules():
    spec = SPECS["paper-test-0"]
    extra = LockRule(spec.locks[0].locker, 1, spec.locks[0].locked, 1)
    doubled = replace(spec, locks=(*spec.locks, extra, spec.locks[0]))
    features = lock_features(doubled)
    assert len(features) == len(lock_features(spec))
    first = next(f for f in features if (f.locker, f.locked) == (extra.locker, extra.locked))
    assert first.rules == (spec.locks[0], extra, spec.locks[0])


@pytest.mark.parametrize("name", NAMES)
def test_features_stand_on_the_locker_and_reach_into_the_locked_component(name):
    spec = SPECS[name]
    for f in layout(name).features:
        xy = np.asarray(f.mesh.vertices)[:, :2]
        shape = hull(xy)
        locker, locked = footprint(spec, f.locker), footprint(spec, f.locked)
        # attached: the feature overlaps the locker's footprint, and nothing strays more than 2 mm from the
        # locker's footprint except towards (and into) the locked component
        assert polygon_gap(shape, locker) <= 0.002, f.name
        corridor = hull(np.concatenate([locker, locked]))
        assert min(depth_inside(corridor, p) for p in xy) >= -0.002, f.name
        reach = max(depth_inside(locked, p) for p in xy)
        assert reach >= 0.001 - 1e-9, (f.name, reach)
        # every feature stands on the plates' tops (z = PLATE_THICKNESS) and rises above them
        assert f.mesh.bounds[0, 2] == pytest.approx(PLATE_THICKNESS, abs=1e-9), f.name
        assert f.mesh.bounds[1, 2] > PLATE_THICKNESS + 0.003, f.name


def test_most_features_reach_the_nominal_4_mm():
    reaches = []
    for name in NAMES:
        spec = SPECS[name]
        for f in layout(name).features:
            xy = np.asarray(f.mesh.vertices)[:, :2]
            reaches.append(max(depth_inside(footprint(spec, f.locked), p) for p in xy))
    assert np.mean(np.array(reaches) >= 0.004 - 1e-6) >= 0.75, np.round(np.array(reaches) * 1000, 1)


@pytest.mark.parametrize("name", NAMES)
def test_no_feature_covers_a_marker_quiet_zone_or_another_feature(name):
    spec = SPECS[name]
    h = MARKER_SIZE * 4 / 3 / 2
    zones = [transform_points(c.pose, rectangle(-h, h, -h, h)) for c in spec.components]
    shapes = [hull(np.asarray(f.mesh.vertices)[:, :2]) for f in layout(name).features]
    for k, shape in enumerate(shapes):
        for c, zone in zip(spec.components, zones, strict=True):
            assert polygon_gap(shape, zone) > 0, (layout(name).features[k].name, c.name)
        for other in shapes[k + 1 :]:
            assert polygon_gap(shape, other) > 0


@pytest.mark.parametrize("name", NAMES)
def test_meshes_are_watertight_volumes(name):
    for f in layout(name).features:
        assert f.mesh.is_watertight and f.mesh.is_volume, f.name
        assert f.mesh.volume > 1e-8, f.name


def test_a_spec_without_locks_has_no_features():
    spec = replace(SPECS["paper-test-0"], locks=())
    assert lock_features(spec) == []
    assert layout_lock_features(spec).skipped == ()


def test_unknown_kinds_fall_back_to_a_catch_placed_by_pose():
    components = (
        Component("lever-a", "lever", (0.0, 0.0, 0.0), 0),
        Component("drawer-b", "drawer", (0.1, 0.0, math.pi / 2), 1),
        Component("door-c", "door", (-0.12, 0.0, 0.0), 2),
        Component("wheel-d", "wheel", (0.0, 0.12, 0.0), 3),
    )
    locks = (
        LockRule("lever-a", 0, "drawer-b", 0),
        LockRule("drawer-b", 1, "lever-a", 1),
        LockRule("door-c", 0, "lever-a", 0),
        LockRule("lever-a", 0, "wheel-d", 0),
    )
    spec = PuzzleSpec("strangers", components, locks, Goal("drawer-b"), Box((0.4, 0.4, 0.08)))
    placed = layout_lock_features(spec)
    kinds = {(f.locker, f.locked): f.kind for f in placed.features}
    assert kinds == {
        ("lever-a", "drawer-b"): "catch",
        ("drawer-b", "lever-a"): "catch",
        ("door-c", "lever-a"): "catch",
        ("lever-a", "wheel-d"): "notch",
    }, placed.skipped
    for f in placed.features:
        assert f.mesh.is_volume
        assert f.rgba == FEATURE_RGBA[f.kind]


def compiled(spec, **kwargs):
    root = build_puzzle_box(spec, **kwargs)
    return mujoco.MjSpec.from_string(root.to_xml_string(), assets=root.get_assets()).compile()


def test_the_default_model_is_unchanged():
    spec = SPECS["paper-test-0"]
    default = build_puzzle_box(spec).to_xml_string()
    assert default == build_puzzle_box(spec, True, False).to_xml_string()
    assert default == build_puzzle_box(spec, with_markers=True, lock_features=False).to_xml_string()
    assert ":lock:" not in default and "<mesh" not in default


@pytest.mark.parametrize("name", ["paper-test-0", "paper-train-0", "random-n6-s1"])
def test_features_in_the_mjcf_are_visual_only_and_ride_on_the_locker(name):
    spec = SPECS[name]
    plain, featured = compiled(spec), compiled(spec, lock_features=True)
    features = lock_features(spec)
    assert featured.ngeom == plain.ngeom + len(features)
    prefixes = component_prefixes(spec)
    for f in features:
        g = mujoco.mj_name2id(featured, mujoco.mjtObj.mjOBJ_GEOM, f"{prefixes[f.locker]}:lock:{prefixes[f.locked]}")
        assert g >= 0
        assert featured.geom_bodyid[g] == mujoco.mj_name2id(featured, mujoco.mjtObj.mjOBJ_BODY, prefixes[f.locker])
        assert featured.geom_contype[g] == 0 and featured.geom_conaffinity[g] == 0 and featured.geom_group[g] == 2
    assert np.array_equal(plain.body_mass, featured.body_mass)
    assert np.array_equal(plain.body_inertia, featured.body_inertia)

    # the geoms are the features: at qpos0 (closed) the mesh vertices in the lid (= world) frame are the feature's
    data = mujoco.MjData(featured)
    mujoco.mj_forward(featured, data)
    for f in features:
        g = mujoco.mj_name2id(featured, mujoco.mjtObj.mjOBJ_GEOM, f"{prefixes[f.locker]}:lock:{prefixes[f.locked]}")
        m = featured.geom_dataid[g]
        v0, nv = featured.mesh_vertadr[m], featured.mesh_vertnum[m]
        world = featured.mesh_vert[v0 : v0 + nv] @ data.geom_xmat[g].reshape(3, 3).T + data.geom_xpos[g]
        assert np.allclose([world.min(0), world.max(0)], f.mesh.bounds, atol=1e-6), f.name

    # the same motion with and without the features, to the bit
    runs = []
    for model in (plain, featured):
        d = mujoco.MjData(model)
        d.qvel[:] = np.linspace(0.2, 1.0, model.nv)
        for _ in range(100):
            d.qfrc_applied[:] = 0.05 * np.sin(np.arange(model.nv) + d.time * 50)
            mujoco.mj_step(model, d)
        assert not any(w.number for w in d.warning), name
        runs.append(d.qpos.copy())
    assert np.any(runs[0] != 0)
    assert np.array_equal(runs[0], runs[1])


@pytest.mark.parametrize("name", ["paper-test-0", "random-n6-s3"])
def test_exports_carry_the_features_on_their_lockers(name, tmp_path):
    spec = SPECS[name]
    features = lock_features(spec)
    bare = component_meshes(spec, lock_features=False)
    paths = export_meshes(spec, tmp_path)
    glb = next(p for p in paths if p.suffix == ".glb")
    scene = trimesh.load(glb, force="scene")
    parts = {}
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        parts[node] = scene.geometry[geometry].copy().apply_transform(transform)
    assert set(parts) == set(bare)  # the box, the components, the mechanisms (models.mesh_export)
    for c in spec.components:
        own = [f.mesh.bounds for f in features if f.locker == c.name]
        lo = np.min([bare[c.name].bounds[0], *(b[0] for b in own)], 0)
        hi = np.max([bare[c.name].bounds[1], *(b[1] for b in own)], 0)
        assert np.allclose(parts[c.name].bounds, [lo, hi], atol=1e-6), c.name
        for b in own:
            assert np.all(parts[c.name].bounds[0] <= b[0] + 1e-6) and np.all(b[1] <= parts[c.name].bounds[1] + 1e-6)
        # the part holds exactly its geoms plus its features (volumes add up)
        extra = sum(f.mesh.volume for f in features if f.locker == c.name)
        assert parts[c.name].volume == pytest.approx(bare[c.name].volume + extra, rel=1e-3)
    assert np.allclose(parts[BOX_PART].bounds, bare[BOX_PART].bounds, atol=1e-6)


@pytest.mark.parametrize("kinds", [["lever", "slide", "door"], ["drawer", "wheel", "slide"]])
def test_a_raised_or_sliding_lockers_features_ride_on_its_moving_body(kinds):
    """A lever's and a drawer's moving parts are a child body above their fixed parts: their features go there,
    at the part's height, and keep their place on it as its joint turns or slides."""
    from puzzlebox.models.generator import generate_chain

    spec = generate_chain(kinds, seed=1)
    locker = spec.components[0]
    model = compiled(spec, lock_features=True)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geoms = [g for g in range(model.ngeom) if model.geom(g).name.startswith(f"{locker.name}:lock:")]
    assert geoms
    joint = model.joint(f"{locker.name}:joint")
    handle = model.site(f"{locker.name}:handle_site").id
    for g in geoms:
        assert model.geom_bodyid[g] == model.jnt_bodyid[joint.id]  # the body the joint moves
    feature = next(f for f in lock_features(spec) if f.locker == locker.name)
    assert data.geom_xpos[geoms[0]][2] == pytest.approx(feature.mesh.centroid[2], abs=2e-3)  # at the part's height
    before = data.geom_xpos[geoms[0]] - data.site_xpos[handle]
    data.qpos[joint.qposadr[0]] = model.jnt_range[joint.id, 1]
    mujoco.mj_forward(model, data)
    after = data.geom_xpos[geoms[0]] - data.site_xpos[handle]
    if model.jnt_type[joint.id] == mujoco.mjtJoint.mjJNT_SLIDE:
        np.testing.assert_allclose(after, before, atol=1e-9)  # translated with the tray
    else:
        assert np.linalg.norm(after) == pytest.approx(np.linalg.norm(before), abs=1e-9)  # turned with the arm
