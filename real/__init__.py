"""Drivers of a real cell behind the ``models.robot.Robot`` protocol (needs the ``real`` extra for the arm).

Importing this package imports no SDK: :class:`XArmRobot` imports ``xarm-python-sdk`` when it is constructed.
"""

from puzzlebox.real import errors
from puzzlebox.real.errors import *  # noqa: F403 - the typed errors, listed in real.errors.__all__
from puzzlebox.real.xarm_driver import XARM_CONTROL_PORT, XArmRobot, probe_controller

__all__ = []  # the typed errors first, in the forms type checkers read
__all__ += errors.__all__
__all__ += ["XARM_CONTROL_PORT", "XArmRobot", "probe_controller"]
