"""A puzzle box as triangle meshes (GLB, OBJ, STL) for viewers, other simulators and 3-D printing.

The geometry is the compiled MuJoCo model's, one source for sim and print: the scene of
:func:`models.scene.build_scene` is compiled, posed at ``qpos0`` (every component closed) and each geom is
turned into triangles at its pose. Parts:

- ``box``: the shell, every geom of the box that no component carries;
- one per component, named by its spec name, holding every geom of that component's body subtree (plate or
  disc, handle, hinge pin and the ArUco marker plate, kept as the thin box it is in the model; its texture is
  not exported) but its mechanism geoms and, unless ``lock_features=False``, the visible lock features whose
  locker it is (:mod:`models.lock_features`: bolts, notches and catches, dark red or black, as
  :func:`models.puzzle_box.build_puzzle_box` with ``lock_features=True`` carries them), so a locker's part
  includes its bolts;
- one per **mechanism** chain (``locks="contact"``, the default; none with ``locks="latch"``, the model
  without mechanisms): the geoms whose name holds ``:interlock:`` or ``:latch:`` (:mod:`models.mechanism_mjcf`),
  wherever they are in the box, grouped by name up to a trailing ``:<index>``: ``<A>:interlock:<B>:wall:<k>``
  make the part ``<A>-interlocks-<B>-wall`` (``A``, ``B`` the spec names of the locker and the locked part),
  ``<A>:latch:<B>:tooth:<k>`` the part ``<A>-latches-<B>-tooth``; after the components, by locker (spec order),
  locked part and role. A mechanism is exported as MuJoCo collides with it: a chain of capsules as one tube
  along their axes (the capsules' union: every vertex on its surface, round ends, the outside of a bend on the
  ball of the joint, its inside the crease where the cylinders meet), a mesh geom (a latch's tooth) as its
  convex hull, a box as itself. These are the shapes the twin collides with, separate parts to print.

Every part is **one watertight solid**: the union (manifold3d) of its geoms' closed meshes, so overlapping or
touching geoms (a hinge pin half in its plate, a drawer's rails against its housing) leave no inner faces nor
edges of more than two faces, also once an STL loader has welded its vertices; faces keep the colour (geom
rgba) of the geom they come from. To that end each geom grows by 50 nm on every side before the union and
edges under 0.1 µm are collapsed after it: steps of the union's surface stay several float32 steps long, so an STL
(float32 coordinates) welded by its loader (trimesh merges vertices within 10 nm) stays one closed surface — at
10 nm a lever's arm against its bracket left steps of 10-20 nm that welding pinched into edges of four faces, that
part's STL and the merged one open. A part that does not survive that round trip (:func:`watertight_as_stl`) is
named in an :class:`OpenMeshWarning`. The merged ``<name>.stl`` is the parts side by side.

Frame and units: the **lid frame** (origin at the centre of the lid's top face, x along the box length, z
up; the shell spans ``z`` from ``-height`` to 0), in **metres** — wherever ``spec.box.pose`` puts the box.
glTF (GLB) is metres by definition; STL and OBJ carry no unit, so a slicer that assumes millimetres needs
a scale of 1000. Round surfaces (cylinders, capsules, spheres) are polygons inscribed in them whose edges
stray at most :data:`SAGITTA` (10 µm) from them, so every part's bounding box is the model's within that.

``<name>.obj`` has one ``o <part>`` object per part (``trimesh.load(path, split_objects=True)`` reads them
back apart); STL has no names, hence ``<name>-<part>.stl`` per part plus the merged ``<name>.stl``.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import manifold3d
import mujoco
import numpy as np
import scipy.spatial
import trimesh
import trimesh.exchange.obj
from trimesh.visual import ColorVisuals

from puzzlebox.models.atomic import write_atomically
from puzzlebox.models.errors import ModelsError
from puzzlebox.models.lock_features import lock_features as features_of
from puzzlebox.models.mechanism_mjcf import LockMode
from puzzlebox.models.puzzle_box import component_prefixes
from puzzlebox.models.scene import BOX, SceneConfig, build_scene
from puzzlebox.models.spec import PuzzleSpec

BOX_PART = "box"
"""Name of the part holding the box shell (the geoms no component carries)."""
SAGITTA = 1e-5
"""Largest gap between a round surface and its polygon [m]: sets the number of sections."""
MECHANISM_TAGS = {"interlock": "interlocks", "latch": "latches"}
"""A geom whose name holds ``:<tag>:`` is a mechanism geom; its part's name says ``-<value>-`` there."""
_MIN_SECTIONS = 8
_GROW = 5e-8
"""Each geom's mesh grows by this [m] on every side before a part's union (:func:`_solid`): several float32 steps
(1.5e-8 m at 0.2 m), so that the steps it leaves survive an STL round trip."""
_WELD = 1e-7
"""Edges shorter than this [m] collapse in a part's union: trimesh welds vertices nearer than 1e-8 m (STL
loading), which would pinch a sliver of the union into edges of four faces."""
_GREY = (0.5, 0.5, 0.5, 1.0)
_JOINT = 1e-7
"""Capsule ends nearer than this [m] are one joint of a chain."""
UNION_JITTER = 1e-6
"""How far [m] each further chain of a mechanism part moves from its geoms (:func:`_mechanism_pieces`)."""
_SKEWS = (np.array([0.28, 0.53, 0.8]), np.array([-0.62, 0.18, 0.76]), np.array([0.45, -0.71, 0.54]))
"""Directions in no plane of the lid frame's axes, added to a chain's own in its jitter, one per attempt."""


class MeshExportError(ModelsError):
    """A spec whose box cannot be exported as meshes."""


class OpenMeshWarning(UserWarning):
    """A part exported whose mesh is not watertight (its union left edges of more than two faces once welded);
    none is in the paper boxes nor in the random boxes of the tests. The message names the spec and the part."""


@dataclass(frozen=True)
class _Part:
    name: str
    stem: str
    """Its ``<part>`` in file names: safe characters, unique."""
    mesh: trimesh.Trimesh


def component_meshes(
    spec: PuzzleSpec, lock_features: bool = True, locks: LockMode = "contact"
) -> dict[str, trimesh.Trimesh]:
    """Part name -> mesh (one watertight solid, faces coloured by geom rgba) in the lid frame [m]: ``box``
    first, then the components in spec order, then the mechanism chains (module docstring; none with
    ``locks="latch"``, the model without mechanisms); with ``lock_features`` each locker's part also holds its
    lock features' meshes (:func:`models.lock_features.lock_features`). Raises :class:`MeshExportError`."""
    return {part.name: part.mesh for part in _parts(spec, lock_features, locks)}


def export_meshes(
    spec: PuzzleSpec, out_dir: str | Path, lock_features: bool = True, locks: LockMode = "contact"
) -> list[Path]:
    """Write ``<name>.glb``, ``<name>.obj``, ``<name>.stl`` (all parts merged) and ``<name>-<part>.stl``
    per part into ``out_dir`` (created), each atomically; lid frame, metres (module docstring); the parts
    are :func:`component_meshes`'s (lock features included unless ``lock_features=False``, mechanisms
    unless ``locks="latch"``). ``<name>`` and ``<part>`` in file names have characters outside
    ``[A-Za-z0-9_.-]`` replaced by '_' (a component's ``<part>`` is its MJCF name, unique; a mechanism's
    spells its components so)."""
    parts = _parts(spec, lock_features, locks)
    out = Path(out_dir)
    stem = _safe(spec.name)
    scene = trimesh.Scene()
    for part in parts:
        scene.add_geometry(part.mesh, node_name=part.name, geom_name=part.name)
    meshes = [part.mesh for part in parts]
    files: list[tuple[Path, Callable[[], bytes]]] = [
        (out / f"{stem}.glb", lambda: _export(scene, "glb")),
        (out / f"{stem}.obj", lambda: trimesh.exchange.obj.export_obj(scene, include_texture=False).encode()),
        (out / f"{stem}.stl", lambda: _export(_merged(meshes), "stl")),
    ]
    for part in parts:
        files.append((out / f"{stem}-{part.stem}.stl", lambda mesh=part.mesh: _export(mesh, "stl")))
    return [write_atomically(path, lambda tmp, make=make: tmp.write_bytes(make())) for path, make in files]


def _export(geometry: trimesh.Trimesh | trimesh.Scene, file_type: str) -> bytes:
    """``geometry`` as a ``file_type`` file (trimesh types ``export`` for all formats at once: dict, bytes or str)."""
    data = geometry.export(file_type=file_type)
    assert isinstance(data, bytes)
    return data


def _merged(meshes: list[trimesh.Trimesh]) -> trimesh.Trimesh:
    """``trimesh.util.concatenate(meshes)``: one mesh (its return type is any geometry)."""
    merged = trimesh.util.concatenate(meshes)
    assert isinstance(merged, trimesh.Trimesh)
    return merged


def geom_mesh(model: mujoco.MjModel, geom: int) -> trimesh.Trimesh:
    """Geom ``geom`` of ``model`` as a closed mesh in its own geom frame [m] (round surfaces inscribed, their
    poles and equators on the frame's axes); raises :class:`MeshExportError` for types without a closed
    surface (plane, height field, SDF)."""
    size = model.geom_size[geom]
    kind = mujoco.mjtGeom(model.geom_type[geom])
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return trimesh.creation.box(extents=2 * size)
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return trimesh.creation.cylinder(radius=size[0], height=2 * size[1], sections=_sections(size[0]))
    if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
        return _capsule(size[0], size[1])
    if kind in (mujoco.mjtGeom.mjGEOM_SPHERE, mujoco.mjtGeom.mjGEOM_ELLIPSOID):
        radii = size if kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID else np.full(3, size[0])
        return _capsule(1.0, 0.0, _sections(float(radii.max()))).apply_scale(radii)
    if kind == mujoco.mjtGeom.mjGEOM_MESH:
        mesh = model.geom_dataid[geom]
        v0, nv = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        f0, nf = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
        # the compiler moves mesh vertices into the geom frame; face indices count from the mesh's first vertex
        vertices, faces = model.mesh_vert[v0 : v0 + nv], model.mesh_face[f0 : f0 + nf]
        return trimesh.Trimesh(vertices.copy(), faces.copy(), process=False)
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom)
    raise MeshExportError(f"geom {name!r}: type {kind.name} has no closed surface to export")


def mechanism_group(geom_name: str) -> str | None:
    """The chain a mechanism geom belongs to: its name (attachment prefix ``box/`` dropped) up to the last
    ``:<index>``, e.g. ``door-0:interlock:slide-1:wall``; ``None`` if the name holds no ``:<tag>:`` of
    :data:`MECHANISM_TAGS` (not a mechanism geom)."""
    name = geom_name.removeprefix(BOX)
    if not any(f":{tag}:" in name for tag in MECHANISM_TAGS):
        return None
    return re.sub(r":\d+$", "", name)


def _parts(spec: PuzzleSpec, lock_features: bool, locks: LockMode) -> list[_Part]:
    if spec.box is None:
        raise MeshExportError(f"spec {spec.name!r} has no box (a disassembly scene): only puzzle boxes export")
    prefixes = component_prefixes(spec)
    if BOX_PART in {c.name for c in spec.components} | set(prefixes.values()):
        raise MeshExportError(f"spec {spec.name!r} names a component {BOX_PART!r}, the name of the box part")
    # the meshes do not depend on where the robot is: build the box wherever it stands, reachable or not
    scene = build_scene(spec, SceneConfig(min_reach=0.0, max_reach=math.inf, locks=locks))
    model = scene.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    lid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{BOX}lid")
    T_lid_world = np.linalg.inv(_pose(data.xpos[lid], data.xmat[lid]))
    box_geoms = _subtree_geoms(model, lid)

    chains: dict[str, list[int]] = {}  # mechanism group -> its geoms
    for g in box_geoms:
        group = mechanism_group(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "")
        if group is not None:
            chains.setdefault(group, []).append(g)
    mechanism = {g for geoms in chains.values() for g in geoms}

    pieces: dict[str, list[tuple[trimesh.Trimesh, tuple]]] = {}
    stems = {BOX_PART: BOX_PART}
    taken: set[int] = set()
    for c in spec.components:
        root = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, scene.names.components[c.name].body)
        geoms = _subtree_geoms(model, root)
        taken.update(geoms)
        pieces[c.name] = [_posed(model, data, g, T_lid_world) for g in geoms if g not in mechanism]
        stems[c.name] = prefixes[c.name]
    pieces = {BOX_PART: [_posed(model, data, g, T_lid_world) for g in box_geoms if g not in taken | mechanism]} | pieces
    if lock_features:
        for feature in features_of(spec):
            visual = feature.mesh.visual
            assert isinstance(visual, ColorVisuals)  # lock_features coloured its faces
            rgba = tuple(visual.face_colors[0] / 255.0) if len(feature.mesh.faces) else _GREY
            pieces[feature.locker] += [(body, rgba) for body in _bodies(feature.mesh)]
    order = {prefix: k for k, prefix in enumerate(prefixes.values())}
    spec_names = {prefix: name for name, prefix in prefixes.items()}
    mechanisms = {}
    for group in sorted(chains, key=lambda group: _mechanism_order(group, order)):
        name, stem = _mechanism_names(group, spec_names)
        if name in pieces or stem in stems.values():
            raise MeshExportError(f"spec {spec.name!r}: mechanism part {name!r} clashes with another part's name")
        mechanisms[name] = group
        stems[name] = stem
    parts = []
    for name in [*pieces, *mechanisms]:
        try:
            if name in pieces:
                mesh = _solid(pieces[name])
            else:  # a mechanism's chains are moved a little (UNION_JITTER), each attempt otherwise
                for attempt in range(len(_SKEWS)):
                    mesh = _solid(_mechanism_pieces(model, data, chains[mechanisms[name]], T_lid_world, attempt))
                    if mesh.is_watertight:
                        break
        except MeshExportError as err:
            raise MeshExportError(f"spec {spec.name!r}, part {name!r}: {err}") from None
        if not watertight_as_stl(mesh):
            warnings.warn(f"spec {spec.name!r}: part {name!r} is not watertight", OpenMeshWarning, stacklevel=3)
        parts.append(_Part(name, stems[name], mesh))
    return parts


def watertight_as_stl(mesh: trimesh.Trimesh) -> bool:
    """Whether ``mesh`` is watertight as an STL loader sees it: its coordinates in float32 and its vertices welded
    (trimesh's tolerance, 10 nm)."""
    loaded = trimesh.Trimesh(np.asarray(mesh.vertices, dtype=np.float32)[mesh.faces].reshape(-1, 3),
                             np.arange(3 * len(mesh.faces)).reshape(-1, 3))  # fmt: skip
    return bool(loaded.is_watertight)


def _split(group: str) -> tuple[str, str, str, list[str]]:
    """``<A>:<tag>:<B>:<role...>`` -> ``(A, tag, B, [role, ...])``."""
    fields = group.split(":")
    i = next(k for k, f in enumerate(fields) if f in MECHANISM_TAGS and 0 < k < len(fields) - 1)
    return ":".join(fields[:i]), fields[i], fields[i + 1], fields[i + 2 :]


def _mechanism_order(group: str, order: dict[str, int]) -> tuple:
    """Mechanism parts by locker (spec order), tag, locked part, role; groups not between two components last."""
    locker, tag, locked, rest = _split(group)
    if locker not in order or locked not in order:
        return (len(order), group)
    return (order[locker], tag, order[locked], rest)


def _mechanism_names(group: str, spec_names: dict[str, str]) -> tuple[str, str]:
    """Part name and file stem of a mechanism group ``<A>:<tag>:<B>:<role...>`` (module docstring)."""
    locker, tag, locked, rest = _split(group)
    if locker not in spec_names or locked not in spec_names:  # not between two components: its own name
        return group.replace(":", "-"), _safe(group.replace(":", "-"))
    name = "-".join([spec_names[locker], MECHANISM_TAGS[tag], spec_names[locked], *rest])
    return name, _safe("-".join([locker, MECHANISM_TAGS[tag], locked, *rest]))


def _posed(model: mujoco.MjModel, data: mujoco.MjData, g: int, T: np.ndarray) -> tuple[trimesh.Trimesh, tuple]:
    """Geom ``g``'s mesh at its ``data`` pose moved by ``T`` (world -> export frame), and its rgba."""
    piece = geom_mesh(model, g)
    piece.apply_transform(T @ _pose(data.geom_xpos[g], data.geom_xmat[g]))
    return piece, tuple(model.geom_rgba[g])


def _mechanism_pieces(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: list[int], T: np.ndarray, attempt: int = 0
) -> list[tuple[trimesh.Trimesh, tuple]]:
    """A mechanism group's geoms as MuJoCo collides with them, in the export frame (``T``: world -> export):
    capsules joined end to end (a chain, in index order; a lone capsule is a chain of one) are one tube
    (:func:`_tubes`; the k-th chain of the group moved by ``k (attempt + 1)`` :data:`UNION_JITTER`), a mesh geom is
    its convex hull (the k-th moved by ``(k + 1) attempt`` :data:`UNION_JITTER` after the first attempt), any other geom
    its :func:`geom_mesh`."""
    pieces: list[tuple[trimesh.Trimesh, tuple]] = []
    chain: list[np.ndarray] = []
    radius, rgba = 0.0, _GREY

    made = 0  # chains made so far
    meshes = 0  # mesh geoms so far

    def flush() -> None:
        nonlocal made
        points = np.array(chain)
        # a wall's backing chains are copies of its axis chain, their rings in the same planes: each chain after
        # the first moves by UNION_JITTER more, mostly along itself, so no two rings are coplanar (the union of
        # near-coplanar rings leaves slivers that welding pinches)
        along = points[-1] - points[0]
        along = along / max(float(np.linalg.norm(along)), _JOINT) + _SKEWS[attempt]
        shift = UNION_JITTER * (attempt + 1) * made * along / np.linalg.norm(along)
        pieces.extend((tube.apply_translation(shift), rgba) for tube in _tubes(points, radius))
        chain.clear()
        made += 1

    for g in sorted(geoms, key=lambda g: _index(model, g)):
        kind = mujoco.mjtGeom(model.geom_type[g])
        pose = T @ _pose(data.geom_xpos[g], data.geom_xmat[g])
        if kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
            half, r = model.geom_size[g][1], model.geom_size[g][0]
            ends = [pose[:3, 3] - half * pose[:3, 2], pose[:3, 3] + half * pose[:3, 2]]
            if chain and r == radius:
                joins = [min(_gap(chain[i], e) for e in ends) < _JOINT for i in (0, -1)]
                if len(chain) == 2 and joins[0] and not joins[1]:
                    chain.reverse()  # the first capsule of the chain points away from the second
                if _gap(chain[-1], ends[1]) < _JOINT:
                    ends.reverse()
                if _gap(chain[-1], ends[0]) < _JOINT:
                    chain.append(ends[1])
                    continue
            if chain:
                flush()
            chain[:], radius, rgba = ends, r, tuple(model.geom_rgba[g])
            continue
        if chain:
            flush()
        if kind == mujoco.mjtGeom.mjGEOM_MESH:
            vertices = geom_mesh(model, g).apply_transform(pose).vertices
            hull = trimesh.convex.convex_hull(vertices)
            if attempt:  # a row of teeth turned a little from one to the next: faces near-coplanar, as rings are
                hull.apply_translation(
                    UNION_JITTER * attempt * (meshes + 1) * _SKEWS[attempt] / np.linalg.norm(_SKEWS[attempt])
                )
            meshes += 1
            pieces.append((hull, tuple(model.geom_rgba[g])))
        else:
            pieces.append(_posed(model, data, g, T))
    if chain:
        flush()
    return pieces


def _tubes(points: np.ndarray, radius: float) -> list[trimesh.Trimesh]:
    """The capsule chain along ``points`` (``(n, 3)``) of ``radius`` as closed tubes (:func:`_tube`): one,
    but split at a bend so sharp for its segments that the creases of its ends would cross (a U-turn within a
    radius; the split tubes overlap in a ball at the joint, the part's union joins them: every other one is
    thinner by 2 :data:`SAGITTA`, so their surfaces cross rather than graze)."""
    keep = np.concatenate([[True], np.linalg.norm(np.diff(points, axis=0), axis=1) > _JOINT])
    points = points[keep]
    if len(points) == 1:
        return [_capsule(radius, 0.0).apply_translation(points[0])]
    u = np.diff(points, axis=0)
    length = np.linalg.norm(u, axis=1)
    u /= length[:, None]
    cos = np.clip(np.sum(u[:-1] * u[1:], axis=1), -1.0, 1.0)
    with np.errstate(divide="ignore"):
        mitre = radius * np.sqrt((1.0 - cos) / (1.0 + cos))  # r tan(bend / 2): how far a crease reaches
    reach = np.concatenate([[0.0], mitre, [0.0]])
    short = reach[:-1] + reach[1:] > length  # a segment whose ends' creases would cross
    splits = np.flatnonzero(short[:-1] | short[1:]) + 1
    runs = zip([0, *splits], [*splits, len(points) - 1], strict=True)
    # every other tube thinner by twice the sagitta: its ball at a shared joint lies inside the other's polygons
    thin = radius - min(2 * SAGITTA, radius / 50)
    return [_tube(points[a : b + 1], thin if k % 2 else radius) for k, (a, b) in enumerate(runs)]


def _tube(points: np.ndarray, radius: float) -> trimesh.Trimesh:
    """A closed tube of ``radius`` along the polyline ``points`` with round ends: the union of the capsules
    between consecutive points, inscribed (every vertex on its surface). Rings of vertices on each segment's
    cylinder; at an inner point the outside of the bend is the ball's, swept in steps of at most one section's
    angle, and the inside the two cylinders' crease, in the plane halving the bend; hemispheres at the ends.
    The frame is carried from segment to segment by the rotation between them, so faces between two rings lie
    on the cylinder of the segment they span."""
    n = _sections(radius)
    n += -n % 4
    theta = 2 * np.pi * np.arange(n) / n
    u = np.diff(points, axis=0)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    e1 = np.cross(u[0], np.eye(3)[np.argmin(np.abs(u[0]))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u[0], e1)
    vertices: list[np.ndarray] = []

    def add(points: np.ndarray) -> np.ndarray:
        vertices.append(points.reshape(-1, 3))
        return sum(len(v) for v in vertices[:-1]) + np.arange(len(vertices[-1]))

    def circle(e1: np.ndarray, e2: np.ndarray, scale: float = 1.0) -> np.ndarray:
        return scale * radius * (np.cos(theta)[:, None] * e1 + np.sin(theta)[:, None] * e2)

    lat = np.pi / 2 * np.arange(1, n // 4) / (n // 4)  # latitudes of the cap rings, from the equator
    poles = [add(points[0] - radius * u[0])]
    rings = [add(points[0] - radius * np.sin(a) * u[0] + circle(e1, e2, np.cos(a))) for a in lat[::-1]]
    rings.append(add(points[0] + circle(e1, e2)))
    for k in range(1, len(points) - 1):
        a, b = u[k - 1], u[k]
        c = circle(e1, e2)
        turn = b - (a @ b) * a
        if np.linalg.norm(turn) < 1e-12:  # straight on
            rings.append(add(points[k] + c))
            continue
        t = (a + b) / np.linalg.norm(a + b)
        bend = math.acos(float(np.clip(a @ b, -1.0, 1.0)))
        axis = np.cross(a, b) / np.linalg.norm(np.cross(a, b))
        steps = max(1, math.ceil(bend * n / (2 * np.pi) - 1e-9))
        # the inside of the bend: the crease, where the cylinders meet; and the points of the outside that one
        # step of the sweep would move by less than _WELD (welded on loading, they would pinch the surface)
        inner = c @ (turn / np.linalg.norm(turn)) > -_WELD / (2 * math.sin(bend / (2 * steps)))
        crease = add(points[k] + c[inner] - np.outer(c[inner] @ t / (a @ t), a))
        for step in range(steps + 1):  # the outside: on the ball
            ring = np.empty(n, dtype=int)
            ring[inner] = crease
            ring[~inner] = add(points[k] + _turn(c[~inner], axis, bend * step / steps))
            rings.append(ring)
        e1, e2 = _turn(e1, axis, bend), _turn(e2, axis, bend)
    rings.append(add(points[-1] + circle(e1, e2)))
    rings += [add(points[-1] + radius * np.sin(a) * u[-1] + circle(e1, e2, np.cos(a))) for a in lat]
    poles.append(add(points[-1] + radius * u[-1]))
    i = np.arange(n)
    j = (i + 1) % n
    faces = [np.column_stack([np.full(n, poles[0][0]), rings[0][j], rings[0][i]])]
    for a, b in zip(rings[:-1], rings[1:], strict=True):
        faces += [np.column_stack([a[i], a[j], b[j]]), np.column_stack([a[i], b[j], b[i]])]
    faces.append(np.column_stack([np.full(n, poles[1][0]), rings[-1][i], rings[-1][j]]))
    faces = np.vstack(faces)
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])]
    tube = trimesh.Trimesh(np.vstack(vertices), faces, process=False)
    if tube.volume < 0:
        tube.invert()
    return tube


def _turn(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Vectors ``v`` (rows) turned by ``angle`` about the unit ``axis``."""
    c, s = math.cos(angle), math.sin(angle)
    return v * c + np.cross(axis, v) * s + np.outer(v @ axis, axis) * (1.0 - c)


def _index(model: mujoco.MjModel, g: int) -> tuple[str, int]:
    """Sort key of a mechanism geom: its name without, then with, its trailing ``:<index>``."""
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
    match = re.search(r":(\d+)$", name)
    return (name[: match.start()], int(match.group(1))) if match else (name, -1)


def _gap(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b))


def _solid(pieces: Iterable[tuple[trimesh.Trimesh, tuple]]) -> trimesh.Trimesh:
    """The union of closed meshes as one watertight mesh, each face coloured (rgba) by the piece it comes
    from. Each piece is first grown by :data:`_GROW` along each axis, so pieces that touch (a drawer's rails
    against its housing, edge to edge) overlap and fuse rather than meet along an edge of four faces; edges
    shorter than :data:`_WELD` are collapsed afterwards (pieces whose faces meet within float error, a bolt on
    a plate, leave slivers that welding vertices on loading an STL would pinch)."""
    manifolds, colours = [], {}
    for piece, rgba in pieces:
        piece = piece.copy()
        piece.merge_vertices()
        if piece.volume < 0:
            piece.invert()
        lo, hi = piece.bounds
        centre, half = (lo + hi) / 2, np.maximum((hi - lo) / 2, _GROW)
        piece.vertices = centre + (piece.vertices - centre) * (1.0 + _GROW / half)
        solid = _manifold(piece.vertices, piece.faces)
        if solid.status() != manifold3d.Error.NoError:
            raise MeshExportError(f"a geom's mesh is not a closed surface ({solid.status().name})")
        solid = solid.as_original()
        colours[solid.original_id()] = rgba
        manifolds.append(solid)
    if not manifolds:
        raise MeshExportError("a part without geoms cannot be exported")
    union = manifold3d.Manifold.batch_boolean(manifolds, manifold3d.OpType.Add).to_mesh64()
    faces = np.asarray(union.tri_verts, dtype=np.int64)
    vertices = np.asarray(union.vert_properties)[:, :3]
    rgba = np.empty((len(faces), 4))
    runs = np.asarray(union.run_index, dtype=np.int64) // 3  # runs of triangles by original mesh
    for start, stop, original in zip(runs[:-1], runs[1:], union.run_original_id, strict=True):
        rgba[start:stop] = colours.get(int(original), _GREY)
    # weld as one original (manifold keeps the seams between originals); a face keeps the colour of the
    # union's face nearest to it (it moved by less than _WELD)
    welded = _manifold(vertices, faces).simplify(_WELD).to_mesh64()
    out = trimesh.Trimesh(np.asarray(welded.vert_properties)[:, :3], np.asarray(welded.tri_verts, np.int64))
    nearest = scipy.spatial.KDTree(vertices[faces].mean(axis=1)).query(out.triangles_center)[1]
    assert isinstance(out.visual, ColorVisuals)  # a new mesh's
    out.visual.face_colors = np.round(255 * rgba[nearest]).astype(np.uint8)
    return out


def _manifold(vertices: np.ndarray, faces: np.ndarray) -> manifold3d.Manifold:
    mesh = manifold3d.Mesh64(
        vert_properties=np.array(vertices, dtype=np.float64, order="C"),  # copies: writable
        tri_verts=np.array(faces, dtype=np.uint64, order="C"),
    )
    return manifold3d.Manifold(mesh)


def _bodies(mesh: trimesh.Trimesh) -> list[trimesh.Trimesh]:
    """The connected pieces of a mesh (a concatenation of closed meshes), each closed."""
    mesh = mesh.copy()
    mesh.merge_vertices()
    return list(mesh.split(only_watertight=False))


def _capsule(radius: float, half: float, sections: int | None = None) -> trimesh.Trimesh:
    """A closed capsule along z (a sphere when ``half`` is 0), inscribed: ``sections`` (a multiple of 4, by
    default from :data:`SAGITTA`) around z and as many per turn from pole to pole, equator and poles included."""
    n = sections or _sections(radius)
    n += -n % 4
    theta = np.linspace(-np.pi / 2, np.pi / 2, n // 2 + 1)
    r, z = np.cos(theta), np.sin(theta)
    r[0] = r[-1] = 0.0
    split = n // 4  # the equator: the lower cap ends there, the upper begins
    h = half / radius
    profile = np.concatenate(
        [np.column_stack([r[: split + 1], z[: split + 1] - h]), np.column_stack([r[split:], z[split:] + h])]
    )
    if half == 0.0:
        profile = np.delete(profile, split + 1, axis=0)
    # built at unit radius, then scaled: trimesh drops triangles of area under 1e-8 as degenerate
    return trimesh.creation.revolve(profile, sections=n).apply_scale(radius)


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
