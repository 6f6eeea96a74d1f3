"""Coarser meshes for pictures: the xArm's meshes carry 91 k triangles (the gripper's base alone 24 k), and on the
CPU renderer (llvmpipe) every one of them costs in every view whether it is seen or not (up to half of a rollout
view's rendering). :func:`coarsen_meshes` simplifies a model's meshes in place, for drawing only, by vertex
clustering on a grid, each cluster's vertex placed where it best keeps the faces around it (the quadric error of
Lindstrom, "Out-of-core simplification of large polygonal models", SIGGRAPH 2000): flat faces stay flat and creases
stay sharp; the normals are the coarse mesh's own (smooth across a corner, flat across a crease). Only the face
list shrinks (``mesh_facenum``); vertex and normal arrays keep their sizes, so the model stays a valid
:class:`mujoco.MjModel` for kinematics and rendering. Never apply it to a model that collides or that the
pipeline's cameras render: its geometry is the drawing's alone. Thin shells (the gripper's) fold on themselves
when their two faces fall in one cell: keep such meshes out.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import mujoco
import numpy as np

__all__ = ["coarsen_meshes"]


def coarsen_meshes(model: mujoco.MjModel, cell: float, meshes: Iterable[int] | None = None) -> int:
    """Simplify ``meshes`` of ``model`` (default: all) in place by clustering their vertices in cubes of ``cell``
    [m]; returns the number of faces left in them. Each cluster becomes one vertex (at the point that minimises
    the squared distances to its faces' planes, near the cluster's mean); faces whose corners fall in fewer than
    three clusters vanish, and so do duplicates. Normals are recomputed (:func:`_normals`); texture coordinates are
    kept."""
    if not cell > 0:
        raise ValueError(f"cell must be positive [m], got {cell}")
    left = 0
    for mesh in range(model.nmesh) if meshes is None else meshes:
        left += _coarsen(model, int(mesh), cell)
    return left


def _coarsen(model: mujoco.MjModel, mesh: int, cell: float) -> int:
    v0, nv = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    f0, nf = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
    verts = np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=float)
    faces = np.asarray(model.mesh_face[f0 : f0 + nf], dtype=np.int64)
    if nf == 0:
        return 0
    _, first, cluster = np.unique(np.floor(verts / cell).astype(np.int64), axis=0, return_index=True,
                                  return_inverse=True)  # fmt: skip
    cluster = cluster.ravel()
    n = len(first)
    mean = np.zeros((n, 3))
    np.add.at(mean, cluster, verts)
    mean /= np.bincount(cluster, minlength=n)[:, None]
    # each face's plane (unit normal, offset) weighted by its area, added to the quadric of its corners' clusters
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    normal = np.cross(b - a, c - a)
    area = np.linalg.norm(normal, axis=1)
    unit = normal / np.maximum(area, 1e-18)[:, None]
    plane = np.concatenate([unit, -np.einsum("ij,ij->i", unit, a)[:, None]], axis=1)
    quadric = 0.5 * area[:, None, None] * plane[:, :, None] * plane[:, None, :]
    total = np.zeros((n, 4, 4))
    for corner in range(3):
        np.add.at(total, cluster[faces[:, corner]], quadric)
    # minimise p' A p - 2 b' p + eps |p - mean|^2: eps keeps a flat or straight cluster's point near its mean
    A, rhs = total[:, :3, :3], -total[:, :3, 3]
    eps = 1e-3 * np.trace(A, axis1=1, axis2=2)[:, None, None] + 1e-15
    point = np.linalg.solve(A + eps * np.eye(3), (rhs + eps[:, :, 0] * mean)[:, :, None])[:, :, 0]
    stray = np.abs(point - mean).max(axis=1) > cell  # an ill-posed cluster: keep its mean
    point[stray] = mean[stray]
    # faces over cluster representatives (the first vertex of each cluster, moved to the cluster's point)
    corners = first[cluster][faces]
    kept = np.flatnonzero(
        (corners[:, 0] != corners[:, 1]) & (corners[:, 1] != corners[:, 2]) & (corners[:, 0] != corners[:, 2])
    )
    # duplicates: the same corners in the same turning order (a face and its back are both kept)
    k = corners[kept]
    start = np.argmin(k, axis=1)
    rows = np.arange(len(k))
    canonical = np.stack([k[rows, (start + j) % 3] for j in range(3)], axis=1)
    _, unique = np.unique(canonical, axis=0, return_index=True)
    kept = kept[np.sort(unique)]
    count = len(kept)
    model.mesh_vert[v0 + first] = point
    faces_left = corners[kept]
    normals = _normals(np.asarray(model.mesh_vert[v0 : v0 + nv], dtype=float), faces_left)
    model.mesh_face[f0 : f0 + count] = faces_left
    n0, room = int(model.mesh_normaladr[mesh]), int(model.mesh_normalnum[mesh])
    if normals is not None and len(normals[0]) <= room:
        model.mesh_normal[n0 : n0 + len(normals[0])] = normals[0]
        model.mesh_facenormal[f0 : f0 + count] = normals[1]
    else:  # no room for them: each corner keeps its own normal as modelled
        model.mesh_facenormal[f0 : f0 + count] = np.array(model.mesh_facenormal[f0 : f0 + nf])[kept]
    if model.mesh_facetexcoord.shape[0] >= f0 + nf and model.mesh_texcoordnum[mesh] > 0:
        model.mesh_facetexcoord[f0 : f0 + count] = np.array(model.mesh_facetexcoord[f0 : f0 + nf])[kept]
    model.mesh_facenum[mesh] = count
    return count


CREASE = math.cos(math.radians(40.0))
"""Cosine of the angle between a face and the mean of the faces around a corner beyond which the face is drawn flat
at that corner (a crease), not smooth."""


def _normals(verts: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Normals of a coarsened mesh: at each corner the area-weighted mean of the faces around its vertex, or the
    face's own where they differ by more than :data:`CREASE` (an edge stays sharp). The modelled normals belonged to
    vertices that have moved: kept, they would crumple the shading. Returns the normals and each face's three
    indices into them, or None for a mesh with no face."""
    if not len(faces):
        return None
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    face_normal = np.cross(b - a, c - a)  # its length is twice the area: the weight
    smooth = np.zeros_like(verts)
    for corner in range(3):
        np.add.at(smooth, faces[:, corner], face_normal)
    used = np.unique(faces)
    index = np.full(len(verts), -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    unit = smooth[used] / np.maximum(np.linalg.norm(smooth[used], axis=1), 1e-18)[:, None]
    flat = face_normal / np.maximum(np.linalg.norm(face_normal, axis=1), 1e-18)[:, None]
    corner_index = index[faces]
    sharp = np.einsum("fj,fcj->fc", flat, unit[corner_index]) < CREASE
    flat_faces = np.flatnonzero(sharp.any(axis=1))
    flat_index = np.full(len(faces), -1, dtype=np.int64)
    flat_index[flat_faces] = len(used) + np.arange(len(flat_faces))
    corner_index = np.where(sharp, flat_index[:, None], corner_index)
    return np.concatenate([unit, flat[flat_faces]]).astype(np.float32), corner_index.astype(np.int32)
