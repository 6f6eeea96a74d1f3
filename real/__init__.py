"""Drivers of a real cell behind the ``models.robot.Robot`` protocol (needs the ``real`` extra for the arm).

Importing this package imports no SDK: :class:`XArmRobot` imports ``xarm-python-sdk`` when it is constructed.
"""

from real.errors import (
    ArmUnreachable,
    CommandRefused,
    ForceLimitExceeded,
    RealError,
    SDKCallFailed,
    SDKMissing,
    UnknownCamera,
)
from real.xarm_driver import XARM_CONTROL_PORT, XArmRobot, probe_controller

__all__ = [
    "XARM_CONTROL_PORT",
    "ArmUnreachable",
    "CommandRefused",
    "ForceLimitExceeded",
    "RealError",
    "SDKCallFailed",
    "SDKMissing",
    "UnknownCamera",
    "XArmRobot",
    "probe_controller",
]
