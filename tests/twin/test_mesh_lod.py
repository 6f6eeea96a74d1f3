"""Coarser meshes for the rollout video: far fewer triangles, the same silhouette to within pixels, and the
trial's own model untouched."""

import copy

import numpy as np
import pytest

from puzzlebox.lab.rollout_observers import scene_cameras
from puzzlebox.models.generator import paper_family
from puzzlebox.twin.mesh_lod import coarsen_meshes
from puzzlebox.twin.rollout_video import RolloutConfig, RolloutDrawer
from puzzlebox.twin.session import TwinSession


def test_the_video_arm_keeps_its_silhouette_with_fewer_triangles_and_the_gripper_all_of_its():
    with TwinSession(paper_family("test")[0], seed=0) as session:
        faces = int(session.model.mesh_facenum.sum())
        qpos = session.data.qpos.copy()
        qpos[:7] = [-0.607, 0.06, 0.481, 0.87, -0.038, 0.815, 0.538]  # the gripper at a handle (a trial's frame)
        cameras = scene_cameras(session)
        masks = {}
        for cell in (0.0, 0.004):
            drawer = RolloutDrawer(session.model, cameras, RolloutConfig(mesh_cell=cell))
            drawn = int(drawer.model.mesh_facenum.sum())
            arm = np.flatnonzero(drawer.model.geom_group == 1)
            drawer.pose(qpos)
            masks[cell] = {view: drawer.geom_mask(view, arm) for view in ("three-quarter", "wrist")}
            drawer.close()
            assert drawn == faces if cell == 0 else drawn < 0.8 * faces
        assert int(session.model.mesh_facenum.sum()) == faces  # the trial's model is never coarsened
    for view, full in masks[0.0].items():
        coarse = masks[0.004][view]
        assert full.sum() > 1000, view  # the arm in view (the wrist camera sees the fingers)
        iou = (full & coarse).sum() / (full | coarse).sum()
        assert iou > (0.97 if view == "three-quarter" else 0.999), (view, iou)  # the gripper stays whole


def test_coarsening_refuses_a_non_positive_cell_and_moves_no_vertex_beyond_its_neighbourhood():
    with TwinSession(paper_family("test")[0], seed=0) as session:
        with pytest.raises(ValueError, match="positive"):
            coarsen_meshes(session.model, 0.0)
        coarse = copy.deepcopy(session.model)  # never the session's own model
    cell = 0.004
    before = [np.array(coarse.mesh_vert[coarse.mesh_vertadr[m] : coarse.mesh_vertadr[m] + coarse.mesh_vertnum[m]])
              for m in range(coarse.nmesh)]  # fmt: skip
    coarsen_meshes(coarse, cell)
    for m in range(coarse.nmesh):
        v0, f0, nf = coarse.mesh_vertadr[m], coarse.mesh_faceadr[m], coarse.mesh_facenum[m]
        used = np.unique(coarse.mesh_face[f0 : f0 + nf])
        assert nf > 0 and used.max() < coarse.mesh_vertnum[m]
        # a cluster's point lies within a cell of its mean, which lies in the cell of the vertex that carries it
        assert np.abs(coarse.mesh_vert[v0 + used] - before[m][used]).max() <= 2 * cell + 1e-6
