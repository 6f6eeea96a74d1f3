"""Per-trial physics: the profile's friction, damping, mass, latch-compliance and grip draws applied to
the session's model (:class:`~twin.reality.PhysicsReality`), one factor per component from the
session's seed. The damping, joint friction and latch compliance applied are these factors times the
cell's factor of the component's kind (:class:`~twin.cell.KindFactors`, :meth:`PhysicsDraw.times`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np

from puzzlebox.twin.reality import PhysicsReality


@dataclass(frozen=True)
class PhysicsDraw:
    """The factors drawn for one trial, one per component in spec order [-]."""

    friction: np.ndarray
    joint_damping: np.ndarray
    joint_friction: np.ndarray
    mass: np.ndarray
    latch_compliance: np.ndarray

    def times(self, joint_damping: np.ndarray, joint_friction: np.ndarray, latch_compliance: np.ndarray) -> PhysicsDraw:
        """These factors with the damping, joint friction and latch compliance multiplied by the given ones (one
        per component, e.g. the cell's kind factors): what is applied to the model."""
        return replace(
            self,
            joint_damping=self.joint_damping * joint_damping,
            joint_friction=self.joint_friction * joint_friction,
            latch_compliance=self.latch_compliance * latch_compliance,
        )


def draw_physics(config: PhysicsReality, n: int, rng: np.random.Generator) -> PhysicsDraw:
    return PhysicsDraw(
        friction=np.asarray(config.friction_scale.draw(rng, n)),
        joint_damping=np.asarray(config.joint_damping_scale.draw(rng, n)),
        joint_friction=np.asarray(config.joint_friction_scale.draw(rng, n)),
        mass=np.asarray(config.mass_scale.draw(rng, n)),
        latch_compliance=np.asarray(config.latch_compliance_scale.draw(rng, n)),
    )


def subtree_bodies(model: mujoco.MjModel, root: int) -> np.ndarray:
    """Ids of body ``root`` and of every body below it in ``model``'s tree."""
    inside = np.zeros(model.nbody, dtype=bool)
    inside[root] = True
    for b in range(root + 1, model.nbody):  # MuJoCo numbers a parent before its children
        inside[b] = inside[model.body_parentid[b]]
    return np.flatnonzero(inside)


def apply_physics(
    model: mujoco.MjModel,
    config: PhysicsReality,
    draw: PhysicsDraw,
    handle_geoms: np.ndarray,
    component_dofs: np.ndarray,
    component_bodies: np.ndarray,
    latch_eqs: np.ndarray,
) -> bool:
    """Scale the model's fields by ``draw``; True if anything changed (then call ``mj_setConst``)."""
    changed = False
    if config.pad_friction is not None or np.any(draw.friction != 1) or config.grip_force_scale != 1.0:
        # the handle geoms have priority 2: their friction is the handle/pad contact's (DESIGN.md). A weaker
        # grip is applied as the pad friction it leaves: what holds a handle is the friction capacity
        # 2 mu N, and scaling mu by the grip's factor scales it as scaling N would. (Scaling the gripper
        # servo itself does not model a weaker grip: the robosuite linkage's passive resistance then
        # stalls the fingers short of a 12 mm post — at 1/3 they stopped 5 mm off it and crept on.)
        base = model.geom_friction[handle_geoms, 0] if config.pad_friction is None else config.pad_friction
        model.geom_friction[handle_geoms, 0] = base * draw.friction * config.grip_force_scale
        changed = True
    if np.any(draw.joint_damping != 1) or np.any(draw.joint_friction != 1):
        model.dof_damping[component_dofs] *= draw.joint_damping
        model.dof_frictionloss[component_dofs] *= draw.joint_friction
        changed = True
    if np.any(draw.mass != 1):
        for body, s in zip(component_bodies, draw.mass, strict=True):
            for b in subtree_bodies(model, body):
                model.body_mass[b] *= s
                model.body_inertia[b] *= s
        changed = True
    if np.any(draw.latch_compliance != 1):
        model.eq_solref[latch_eqs, 0] *= draw.latch_compliance
        changed = True
    return changed
