"""The UFactory xArm-7 with its gripper and a wrist force/torque sensor, as an MJCF model.

Origin of the model: the meshes, kinematics and inertias come from the xArm-7 and gripper files that
the ``robosuite==1.5.2`` wheel ships (MIT license), themselves derived from MuJoCo Menagerie's
``ufactory_xarm7`` (BSD-3-Clause), derived from UFACTORY's public URDF. The set-up installs that wheel
with ``--no-deps``; it is never imported — only its files are read. Nothing of it is committed here.

Adapted in code, as DESIGN.md records:
- torque motors replaced by position servos with Menagerie's gains (joints 1-2: kp 1500 N·m/rad,
  kv 150, |tau| <= 50 N·m; 3-5: 1000, 100, 30; 6-7: 800, 80, 20) and Menagerie's joint damping
  and armature;
- gravity compensation on every arm body (the servos alone sag ~14 mm at the TCP);
- a ``flange`` body between link7 and the gripper carrying the wrist F/T site ``ft_site`` with
  ``wrist_force`` / ``wrist_torque`` sensors (they measure what the gripper subtree exchanges with
  the arm, expressed in the site frame);
- the gripper mounted on the flange at link7's origin (robosuite mounts it 2.7 cm inside link7), its
  ``<default group>`` attribute that MuJoCo rejects removed, its own sensors removed, and its finger
  joints limited to 0..0.85 rad as in Menagerie (robosuite's class nesting leaves them unlimited);
- a ``tcp`` site between the finger pads and a ``wrist_camera`` looking along the approach axis.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import mujoco
from dm_control import mjcf

from puzzlebox.models.errors import ModelsError

ROBOSUITE_VERSION = "1.5.2"
ARM_JOINTS = tuple(f"joint{i}" for i in range(1, 8))
_SERVO_CLASS = {1: 0, 2: 0, 3: 1, 4: 1, 5: 1, 6: 2, 7: 2}
# Menagerie ufactory_xarm7 servo classes: (kp [N·m/rad], kv [N·m·s/rad], force limit [N·m], damping)
_SERVO_GAINS = ((1500.0, 150.0, 50.0, 10.0), (1000.0, 100.0, 30.0, 5.0), (800.0, 80.0, 20.0, 2.0))
TCP_OFFSET = 0.172
"""TCP along the gripper's approach axis from the gripper base (between the finger pads) [m]."""
HOME_QPOS = (-1.5708, -0.247, 0.0, 0.909, 0.0, 1.156, 0.0)
"""The rest posture [rad]: Menagerie's home turned a quarter turn about the base, so the gripper
points down 40 cm to the robot's right, out of the overview camera's view of the workspace."""


class RobotAssetsMissing(ModelsError):
    """The xArm-7 files are not installed (the set-up installs robosuite==1.5.2 with --no-deps)."""


@dataclass(frozen=True)
class XArm7Config:
    """Options of the robot model."""

    gravity_compensation: bool = True
    """Compensate gravity on the arm bodies (as the real controller does); applied by
    :func:`compensate_gravity` when the scene is compiled."""
    wrist_camera_fovy: float = 70.0
    """Vertical field of view of the wrist camera [deg]."""


def robosuite_assets() -> tuple[Path, Path]:
    """Paths of the robot and gripper MJCF files in the installed robosuite wheel (not imported)."""
    try:
        dist = metadata.distribution("robosuite")
    except metadata.PackageNotFoundError:
        raise RobotAssetsMissing(
            f"the xArm-7 model files come from robosuite=={ROBOSUITE_VERSION}; install it with "
            f"'pip install --no-deps robosuite=={ROBOSUITE_VERSION}' (make install does)"
        ) from None
    robot = Path(str(dist.locate_file("robosuite/models/assets/robots/xarm7/robot.xml")))
    gripper = Path(str(dist.locate_file("robosuite/models/assets/grippers/xarm7_gripper.xml")))
    for path in (robot, gripper):
        if not path.is_file():
            raise RobotAssetsMissing(f"robosuite {dist.version} lacks {path}; need robosuite=={ROBOSUITE_VERSION}")
    return robot, gripper


def _element(root: mjcf.RootElement, namespace: str, identifier: str) -> mjcf.Element:
    """``root.find(namespace, identifier)``: an element the robosuite model files have."""
    element = root.find(namespace, identifier)
    assert element is not None, f"robosuite's {root.model} model has no {namespace} {identifier!r}"
    return element


def _load_gripper(path: Path) -> mjcf.RootElement:
    text = path.read_text()
    # MuJoCo rejects a `group` attribute on <default>; geoms carry their own group anyway.
    text = re.sub(r'(<default class="xarm7_hand")\s+group="\d+"', r"\1", text)
    gripper = mjcf.from_xml_string(text, model_dir=str(path.parent))
    for sensor in list(gripper.sensor.all_children()):
        sensor.remove()
    for name in ("ft_frame",):
        site = gripper.find("site", name)
        if site is not None:
            site.remove()
    eef = gripper.find("body", "eef")
    if eef is not None:
        eef.remove()
    # robosuite's driver/follower/spring_link defaults are siblings of the class that sets the
    # finger range, so its joints come out unlimited; Menagerie nests them: range 0..0.85 rad.
    for joint in gripper.find_all("joint"):
        joint.range = [0.0, 0.85]
        joint.limited = True
    _element(gripper, "actuator", "fingers_actuator").name = "fingers"
    # the left and right finger linkages never meet (12 mm or more apart at any opening; their pads do meet)
    for left in ("left_outer_knuckle", "left_inner_knuckle"):
        for right in ("right_outer_knuckle", "right_inner_knuckle"):
            gripper.contact.add("exclude", body1=left, body2=right)
    gripper.model = "gripper"  # its namescope: xarm7/gripper/...
    return gripper


def build_xarm7(config: XArm7Config | None = None) -> mjcf.RootElement:
    """The xArm-7 + gripper + wrist F/T model (see the module docstring); attach it to a scene."""
    config = config or XArm7Config()
    robot_xml, gripper_xml = robosuite_assets()
    robot = mjcf.from_path(str(robot_xml))
    robot.model = "xarm7"
    for actuator in list(robot.actuator.all_children()):
        actuator.remove()  # torque motors: replaced by position servos below
    _element(robot, "body", "right_hand").remove()  # robosuite's mount, 2.7 cm inside link7
    _element(robot, "site", "right_center").remove()
    camera = robot.find("camera", "robotview")
    if camera is not None:
        camera.remove()

    for i, joint_name in enumerate(ARM_JOINTS, start=1):
        kp, kv, force, damping = _SERVO_GAINS[_SERVO_CLASS[i]]
        joint = _element(robot, "joint", joint_name)
        joint.damping = damping
        joint.armature = 0.1
        joint.frictionloss = 1.0
        robot.actuator.add(
            "general",
            name=joint_name,
            joint=joint,
            biastype="affine",
            gainprm=[kp],
            biasprm=[0.0, -kp, -kv],
            forcerange=[-force, force],
            ctrlrange=joint.range,
        )

    # pairs whose bounding spheres overlap at every step but which no joint angle brings together (nearest over
    # the joint ranges: base-link1 0.2 mm, base-link2 28 mm; link2-link4 can meet, at -51 mm: kept), taken out
    # of the narrow phase with the pairs below: 6.4 -> 3.9 us of a 30 us step
    for body1, body2 in (("base", "link1"), ("base", "link2")):
        robot.contact.add("exclude", body1=body1, body2=body2)

    link7 = _element(robot, "body", "link7")
    flange = link7.add("body", name="flange")
    flange.add("site", name="ft_site", size=[0.005], rgba=[1, 0.5, 0, 1], group=4)
    robot.sensor.add("force", name="wrist_force", site="ft_site")
    robot.sensor.add("torque", name="wrist_torque", site="ft_site")

    gripper = _load_gripper(gripper_xml)
    base = _element(gripper, "body", "xarm_gripper_base_link")
    base.add("site", name="tcp", pos=[0, 0, TCP_OFFSET], size=[0.004], rgba=[0, 1, 0, 1], group=4)
    # the camera looks along its -z: turned 180 deg about x it looks along the approach axis (+z)
    base.add("camera", name="wrist_camera", pos=[0.075, 0.0, 0.04], quat=[0, 1, 0, 0], fovy=config.wrist_camera_fovy)
    # as Menagerie mounts the gripper on link7: at its origin, turned half a turn about z
    mount = flange.add("site", name="gripper_mount", quat=[0, 0, 0, 1], size=[0.002], group=4)
    mount.attach(gripper)
    # link6 is 50 mm or more from every finger link at any turn of joint 7 and any opening of the fingers
    for finger in ("left_outer_knuckle", "left_inner_knuckle", "right_outer_knuckle", "right_inner_knuckle"):
        robot.contact.add("exclude", body1=robot.find("body", "link6"), body2=gripper.find("body", finger))

    _name_unnamed(robot)
    return robot


def compensate_gravity(spec: mujoco.MjSpec, prefix: str) -> None:
    """Turn on gravity compensation for every body whose name starts with ``prefix`` (the robot's
    namescope once attached). Done on the compiled-side ``MjSpec`` because dm_control 1.0.50's MJCF
    schema does not know the ``gravcomp`` attribute."""
    for body in spec.bodies:
        if body.name.startswith(prefix):
            body.gravcomp = 1.0


def _name_unnamed(root: mjcf.RootElement) -> None:
    """Give every geom, site and body a name (a named model is one a user can query and debug)."""
    for kind in ("body", "geom", "site"):
        for k, element in enumerate(root.find_all(kind)):
            if not hasattr(element, "name"):  # attachment frames: named by what they attach
                continue
            if element.name is None:
                parent = getattr(element.parent, "name", None) or kind
                element.name = f"{parent}_{kind}{k}"
