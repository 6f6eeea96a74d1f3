"""The whole scene: table, the xArm-7 with its wrist F/T sensor, the puzzle box of a spec, lights and
cameras — built with ``dm_control.mjcf`` and compiled (or exported) through MuJoCo's ``MjSpec``.

World frame = robot base frame: origin at the robot's base on the table top, z up. The box stands on
the table at ``spec.box.pose`` (or :data:`DEFAULT_BOX_POSE`); the ``overview`` camera looks straight
down on the workspace from above (image right = world +x, image up = world +y).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from dm_control import mjcf

from puzzlebox.models import reach
from puzzlebox.models.errors import ModelsError
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.puzzle_box import LockMode, build_puzzle_box, component_prefixes, lid_to_world, yaw_quat
from puzzlebox.models.spec import PuzzleSpec
from puzzlebox.models.xarm7 import ARM_JOINTS, HOME_QPOS, XArm7Config, build_xarm7, compensate_gravity

DEFAULT_BOX_POSE = (0.45, 0.0, 0.0)
"""Where the box stands when the spec leaves ``box.pose`` out: centred 45 cm in front of the robot [m, m, rad]."""
ROBOT = "xarm7/"
BOX = "box/"


class SceneError(ModelsError):
    """A spec the twin cannot build."""


class UnreachableBoxPose(SceneError):
    """A component handle lies outside the robot's workspace."""


@dataclass(frozen=True)
class SceneConfig:
    """How the scene is laid out."""

    timestep: float = 0.002
    """Physics step [s] (DESIGN.md: 2 ms runs the arm at ~100x real time)."""
    overview_height: float = 0.50
    """Height of the overview camera above the table [m]... plus the box height (it looks at the lid)."""
    overview_xy: tuple[float, float] = (0.45, 0.0)
    """Where the overview camera hangs above the table, in the robot base frame [m]."""
    overview_fovy: float = 55.0
    """Vertical field of view of the overview camera [deg]: ~0.52 m x 0.69 m of lid seen from 0.5 m."""
    min_reach: float = reach.MIN_REACH
    """Closest a handle may be to the robot's base axis, horizontally [m]."""
    max_reach: float = reach.MAX_REACH
    """Farthest a handle may be from the robot's base axis, horizontally [m] (top-down grasps)."""
    with_markers: bool = True
    """Texture every component with its ArUco marker."""
    lock_features: bool = False
    """Add the box's visible lock features as visual-only meshes (geom group 2, no contacts, no mass:
    :func:`models.puzzle_box.build_puzzle_box`). Off by default: the scene is then exactly the one built before
    lock features existed."""
    locks: LockMode = "contact"
    """How the box holds its lock rules: ``contact``, mechanisms that block by contact (rules they do not realize
    left to the latches, which the twin engages), or ``latch``, the rule-driven latches alone (the model built
    before mechanisms existed: an ablation). :func:`models.puzzle_box.build_puzzle_box`."""
    calibration_board: bool = False
    """Add the ChArUco calibration board as a mocap body, hidden in the table until a rig places it
    (``models.charuco.add_board_body``, ``twin.calibration_rig``)."""
    robot: XArm7Config = field(default_factory=XArm7Config)


@dataclass(frozen=True)
class ComponentNames:
    """MuJoCo names of one component's elements in the compiled scene."""

    body: str
    joint: str
    latch: str
    handle: str
    handle_site: str
    frame_site: str
    marker: str


@dataclass(frozen=True)
class SceneNames:
    """MuJoCo names of everything the twin addresses, so nothing downstream spells a name twice."""

    arm_joints: tuple[str, ...]
    arm_actuators: tuple[str, ...]
    gripper_actuator: str
    wrist_force: str
    wrist_torque: str
    ft_site: str
    tcp_site: str
    flange: str
    wrist_camera: str
    overview_camera: str
    components: dict[str, ComponentNames]


@dataclass
class Scene:
    """A built scene: the MJCF tree, the names, and where the box stands."""

    spec: PuzzleSpec
    root: mjcf.RootElement
    names: SceneNames
    box_pose: tuple[float, float, float]
    T_world_lid: np.ndarray
    config: SceneConfig

    def to_mjspec(self) -> mujoco.MjSpec:
        """The scene as a MuJoCo ``MjSpec`` with what dm_control's schema cannot say (gravity
        compensation of the robot) applied."""
        spec = mujoco.MjSpec.from_string(self.root.to_xml_string(), assets=self.root.get_assets())
        if self.config.robot.gravity_compensation:
            compensate_gravity(spec, ROBOT)
        return spec

    def _add_home_keyframe(self, spec: mujoco.MjSpec) -> None:
        """Add the ``home`` keyframe to ``spec`` (the twin's reset, :meth:`twin.session.TwinSession.reset`): at
        ``qpos0`` the arm's joints are all zero, its fingers 40 mm inside the world's geometry, and it falls onto the
        lid in the first second of a plain simulation."""
        model = spec.compile()
        qpos, ctrl = model.qpos0.copy(), np.zeros(model.nu)
        for joint, angle in zip(self.names.arm_joints, HOME_QPOS, strict=True):
            qpos[model.joint(joint).qposadr[0]] = angle
        for actuator, angle in zip(self.names.arm_actuators, HOME_QPOS, strict=True):
            ctrl[model.actuator(actuator).id] = angle  # (position servos: the arm holds its posture)
        spec.add_key(name="home", qpos=qpos.tolist(), ctrl=ctrl.tolist())

    def compile(self) -> mujoco.MjModel:
        return self.to_mjspec().compile()

    def export(self, out_dir: str | Path) -> Path:
        """Write ``out_dir/scene.xml`` and its assets (meshes, marker textures): loadable by plain
        ``mujoco.MjModel.from_xml_path``, with a ``home`` keyframe (``mujoco.mj_resetDataKeyframe(model, data, 0)``,
        or the viewer's "Load key"): the arm at its rest posture holding it, the gripper open, every part closed."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        spec = self.to_mjspec()
        self._add_home_keyframe(spec)
        for filename, contents in self.root.get_assets().items():
            (out / filename).write_bytes(contents)
        path = out / "scene.xml"
        path.write_text(spec.to_xml())
        return path


def build_scene(spec: PuzzleSpec, config: SceneConfig | None = None) -> Scene:
    """Table + robot + box + lights + cameras for a puzzle-box spec; raises :class:`SceneError`."""
    config = config or SceneConfig()
    if spec.box is None:
        raise SceneError(f"spec {spec.name!r} has no box; the twin builds puzzle boxes (door/slide/wheel)")
    for c in spec.components:
        get_kind(c.kind)  # UnknownKindError lists the kinds the twin can build
    box_pose = spec.box.pose if spec.box.pose is not None else DEFAULT_BOX_POSE
    height = spec.box.size[2]
    T_world_lid = lid_to_world(box_pose, height)
    _check_reach(spec, T_world_lid, config)

    root = mjcf.RootElement(model="puzzlebox")
    root.compiler.angle = "radian"
    root.option.timestep = config.timestep
    root.option.integrator = "implicitfast"
    root.option.cone = "elliptic"  # DESIGN.md grasping: elliptic cones + impratio 10 hold the handles
    root.option.impratio = 10
    root.option.flag.autoreset = "disable"  # divergence must raise, never silently reset
    root.visual.headlight.ambient = [0.25, 0.25, 0.25]
    root.visual.headlight.diffuse = [0.3, 0.3, 0.3]
    getattr(root.visual, "global").offwidth = 1280
    getattr(root.visual, "global").offheight = 960

    world = root.worldbody
    world.add(
        "light",
        name="key_light",
        pos=[0.4, -0.3, 1.6],
        dir=[-0.1, 0.2, -1],
        directional=True,
        castshadow=True,
        diffuse=[0.55, 0.55, 0.55],
    )
    # the floor is seen, never touched (0.75 m under the table top): out of collision, where a plane is tested
    # against every moving geom at every step (a third of the narrow phase)
    world.add(
        "geom", name="floor", type="plane", size=[2, 2, 0.05], pos=[0, 0, -0.75], rgba=[0.5, 0.5, 0.52, 1],
        contype=0, conaffinity=0,
    )  # fmt: skip
    world.add("geom", name="table", type="box", size=[0.6, 0.7, 0.375], pos=[0.35, 0, -0.375], rgba=[0.9, 0.9, 0.88, 1])
    cx, cy = config.overview_xy
    world.add(
        "camera",
        name="overview",
        pos=[cx, cy, height + config.overview_height],
        quat=[1, 0, 0, 0],  # looks down -z; image right = +x, image up = +y
        fovy=config.overview_fovy,
    )

    robot = build_xarm7(config.robot)
    world.add("site", name="robot_mount", pos=[0, 0, 0], size=[0.001], group=4).attach(robot)
    box_model = build_puzzle_box(
        spec, with_markers=config.with_markers, lock_features=config.lock_features, locks=config.locks
    )
    x, y, yaw = box_pose
    world.add("site", name="box_mount", pos=[x, y, height], quat=yaw_quat(yaw), size=[0.001], group=4).attach(box_model)
    if config.calibration_board:
        from puzzlebox.models.charuco import add_board_body

        add_board_body(world)
    return Scene(spec, root, _names(spec), (x, y, yaw), T_world_lid, config)


def _names(spec: PuzzleSpec) -> SceneNames:
    prefixes = component_prefixes(spec)
    components = {
        c.name: ComponentNames(
            body=f"{BOX}{p}",
            joint=f"{BOX}{p}:joint",
            latch=f"{BOX}{p}:latch",
            handle=f"{BOX}{p}:handle",
            handle_site=f"{BOX}{p}:handle_site",
            frame_site=f"{BOX}{p}:frame",
            marker=f"{BOX}{p}:marker",
        )
        for c, p in ((c, prefixes[c.name]) for c in spec.components)
    }
    return SceneNames(
        arm_joints=tuple(f"{ROBOT}{j}" for j in ARM_JOINTS),
        arm_actuators=tuple(f"{ROBOT}{j}" for j in ARM_JOINTS),
        gripper_actuator=f"{ROBOT}gripper/fingers",
        wrist_force=f"{ROBOT}wrist_force",
        wrist_torque=f"{ROBOT}wrist_torque",
        ft_site=f"{ROBOT}ft_site",
        tcp_site=f"{ROBOT}gripper/tcp",
        flange=f"{ROBOT}flange",
        wrist_camera=f"{ROBOT}gripper/wrist_camera",
        overview_camera="overview",
        components=components,
    )


def unreachable_handles(spec: PuzzleSpec, box_pose: tuple[float, float, float], config: SceneConfig) -> list[str]:
    """The components whose handle would lie outside the robot's reach with the box at ``box_pose``
    ``[x, y, yaw]`` [m, m, rad] (empty: the pose is reachable)."""
    return reach.unreachable_handles(spec, box_pose, config.min_reach, config.max_reach)


def _check_reach(spec: PuzzleSpec, T_world_lid: np.ndarray, config: SceneConfig) -> None:
    yaw = math.atan2(T_world_lid[1, 0], T_world_lid[0, 0])
    problems = unreachable_handles(spec, (T_world_lid[0, 3], T_world_lid[1, 3], yaw), config)
    if problems:
        assert spec.box is not None  # build_scene refused a spec without one
        raise UnreachableBoxPose(
            f"box pose {spec.box.pose} puts handles outside the robot's reach "
            f"({config.min_reach:.2f}..{config.max_reach:.2f} m from the base axis): {', '.join(problems)}"
        )
