"""Mesh export (issue 15 part 4): every part of a box comes back from GLB, OBJ and STL with the extents and
volume its MuJoCo geoms have (±0.1 mm), computed here from the compiled model, not from the exporter."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
import trimesh

from models import spec_from_dict
from models.generator import RandomGraphConfig, generate_random, paper_family
from models.mesh_export import BOX_PART, MeshExportError, component_meshes, export_meshes
from models.puzzle_box import component_prefixes
from models.scene import SceneConfig, build_scene

TOLERANCE = 1e-4  # 0.1 mm, the target
RANDOM = [(6, False, 0), (9, True, 1), (12, True, 2)] + [(3 + i % 18, i % 2 == 1, 1000 + i) for i in range(50)]
"""The issue's target set: every paper box and 50 random boxes (3-20 components, half with several lockers)."""
SPECS = {s.name: s for s in paper_family("all")} | {
    s.name: s
    for s in (
        generate_random(RandomGraphConfig(n, multi_locker=multi), seed=seed, name=f"random-{n}-{multi}-{seed}")
        for n, multi, seed in RANDOM
    )
}


def model_parts(spec):
    """Part name -> (AABB lo, hi, volume) of the MuJoCo geoms of that body (and its children) in the lid
    frame [m, m³]: analytic per geom type, independent of the exporter's triangles."""
    scene = build_scene(spec, SceneConfig(min_reach=0.0, max_reach=math.inf))
    model = scene.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    body = {name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for name in ["box/lid"]}
    body |= {c.name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, scene.names.components[c.name].body)
             for c in spec.components}  # fmt: skip
    lid = body.pop("box/lid")
    R_lid, p_lid = data.xmat[lid].reshape(3, 3), data.xpos[lid]

    def owner(b):  # the component a body belongs to (walking up), the box for the lid, None elsewhere
        while b > 0:
            for name, root in body.items():
                if b == root:
                    return name
            if b == lid:
                return BOX_PART
            b = model.body_parentid[b]
        return None

    parts: dict[str, list] = {}
    for g in range(model.ngeom):
        name = owner(model.geom_bodyid[g])
        if name is None:
            continue
        R = R_lid.T @ data.geom_xmat[g].reshape(3, 3)
        p = R_lid.T @ (data.geom_xpos[g] - p_lid)
        half, volume = geom_extent(model, g, R)
        parts.setdefault(name, []).append((p - half, p + half, volume))
    return {
        name: (np.min([lo for lo, _, _ in geoms], 0), np.max([hi for _, hi, _ in geoms], 0), sum(v for *_, v in geoms))
        for name, geoms in parts.items()
    }


def geom_extent(model, g, R):
    """Half extents of geom ``g`` rotated by ``R`` (about its centre) and its volume."""
    size, kind = model.geom_size[g], model.geom_type[g]
    axis = R[:, 2]
    side = np.sqrt(np.clip(1 - axis**2, 0, None))  # a circle normal to ``axis`` reaches this far along x, y, z
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return np.abs(R) @ size, 8 * np.prod(size)
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return size[1] * np.abs(axis) + size[0] * side, 2 * math.pi * size[0] ** 2 * size[1]
    if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        return size[1] * np.abs(axis) + size[0], math.pi * size[0] ** 2 * (2 * size[1] + 4 * size[0] / 3)
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        return np.full(3, size[0]), 4 / 3 * math.pi * size[0] ** 3
    if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return np.sqrt((R**2) @ size**2), 4 / 3 * math.pi * np.prod(size)
    raise AssertionError(f"geom type {kind} not in the box models; add its extent here")


def node_meshes(scene: trimesh.Scene) -> dict[str, trimesh.Trimesh]:
    """Node name -> its geometry placed by the scene graph."""
    out = {}
    for node in scene.graph.nodes_geometry:
        transform, geometry = scene.graph[node]
        out[node] = scene.geometry[geometry].copy().apply_transform(transform)
    return out


def assert_matches(meshes: dict[str, trimesh.Trimesh], expected, what: str) -> None:
    assert set(meshes) == set(expected), what
    for name, mesh in meshes.items():
        lo, hi, volume = expected[name]
        assert np.abs(mesh.bounds - [lo, hi]).max() <= TOLERANCE, (what, name, mesh.bounds, lo, hi)
        assert mesh.volume == pytest.approx(volume, rel=2e-3), (what, name)  # closed, outward-facing surfaces


@pytest.mark.parametrize("name", sorted(SPECS))
def test_every_format_reloads_with_the_models_parts_extents_and_volumes(name, tmp_path):
    spec = SPECS[name]
    expected = model_parts(spec)
    assert set(expected) == {BOX_PART, *(c.name for c in spec.components)}
    paths = export_meshes(spec, tmp_path, lock_features=False)  # the scene's MJCF carries no features

    stems = {BOX_PART: BOX_PART, **component_prefixes(spec)}
    per_part = {part: tmp_path / f"{spec.name}-{stem}.stl" for part, stem in stems.items()}
    merged = [tmp_path / f"{spec.name}.{ext}" for ext in ("glb", "obj", "stl")]
    assert sorted(paths) == sorted(merged + list(per_part.values()))
    assert sorted(tmp_path.iterdir()) == sorted(paths)  # nothing else, no temporaries left behind

    assert_matches(node_meshes(trimesh.load(merged[0], force="scene")), expected, "glb")
    obj = trimesh.load(merged[1], force="scene", split_objects=True, group_material=False)
    assert_matches(node_meshes(obj), expected, "obj")
    assert_matches({part: trimesh.load(path, force="mesh") for part, path in per_part.items()}, expected, "stl")

    union = trimesh.load(merged[2], force="mesh")
    lo = np.min([lo for lo, _, _ in expected.values()], 0)
    hi = np.max([hi for _, hi, _ in expected.values()], 0)
    assert np.abs(union.bounds - [lo, hi]).max() <= TOLERANCE
    # the union's bottom is the shell's: the box stands on z = -height in the lid frame
    assert union.bounds[0, 2] == pytest.approx(-spec.box.size[2], abs=TOLERANCE)


def test_parts_are_in_the_lid_frame_wherever_the_box_stands():
    spec = SPECS["paper-test-0"]
    moved = spec_from_dict({**spec.to_dict(), "box": {**spec.to_dict()["box"], "pose": [0.9, -0.4, 1.0]}})
    a, b = component_meshes(spec), component_meshes(moved)
    assert list(a) == [BOX_PART, *(c.name for c in spec.components)]  # the box first, then spec order
    for name in a:
        assert np.allclose(a[name].bounds, b[name].bounds, atol=1e-9), name


def test_a_disassembly_scene_is_refused(scene_dict):
    scene = scene_dict
    with pytest.raises(MeshExportError, match="no box"):
        component_meshes(spec_from_dict(scene))
