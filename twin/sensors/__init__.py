"""The twin's sensor models: the wrist F/T sensor, the joint encoders (and the kinematics the arm
reports from them) and the cameras, each applying the reality profile's imperfections. The session
owns them; the robot interface only asks them."""

from puzzlebox.twin.sensors.cameras import Cameras, TrueLens
from puzzlebox.twin.sensors.encoders import JointEncoders
from puzzlebox.twin.sensors.force_torque import ForceTorqueSensor

__all__ = ["Cameras", "ForceTorqueSensor", "JointEncoders", "TrueLens"]
