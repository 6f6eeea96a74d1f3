"""puzzlebox shared vocabulary: puzzle specs, component kinds, lock semantics, the generator and
the symbolic observation / ``World`` protocol that the agent and the robot pipeline both speak."""

import os

# Headless by default: dm_control and mujoco pick their GL backend at import time (DESIGN.md: EGL
# renders on the CPU here); a user's own MUJOCO_GL wins.
os.environ.setdefault("MUJOCO_GL", "egl")

from puzzlebox.models.errors import (
    GeneratorError,
    ModelsError,
    ReachabilityUndecided,
    SpecError,
    SpecProblem,
    UnknownKindError,
)
from puzzlebox.models.kinds import ALLOWED_NEIGHBOURS, KIND_NAMES, PUZZLE_KINDS, KindTemplate, get_kind, kind_code
from puzzlebox.models.lock_table import LockTable
from puzzlebox.models.observation import ComponentObservation, SceneObservation
from puzzlebox.models.robot import CameraImage, Robot
from puzzlebox.models.spec import SPEC_FORMAT, Box, Component, Goal, LockRule, PuzzleSpec, save_spec
from puzzlebox.models.spec_loading import load_spec, spec_from_dict, spec_from_json
from puzzlebox.models.toggle_log import ToggleLog, load_toggles, save_toggles
from puzzlebox.models.try_outcome import OUTCOMES, Outcome, TryResult
from puzzlebox.models.validation import validate_data
from puzzlebox.models.world import World

__all__ = [
    "ALLOWED_NEIGHBOURS",
    "OUTCOMES",
    "CameraImage",
    "Outcome",
    "Robot",
    "TryResult",
    "KIND_NAMES",
    "PUZZLE_KINDS",
    "SPEC_FORMAT",
    "Box",
    "Component",
    "ComponentObservation",
    "GeneratorError",
    "Goal",
    "KindTemplate",
    "LockRule",
    "LockTable",
    "ModelsError",
    "PuzzleSpec",
    "ReachabilityUndecided",
    "SceneObservation",
    "SpecError",
    "SpecProblem",
    "ToggleLog",
    "UnknownKindError",
    "World",
    "get_kind",
    "kind_code",
    "load_spec",
    "load_toggles",
    "save_spec",
    "save_toggles",
    "spec_from_dict",
    "spec_from_json",
    "validate_data",
]
