"""puzzlebox twin: the simulated world — physics session, latches, sensors, cameras, rendering,
video — and the robot interface, the only door the robot's pipeline may use (DESIGN.md, "Layers").

The session, the robot interface and the sweep are imported on first use: they load dm_control,
which opens its GL backend at import, and a process that only renders or writes video should not
pay for that (nor fail there when EGL is unavailable: the renderer reports that itself).
"""

import importlib
import os
from typing import Any

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco/dm_control load: headless EGL by default

from twin.component_states import ComponentStates, HysteresisConfig  # noqa: E402
from twin.errors import (  # noqa: E402
    CommandError,
    RenderingError,
    SimulationDiverged,
    TwinError,
    UnknownCamera,
    VideoError,
)
from twin.rendering import RenderConfig, Renderer  # noqa: E402
from twin.video import VideoWriter  # noqa: E402

_LAZY = {
    "CameraImage": "twin.robot_interface",
    "RobotInterface": "twin.robot_interface",
    "TwinConfig": "twin.session",
    "TwinSession": "twin.session",
    "TwinState": "twin.session",
    "sweep_open": "twin.scripted_sweep",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'twin' has no attribute {name!r}")


__all__ = [
    "CameraImage",
    "CommandError",
    "ComponentStates",
    "HysteresisConfig",
    "RenderConfig",
    "Renderer",
    "RenderingError",
    "RobotInterface",
    "SimulationDiverged",
    "TwinConfig",
    "TwinError",
    "TwinSession",
    "TwinState",
    "UnknownCamera",
    "VideoError",
    "VideoWriter",
    "sweep_open",
]
