"""puzzlebox skills: the robot's pipeline — perception, joint models, primitives — over the twin's
robot interface only (DESIGN.md, "Layers": never simulator ground truth)."""

from puzzlebox.skills.errors import MarkersNotFound, SkillError, UnknownMarker
from puzzlebox.skills.joint_model import JointModel, joint_model
from puzzlebox.skills.perception import (
    MarkerDetection,
    MarkerDetector,
    PerceptionConfig,
    kind_of,
    lid_height,
    select_markers,
    upright_pose,
)
from puzzlebox.skills.toggle_recorder import ToggleRecorder

__all__ = [
    "JointModel",
    "MarkerDetection",
    "MarkerDetector",
    "MarkersNotFound",
    "PerceptionConfig",
    "SkillError",
    "ToggleRecorder",
    "UnknownMarker",
    "joint_model",
    "kind_of",
    "lid_height",
    "select_markers",
    "upright_pose",
]
