"""A puzzle box as triangle meshes (GLB, OBJ, STL) for viewers, other simulators and 3-D printing.

The geometry is the compiled MuJoCo model's: the scene of :func:`models.scene.build_scene` is compiled,
posed at ``qpos0`` (every component closed) and each geom is turned into triangles at its pose. Parts:
``box`` (the shell: every geom of the box that no component carries) and one per component, named by its
spec name, holding every geom of that component's body subtree (plate or disc, handle, hinge pin and the
ArUco marker plate, kept as the thin box it is in the model; its texture is not exported) and, unless
``lock_features=False``, the visible lock features whose locker it is (:mod:`models.lock_features`: bolts,
notches and catches, dark red or black, as :func:`models.puzzle_box.build_puzzle_box` with
``lock_features=True`` carries them), so a locker's part includes its bolts.

Frame and units: the **lid frame** (origin at the centre of the lid's top face, x along the box length, z
up; the shell spans ``z`` from ``-height`` to 0), in **metres** — wherever ``spec.box.pose`` puts the box.
glTF (GLB) is metres by definition; STL and OBJ carry no unit, so a slicer that assumes millimetres needs
a scale of 1000. Round surfaces (cylinders, capsules, spheres) are polygons whose sagitta is at most
:data:`SAGITTA` (10 µm), so every part's bounding box is the model's within that.

``<name>.obj`` has one ``o <part>`` object per part (``trimesh.load(path, split_objects=True)`` reads them
back apart); STL has no names, hence ``<name>-<part>.stl`` per part plus the merged ``<name>.stl``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np
import trimesh

from models.atomic import write_atomically
from models.errors import ModelsError
from models.lock_features import lock_features as features_of
from models.puzzle_box import component_prefixes
from models.scene import BOX, SceneConfig, build_scene
from models.spec import PuzzleSpec

BOX_PART = "box"
"""Name of the part holding the box shell (the geoms no component carries)."""
SAGITTA = 1e-5
"""Largest gap between a round surface and its polygon [m]: sets the number of sections."""
_MIN_SECTIONS = 8


class MeshExportError(ModelsError):
    """A spec whose box cannot be exported as meshes."""


def component_meshes(spec: PuzzleSpec, lock_features: bool = True) -> dict[str, trimesh.Trimesh]:
    """Part name -> mesh (its geoms concatenated, coloured by geom rgba) in the lid frame [m]:
    ``box`` first, then the components in spec order; with ``lock_features`` each locker's part also holds
    its lock features' meshes (:func:`models.lock_features.lock_features`). Raises :class:`MeshExportError`."""
    if spec.box is None:
        raise MeshExportError(f"spec {spec.name!r} has no box (a disassembly scene): only puzzle boxes export")
    if BOX_PART in {c.name for c in spec.components} | set(component_prefixes(spec).values()):
        raise MeshExportError(f"spec {spec.name!r} names a component {BOX_PART!r}, the name of the box part")
    # the meshes do not depend on where the robot is: build the box wherever it stands, reachable or not
    scene = build_scene(spec, SceneConfig(min_reach=0.0, max_reach=math.inf))
    model = scene.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    lid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{BOX}lid")
    T_lid_world = np.linalg.inv(_pose(data.xpos[lid], data.xmat[lid]))
    bodies = {c.name: scene.names.components[c.name].body for c in spec.components}
    roots = {name: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body) for name, body in bodies.items()}
    taken: set[int] = set()
    parts: dict[str, list[int]] = {}
    for name, root in roots.items():
        parts[name] = _subtree_geoms(model, root)
        taken.update(parts[name])
    shell = [g for g in _subtree_geoms(model, lid) if g not in taken]
    parts = {BOX_PART: shell, **parts}
    meshes = {name: _part_mesh(model, data, geoms, T_lid_world) for name, geoms in parts.items()}
    if lock_features:
        for feature in features_of(spec):
            meshes[feature.locker] = trimesh.util.concatenate([meshes[feature.locker], feature.mesh])
    return meshes


def export_meshes(spec: PuzzleSpec, out_dir: str | Path, lock_features: bool = True) -> list[Path]:
    """Write ``<name>.glb``, ``<name>.obj``, ``<name>.stl`` (all parts merged) and ``<name>-<part>.stl``
    per part into ``out_dir`` (created), each atomically; lid frame, metres (module docstring); the parts
    are :func:`component_meshes`'s (lock features included unless ``lock_features=False``).
    ``<name>`` and ``<part>`` in file names have characters outside ``[A-Za-z0-9_.-]`` replaced by '_'."""
    meshes = component_meshes(spec, lock_features=lock_features)
    out = Path(out_dir)
    stem = _safe(spec.name)
    scene = trimesh.Scene()
    for name, mesh in meshes.items():
        scene.add_geometry(mesh, node_name=name, geom_name=name)
    files: list[tuple[Path, Callable[[], bytes]]] = [
        (out / f"{stem}.glb", lambda: scene.export(file_type="glb")),
        (out / f"{stem}.obj", lambda: trimesh.exchange.obj.export_obj(scene, include_texture=False).encode()),
        (out / f"{stem}.stl", lambda: trimesh.util.concatenate(list(meshes.values())).export(file_type="stl")),
    ]
    files_of = {BOX_PART: BOX_PART, **component_prefixes(spec)}  # safe, unique file names per part
    for name, mesh in meshes.items():
        files.append((out / f"{stem}-{files_of[name]}.stl", lambda mesh=mesh: mesh.export(file_type="stl")))
    return [write_atomically(path, lambda tmp, make=make: tmp.write_bytes(make())) for path, make in files]


def geom_mesh(model: mujoco.MjModel, geom: int) -> trimesh.Trimesh:
    """Geom ``geom`` of ``model`` as a mesh in its own geom frame [m]; raises :class:`MeshExportError`
    for types without a closed surface (plane, height field, SDF)."""
    size = model.geom_size[geom]
    kind = mujoco.mjtGeom(model.geom_type[geom])
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return trimesh.creation.box(extents=2 * size)
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return trimesh.creation.cylinder(radius=size[0], height=2 * size[1], sections=_sections(size[0]))
    if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        n = _sections(size[0])
        return trimesh.creation.capsule(height=2 * size[1], radius=size[0], count=[n, n])
    if kind in (mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_ELLIPSOID):
        radii = size if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID else np.full(3, size[0])
        n = _sections(float(radii.max()))
        sphere = trimesh.creation.uv_sphere(radius=1.0, count=[n, n])
        return sphere.apply_scale(radii)
    if kind == mujoco.mjtGeom.mjGEOM_MESH:
        mesh = model.geom_dataid[geom]
        v0, nv = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        f0, nf = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
        # the compiler moves mesh vertices into the geom frame; face indices count from the mesh's first vertex
        vertices, faces = model.mesh_vert[v0 : v0 + nv], model.mesh_face[f0 : f0 + nf]
        return trimesh.Trimesh(vertices.copy(), faces.copy(), process=False)
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom)
    raise MeshExportError(f"geom {name!r}: type {kind.name} has no closed surface to export")


def _part_mesh(model: mujoco.MjModel, data: mujoco.MjData, geoms: list[int], T: np.ndarray) -> trimesh.Trimesh:
    """The geoms at their ``data`` poses, moved by ``T`` (world -> export frame) and concatenated."""
    pieces = []
    for g in geoms:
        piece = geom_mesh(model, g)
        piece.apply_transform(T @ _pose(data.geom_xpos[g], data.geom_xmat[g]))
        piece.visual.face_colors = np.round(255 * model.geom_rgba[g]).astype(np.uint8)
        pieces.append(piece)
    if not pieces:
        raise MeshExportError("a part without geoms cannot be exported")
    return trimesh.util.concatenate(pieces)


def _subtree_geoms(model: mujoco.MjModel, root: int) -> list[int]:
    """Ids of the geoms on body ``root`` and every body below it."""
    inside = np.zeros(model.nbody, dtype=bool)
    inside[root] = True
    for body in range(root + 1, model.nbody):  # MuJoCo numbers a parent before its children
        inside[body] = inside[model.body_parentid[body]]
    return [g for g in range(model.ngeom) if inside[model.geom_bodyid[g]]]


def _pose(pos: np.ndarray, xmat: np.ndarray) -> np.ndarray:
    """4x4 transform from a position and a row-major 3x3 rotation (MuJoCo's ``xmat``)."""
    T = np.eye(4)
    T[:3, :3] = np.asarray(xmat).reshape(3, 3)
    T[:3, 3] = pos
    return T


def _sections(radius: float) -> int:
    """Polygon sections so a circle of ``radius`` [m] strays at most :data:`SAGITTA` from its polygon."""
    if radius <= SAGITTA:
        return _MIN_SECTIONS
    return max(_MIN_SECTIONS, math.ceil(math.pi / math.acos(1.0 - SAGITTA / radius)))


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name) or "puzzlebox"
