"""puzzlebox twin: the simulated world — physics session, latches, sensors, cameras, rendering,
video — and the robot interface, the only door the robot's pipeline may use (DESIGN.md, "Layers").

Reality profiles (:mod:`twin.reality`) make the simulated cell a realistic one: sensor noise, camera
and TCP errors, physics draws, jams, placement; applied inside the session, invisible to the robot.

The session, the robot interface, the profiles and the sweep are imported on first use: they load dm_control,
which opens its GL backend at import, and a process that only renders or writes video should not
pay for that (nor fail there when EGL is unavailable: the renderer reports that itself).
"""

import importlib
import os
from typing import TYPE_CHECKING, Any

os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco/dm_control load: headless EGL by default

from puzzlebox.twin.component_states import ComponentStates, HysteresisConfig  # noqa: E402
from puzzlebox.twin.errors import (  # noqa: E402
    CommandError,
    ProfileError,
    RenderingError,
    SimulationDiverged,
    TwinError,
    UnknownCamera,
    VideoError,
)
from puzzlebox.twin.rendering import RenderConfig, Renderer  # noqa: E402
from puzzlebox.twin.video import VideoWriter  # noqa: E402

if TYPE_CHECKING:  # the lazy names below, for type checkers
    from puzzlebox.twin.reality import PRESETS, RealityProfile, load_profile
    from puzzlebox.twin.robot_interface import RobotInterface
    from puzzlebox.twin.scripted_sweep import sweep_open
    from puzzlebox.twin.session import TwinConfig, TwinSession, TwinState
    from puzzlebox.twin.system_id import FitConfig, fit_kind
    from puzzlebox.twin.toggle_replay import KindScales, ToggleReplay
    from puzzlebox.twin.toggle_scoring import prepare, toggle_errors

_LAZY = {
    "PRESETS": "puzzlebox.twin.reality",
    "RealityProfile": "puzzlebox.twin.reality",
    "load_profile": "puzzlebox.twin.reality",
    "RobotInterface": "puzzlebox.twin.robot_interface",
    "TwinConfig": "puzzlebox.twin.session",
    "TwinSession": "puzzlebox.twin.session",
    "TwinState": "puzzlebox.twin.session",
    "sweep_open": "puzzlebox.twin.scripted_sweep",
    "KindScales": "puzzlebox.twin.toggle_replay",
    "ToggleReplay": "puzzlebox.twin.toggle_replay",
    "FitConfig": "puzzlebox.twin.system_id",
    "fit_kind": "puzzlebox.twin.system_id",
    "prepare": "puzzlebox.twin.toggle_scoring",
    "toggle_errors": "puzzlebox.twin.toggle_scoring",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'twin' has no attribute {name!r}")


__all__ = [
    "CommandError",
    "ComponentStates",
    "FitConfig",
    "HysteresisConfig",
    "KindScales",
    "PRESETS",
    "ProfileError",
    "RealityProfile",
    "RenderConfig",
    "Renderer",
    "RenderingError",
    "RobotInterface",
    "SimulationDiverged",
    "TwinConfig",
    "TwinError",
    "TwinSession",
    "ToggleReplay",
    "TwinState",
    "UnknownCamera",
    "VideoError",
    "VideoWriter",
    "fit_kind",
    "load_profile",
    "prepare",
    "sweep_open",
    "toggle_errors",
]
