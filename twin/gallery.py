"""Standard views of a puzzle box: a top view, a three-quarter view, one close-up per component and a turntable.

The box is drawn alone, in the twin's scene without the robot: the same table, floor, key light, headlight and
materials as the twin (:func:`models.scene.build_scene`), with the box's visible lock features
(:attr:`models.scene.SceneConfig.lock_features`: visual-only meshes in geom group 2) and the components in their
closed state (every joint at 0). One camera, :data:`CAMERA`, is added to the world body; a :class:`View` is a
pose and field of view for it, and :meth:`Gallery.render` moves it there (``model.cam_pos``, ``cam_quat``,
``cam_fovy``) before drawing through :class:`twin.rendering.Renderer`.

Frames and units
----------------
Everything is in the world frame (the robot's base frame on the table top, z up) [m]; the lid frame is the
box's (origin at the lid centre on its top face, x along the length), ``Scene.T_world_lid``. Angles of a view
are given in the lid frame so that a view is the same whatever the box's pose on the table:

* ``azimuth`` [deg]: the heading the camera looks along, measured from the lid's +x about +z (MuJoCo's free
  camera convention: azimuth 45 looks along lid (+x, +y), from the (-x, -y) corner);
* ``elevation`` [deg]: how far above the horizon the camera stands as seen from its target (90: straight down).

Every view is framed from the spec, never from a picture: the points that must be seen (the shell's eight
corners from the box size ``spec.box.size``, each component's footprint ``footprint_in_lid(pose)`` on the lid
and at its handle's top) are fitted exactly into the camera's frustum with :data:`MARGIN` to spare (pixels are
square: ``tan(hfov / 2) = aspect tan(fovy / 2)``). The still views (:func:`frame_view`) take the closest camera
position that holds them, centred on them; the turntable (:func:`orbit_view`) circles the centre of their bounding
box at one distance, the largest any of its headings needs.

Who locks whom
--------------
Every part has a colour of its own (:data:`PART_RGB`, in spec order) and each lock feature is drawn in its
locker's colour (:func:`part_colours`; the features' own colours, dark red and black, said only what a feature
is). :meth:`Gallery.annotate` draws on a whole-box view what a reader checks against the spec: each part's outline
and a label in its colour (name, kind, marker id), the goal ringed, in the top view the lid frame's x and y axes,
and below the image a legend: the goal, then every lock rule in words ("door-0 (door) closed keeps slide-1 (slide)
closed"), each beside its locker's colour and the feature that shows it. ``write_annotated`` writes
``top-annotated.png`` and ``three-quarter-annotated.png`` (``render.py --views`` writes them beside the plain views).

Example::

    with Gallery(spec, RenderConfig(width=640, height=480)) as gallery:
        paths = gallery.write_views(out_dir)                       # top.png, three-quarter.png, component-*.png
        gallery.write_annotated(out_dir)                           # top-annotated.png, three-quarter-annotated.png
        gallery.write_turntable(out_dir / "turntable.mp4", frames=72, fps=24)
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import cv2
import imageio.v3 as iio
import mujoco
import numpy as np
from numpy.typing import ArrayLike

from puzzlebox.models.atomic import write_atomically
from puzzlebox.models.kinds import get_kind
from puzzlebox.models.puzzle_box import component_prefixes
from puzzlebox.models.scene import BOX, ROBOT, Scene, SceneConfig, build_scene
from puzzlebox.models.spec import LockRule, PuzzleSpec
from puzzlebox.twin.rendering import RenderConfig, Renderer, presentation_look
from puzzlebox.twin.video import VideoWriter

__all__ = [
    "CAMERA",
    "CLOSE_UP_ELEVATION",
    "FOVY",
    "MARGIN",
    "PART_RGB",
    "SKY_RGB",
    "THREE_QUARTER_AZIMUTH",
    "THREE_QUARTER_ELEVATION",
    "TURNTABLE_ELEVATION",
    "Gallery",
    "View",
    "build_gallery_model",
    "component_view_name",
    "frame_view",
    "orbit_view",
    "part_colours",
    "rule_text",
    "state_name",
]

CAMERA = "gallery"
"""Name of the camera every view moves (on the world body)."""
FOVY = 40.0
"""Vertical field of view of every view [deg]."""
MARGIN = 1.1
"""How much wider than the framed points the image is (1.1: 10 % to spare on the tightest side)."""
THREE_QUARTER_AZIMUTH = 45.0
"""Heading of the three-quarter view in the lid frame [deg]: it looks along lid (+x, +y)."""
THREE_QUARTER_ELEVATION = 35.0
"""Height of the three-quarter view above the horizon, seen from the box [deg]."""
CLOSE_UP_ELEVATION = 60.0
"""Height of a component close-up above the horizon, seen from the component [deg]: steep enough that the
neighbours behind it do not hide its marker, low enough to show its handle standing up."""
SKY_RGB = ((0.86, 0.89, 0.93), (0.55, 0.58, 0.62))
"""Colours [0-1] of the gallery's gradient skybox, above and below the horizon."""
TURNTABLE_ELEVATION = 30.0
"""Height of the turntable's circling camera above the horizon, seen from the box [deg]."""
PART_RGB = (
    (0.12, 0.47, 0.71), (0.85, 0.37, 0.01), (0.17, 0.63, 0.17), (0.84, 0.15, 0.16), (0.58, 0.40, 0.74),
    (0.55, 0.34, 0.29), (0.89, 0.47, 0.76), (0.74, 0.74, 0.13), (0.09, 0.75, 0.81), (0.35, 0.35, 0.35),
)  # fmt: skip
"""Colours [0-1] of the parts, in spec order (cycled): their labels' and their lock features' (matplotlib's
tab10, darkened where pale)."""
STATE_NAMES = ("closed", "open")
"""What a component's states 0 and 1 are called in words."""


def state_name(state: int) -> str:
    """``closed`` for state 0, ``open`` for 1 (``state <n>`` otherwise)."""
    return STATE_NAMES[state] if 0 <= state < len(STATE_NAMES) else f"state {state}"


def part_colours(spec: PuzzleSpec) -> dict[str, tuple[float, float, float]]:
    """Each part's colour [0-1] by spec name (:data:`PART_RGB` in spec order)."""
    return {c.name: PART_RGB[k % len(PART_RGB)] for k, c in enumerate(spec.components)}


def rule_text(spec: PuzzleSpec, rule: LockRule) -> str:
    """A lock rule in words: ``door-0 (door) closed keeps slide-1 (slide) closed``."""
    kinds = {c.name: c.kind for c in spec.components}
    return (
        f"{rule.locker} ({kinds.get(rule.locker, '?')}) {state_name(rule.locker_state)} keeps "
        f"{rule.locked} ({kinds.get(rule.locked, '?')}) {state_name(rule.locked_state)}"
    )


@dataclass(frozen=True)
class View:
    """One pose of :data:`CAMERA`: where it stands and where it looks, in the world frame."""

    name: str
    """File stem of the view's image (``top``, ``three-quarter``, ``component-<name>``...)."""
    position: tuple[float, float, float]
    """Camera centre in the world frame [m]."""
    quat: tuple[float, float, float, float]
    """Camera orientation in the world frame, ``(w, x, y, z)``, MuJoCo's camera convention: it looks along its
    -z axis, x right and y up in the image."""
    fovy: float
    """Vertical field of view [deg]."""
    target: tuple[float, float, float]
    """The point on the optical axis the view was framed on, world frame [m]."""


def _camera_axes(towards_camera: ArrayLike, up: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit right, image-up and back (target to camera) axes of a camera, world frame."""
    back = np.asarray(towards_camera, dtype=float)
    back = back / np.linalg.norm(back)
    right = np.cross(np.asarray(up, dtype=float), back)
    if np.linalg.norm(right) < 1e-9:
        raise ValueError(f"the up direction {up} is parallel to the line of sight {back}")
    right /= np.linalg.norm(right)
    return right, np.cross(back, right), back


def _view(name: str, position: np.ndarray, axes: tuple[np.ndarray, ...], fovy: float, target: np.ndarray) -> View:
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, np.column_stack(axes).ravel())
    w, x, y, z = quat.tolist()
    return View(name, tuple(np.asarray(position, float).tolist()), (w, x, y, z), fovy, tuple(target.tolist()))


def frame_view(
    name: str,
    towards_camera: np.ndarray,
    points: np.ndarray,
    aspect: float,
    up: ArrayLike = (0.0, 0.0, 1.0),
    fovy: float = FOVY,
    margin: float = MARGIN,
) -> View:
    """The closest view looking along ``-towards_camera`` that holds every one of ``points``, centred on them.

    With the camera's axes fixed, each frustum side is a half-space of camera positions; the closest position
    inside the four of them is found in closed form: for the horizontal pair, ``α - k γ >= max(a - k e)`` and
    ``α + k γ <= min(a + k e)`` (camera at ``α`` along right, ``γ`` along forward; each point at ``a`` along right,
    ``e`` along forward; ``k = tan(hfov / 2) / margin``) give ``γ <= (min(a + k e) - max(a - k e)) / 2k`` with ``α``
    midway; likewise vertically; the camera takes the smaller ``γ`` of the two pairs, so the points touch the
    margin on their tighter side and are centred on the other.

    Args:
        name: the view's name.
        towards_camera: ``(3,)`` direction from the scene to the camera, world frame (normalised here).
        points: ``(n, 3)`` points that must be in view, world frame [m].
        aspect: image width / height.
        up: a world direction that should point up in the image (any not parallel to ``towards_camera``).
        fovy: vertical field of view [deg].
        margin: image extent / extent of the points on the tightest side (>= 1).
    """
    right, image_up, back = _camera_axes(towards_camera, up)
    forward = -back
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    depth = points @ forward
    k_v = math.tan(math.radians(fovy) / 2) / margin
    k_h = aspect * k_v
    offsets, reaches = [], []
    for axis, k in ((right, k_h), (image_up, k_v)):
        across = points @ axis
        low, high = np.max(across - k * depth), np.min(across + k * depth)
        offsets.append((low + high) / 2)
        reaches.append((high - low) / (2 * k))
    along = min(*reaches, float(np.min(depth)) - 0.05)  # and every point at least 5 cm in front
    position = offsets[0] * right + offsets[1] * image_up + along * forward
    centre = points.mean(axis=0)
    target = position + float((centre - position) @ forward) * forward
    return _view(name, position, (right, image_up, back), fovy, target)


def orbit_view(
    name: str,
    target: np.ndarray,
    towards_camera: np.ndarray,
    points: np.ndarray,
    aspect: float,
    fovy: float = FOVY,
    margin: float = MARGIN,
) -> tuple[View, float]:
    """A view from direction ``towards_camera`` whose optical axis passes through ``target``, at the smallest
    distance [m] that holds every one of ``points`` (``|(p - t)·x| <= (D + (p - t)·f) k`` per image axis, see
    :func:`frame_view`). Returns the view and that distance."""
    right, image_up, back = _camera_axes(towards_camera, (0.0, 0.0, 1.0))
    relative = np.asarray(points, dtype=float).reshape(-1, 3) - target
    depth = relative @ -back
    k_v = math.tan(math.radians(fovy) / 2) / margin
    k_h = aspect * k_v
    needed = np.maximum(np.abs(relative @ right) / k_h, np.abs(relative @ image_up) / k_v) - depth
    distance = max(float(np.max(needed)), 0.05 + float(np.max(-depth)))
    return _view(name, target + distance * back, (right, image_up, back), fovy, np.asarray(target)), distance


def component_view_name(component: str) -> str:
    """File stem of a component's close-up: ``component-<name>`` with characters unsafe in a file name as '_'."""
    return "component-" + re.sub(r"[^A-Za-z0-9_.-]", "_", component)


def build_gallery_model(spec: PuzzleSpec, lock_features: bool = True) -> tuple[Scene, mujoco.MjModel]:
    """The twin's scene of a puzzle box without the robot, plus :data:`CAMERA`, compiled.

    Raises:
        models.scene.SceneError: for a spec without a box (a disassembly scene) or a box the twin cannot build.
    """
    scene = build_scene(spec, SceneConfig(lock_features=lock_features))
    mjspec = mujoco.MjSpec.from_string(scene.root.to_xml_string(), assets=scene.root.get_assets())
    # the robot and everything that refers to it (its actuators, sensors, tendon, equalities, contact excludes,
    # meshes and materials): it is not drawn, and its meshes were most of the compile time
    for group in ("actuators", "sensors", "tendons", "equalities", "excludes"):
        for element in list(getattr(mjspec, group)):
            if element.name.startswith(ROBOT):
                mjspec.delete(element)
    mjspec.delete(mjspec.body(ROBOT))
    for group in ("meshes", "materials", "textures"):
        for element in list(getattr(mjspec, group)):
            if element.name.startswith(ROBOT):
                mjspec.delete(element)
    mjspec.worldbody.add_camera(name=CAMERA, fovy=FOVY)
    # a pale sky: the twin's fixed cameras never see past the floor, the gallery's perspective views do (without
    # it, above the horizon is black); not a geom, so it changes no contact and no segmentation
    mjspec.add_texture(
        name="gallery_sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=SKY_RGB[0],
        rgb2=SKY_RGB[1],
        width=64,
        height=64,
    )
    return scene, mjspec.compile()


class Gallery:
    """Renders the standard views of one puzzle box (see the module docstring). Owns a renderer: close it with
    :meth:`close` or use the gallery as a context manager."""

    def __init__(self, spec: PuzzleSpec, config: RenderConfig = RenderConfig(), lock_features: bool = True) -> None:  # noqa: B008
        """Build the box's scene and a renderer for it.

        Raises:
            models.scene.SceneError: for a spec without a box.
            twin.errors.RenderingError: if no OpenGL context can be created.
        """
        self.spec = spec
        self.config = config
        self.scene, self.model = build_gallery_model(spec, lock_features=lock_features)
        presentation_look(self.model)  # the box alone, for people: no camera of the pipeline reads this model
        self.colours = part_colours(spec)
        """Each part's colour [0-1] by spec name: its label's and its lock features'."""
        self.features = self._colour_features()
        """Lock feature geom name -> (locker, locked) spec names."""
        self.data = mujoco.MjData(self.model)
        mujoco.mj_forward(self.model, self.data)
        self._camera = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, CAMERA)
        self._renderer = Renderer(self.model, config)

    def _colour_features(self) -> dict[str, tuple[str, str]]:
        """Draw each lock feature (``<locker>:lock:<locked>``) in its locker's colour; returns them by geom name."""
        prefixes = component_prefixes(self.spec)
        features = {}
        for locker in self.spec.components:
            for locked in self.spec.components:
                name = f"{BOX}{prefixes[locker.name]}:lock:{prefixes[locked.name]}"
                geom = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, name)
                if geom >= 0:
                    self.model.geom_rgba[geom, :3] = self.colours[locker.name]
                    features[name] = (locker.name, locked.name)
        return features

    # -- framing ---------------------------------------------------------------------------------------------

    @property
    def aspect(self) -> float:
        """Image width / height."""
        return self.config.width / self.config.height

    def _lid_to_world(self, points: ArrayLike) -> np.ndarray:
        T = self.scene.T_world_lid
        return np.asarray(points, dtype=float) @ T[:3, :3].T + T[:3, 3]

    def _lid_direction(self, azimuth: float, elevation: float) -> np.ndarray:
        """World direction from a target to a camera at ``azimuth``/``elevation`` (module docstring) [deg]."""
        az, el = math.radians(azimuth), math.radians(elevation)
        heading = np.array([-math.cos(el) * math.cos(az), -math.cos(el) * math.sin(az), math.sin(el)])
        return self.scene.T_world_lid[:3, :3] @ heading

    def component_points(self, component: str) -> np.ndarray:
        """``(n, 3)`` points a close-up of ``component`` frames, world frame [m]: its footprint's corners on the
        lid and at the height of its handle's top (``<c>:handle_site``, closed state)."""
        c = next(c for c in self.spec.components if c.name == component)
        footprint = get_kind(c.kind).footprint_in_lid(c.pose[:3])
        site = self.scene.names.components[component].handle_site
        top = self.data.site(site).xpos
        top_in_lid = np.linalg.solve(self.scene.T_world_lid, [*top, 1.0])[2]
        corners = [[x, y, z] for x, y in footprint for z in (0.0, top_in_lid)]
        return self._lid_to_world(corners)

    def box_points(self) -> np.ndarray:
        """``(n, 3)`` points every whole-box view frames, world frame [m]: the shell's eight corners (lid frame
        ``(±length/2, ±width/2, 0 or -height)``) and every component's :meth:`component_points`."""
        assert self.spec.box is not None  # build_scene refused a spec without one
        length, width, height = self.spec.box.size
        shell = [[sx * length / 2, sy * width / 2, z] for sx in (-1, 1) for sy in (-1, 1) for z in (0.0, -height)]
        parts = [self.component_points(c.name) for c in self.spec.components]
        return np.vstack([self._lid_to_world(shell), *parts])

    def top_view(self) -> View:
        """Straight down on the lid; image right = lid +x, image up = lid +y."""
        lid_z = self.scene.T_world_lid[:3, 2]
        lid_y = self.scene.T_world_lid[:3, 1]
        return frame_view("top", lid_z, self.box_points(), self.aspect, up=lid_y)

    def three_quarter_view(self) -> View:
        """From :data:`THREE_QUARTER_AZIMUTH` and :data:`THREE_QUARTER_ELEVATION`, the whole box in view."""
        direction = self._lid_direction(THREE_QUARTER_AZIMUTH, THREE_QUARTER_ELEVATION)
        return frame_view("three-quarter", direction, self.box_points(), self.aspect)

    def component_view(self, component: str) -> View:
        """A close-up of one component, above and beside it: from :data:`CLOSE_UP_ELEVATION`, on the side of the
        component away from the lid centre (so its neighbours stand behind it), framed on its footprint."""
        c = next(c for c in self.spec.components if c.name == component)
        centre = get_kind(c.kind).footprint_in_lid(c.pose[:3]).mean(axis=0)
        outward = centre if np.linalg.norm(centre) > 1e-3 else np.array([0.0, -1.0])
        azimuth = math.degrees(math.atan2(-outward[1], -outward[0]))  # looks back towards the lid centre
        direction = self._lid_direction(azimuth, CLOSE_UP_ELEVATION)
        return frame_view(component_view_name(component), direction, self.component_points(component), self.aspect)

    def views(self) -> list[View]:
        """The standard views: ``top``, ``three-quarter``, then one close-up per component in spec order."""
        return [
            self.top_view(),
            self.three_quarter_view(),
            *(self.component_view(c.name) for c in self.spec.components),
        ]

    def turntable_views(self, frames: int = 72) -> list[View]:
        """``frames`` views circling the box once at :data:`TURNTABLE_ELEVATION`, starting at the three-quarter
        view's heading, ``360 / frames`` deg apart, all at one distance (the largest any heading needs)."""
        if frames < 1:
            raise ValueError(f"a turntable needs at least one frame, got {frames}")
        points = self.box_points()
        target = (points.min(axis=0) + points.max(axis=0)) / 2
        headings = [THREE_QUARTER_AZIMUTH + 360.0 * k / frames for k in range(frames)]
        directions = [self._lid_direction(a, TURNTABLE_ELEVATION) for a in headings]
        distance = max(orbit_view("", target, d, points, self.aspect)[1] for d in directions)
        views = []
        for k, direction in enumerate(directions):
            axes = _camera_axes(direction, (0.0, 0.0, 1.0))
            views.append(_view(f"turntable-{k:03d}", target + distance * axes[2], axes, FOVY, target))
        return views

    # -- rendering -------------------------------------------------------------------------------------------

    def place(self, view: View) -> None:
        """Move :data:`CAMERA` to ``view`` (model and data: ``cam_xpos``/``cam_xmat`` are recomputed)."""
        self.model.cam_pos[self._camera] = view.position
        self.model.cam_quat[self._camera] = view.quat
        self.model.cam_fovy[self._camera] = view.fovy
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_camlight(self.model, self.data)

    def render(self, view: View) -> np.ndarray:
        """The image of one view: ``uint8`` RGB ``(height, width, 3)``."""
        self.place(view)
        return self._renderer.render(self.data, CAMERA)

    def write_views(self, out_dir: str | Path) -> list[Path]:
        """Write every standard view as ``out_dir/<view name>.png``; returns the paths in :meth:`views` order."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        paths = []
        for view in self.views():
            path = out / f"{view.name}.png"
            image = self.render(view)
            write_atomically(path, lambda tmp, image=image: iio.imwrite(tmp, image, extension=".png"))
            paths.append(path)
        return paths

    # -- annotations -----------------------------------------------------------------------------------------

    def project(self, view: View, points: ArrayLike) -> np.ndarray:
        """``(n, 2)`` pixel coordinates (OpenCV: x right, y down, centres at integers) of world ``points`` in
        ``view``'s image."""
        matrix = np.empty(9)
        mujoco.mju_quat2Mat(matrix, np.asarray(view.quat, dtype=float))
        local = (np.asarray(points, dtype=float).reshape(-1, 3) - view.position) @ matrix.reshape(3, 3)
        depth = np.maximum(-local[:, 2], 1e-9)  # MuJoCo's camera looks along its -z, y up
        w, h = self.config.width, self.config.height
        focal = 0.5 * h / math.tan(math.radians(view.fovy) / 2)
        return np.column_stack([(w - 1) / 2 + focal * local[:, 0] / depth, (h - 1) / 2 - focal * local[:, 1] / depth])

    def legend(self) -> list[tuple[str, tuple[float, float, float] | None]]:
        """The legend's lines (text, colour of the chip before it or None): the goal, then each lock rule in
        words with the feature that shows it (or that none does)."""
        from puzzlebox.models.lock_features import layout_lock_features  # trimesh only when asked

        spec = self.spec
        goal = spec.goal
        kind = next(c.kind for c in spec.components if c.name == goal.component)
        lines: list[tuple[str, tuple[float, float, float] | None]] = [
            (f"{spec.name}: goal {goal.component} ({kind}) {state_name(goal.state)}; a lock feature has its "
             "locker's colour", None),
        ]  # fmt: skip
        layout = layout_lock_features(spec)
        shown = {(f.locker, f.locked): f.kind for f in layout.features}
        for rule in spec.locks:
            feature = shown.get((rule.locker, rule.locked))
            where = f"  [{feature} on {rule.locker}]" if feature and self.features else "  [no visible feature]"
            lines.append((rule_text(spec, rule) + where, self.colours[rule.locker]))
        if not spec.locks:
            lines.append(("no lock rules: every part moves freely", None))
        return lines

    def annotate(self, view: View, image: np.ndarray) -> np.ndarray:
        """``image`` of ``view`` with what a reader checks against the spec (module docstring): each part's
        outline and label (name, kind, marker id) in its colour, the goal ringed, the lid frame's axes in the top
        view, and the legend in a strip below (the image grows by it)."""
        out = np.ascontiguousarray(image).copy()
        taken: list[tuple[int, int, int, int]] = []
        for c in self.spec.components:
            colour = tuple(int(255 * v) for v in self.colours[c.name])
            footprint = get_kind(c.kind).footprint_in_lid(c.pose[:3])
            outline = self.project(view, self._lid_to_world([[x, y, 0.0] for x, y in footprint]))
            polygon = [np.round(outline).astype(np.int32)]
            if c.name == self.spec.goal.component:  # the goal: a thick red rim around its own colour
                cv2.polylines(out, polygon, True, (220, 20, 20), 7, cv2.LINE_AA)
            cv2.polylines(out, polygon, True, colour, 2, cv2.LINE_AA)
            centre = self.project(view, self.data.site(self.scene.names.components[c.name].handle_site).xpos)[0]
            goal = "  GOAL" if c.name == self.spec.goal.component else ""
            _chip(out, f"{c.name} ({c.kind}) #{c.marker}{goal}", centre, colour, taken)
        if view.name == "top":
            origin, x_axis, y_axis = self.project(view, self._lid_to_world([[0, 0, 0], [0.05, 0, 0], [0, 0.05, 0]]))
            for end, name in ((x_axis, "x"), (y_axis, "y")):
                start, tip = (int(origin[0]), int(origin[1])), (int(end[0]), int(end[1]))
                cv2.arrowedLine(out, start, tip, (20, 20, 20), 2, cv2.LINE_AA, tipLength=0.2)
                cv2.putText(out, name, (tip[0] + 4, tip[1] + 4), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (20, 20, 20), 1,
                            cv2.LINE_AA)  # fmt: skip
        return np.concatenate([out, self._legend_strip(out.shape[1])], axis=0)

    def _legend_strip(self, width: int) -> np.ndarray:
        lines = self.legend()
        scale = 0.42 if width >= 560 else 0.34
        step = int(40 * scale) + 6
        strip = np.full((step * len(lines) + 8 + (step * len(lines) + 8) % 2, width, 3), 250, dtype=np.uint8)
        for k, (text, colour) in enumerate(lines):
            y = 6 + step * (k + 1) - 5
            x = 8
            if colour is not None:
                cv2.rectangle(strip, (x, y - step + 8), (x + 14, y + 1), tuple(int(255 * v) for v in colour), -1)
                x += 20
            cv2.putText(strip, text, (x, y), cv2.FONT_HERSHEY_SIMPLEX, scale, (30, 30, 30), 1, cv2.LINE_AA)
        return strip

    def write_annotated(self, out_dir: str | Path) -> list[Path]:
        """Write the top and three-quarter views annotated (:meth:`annotate`) as ``out_dir/top-annotated.png``
        and ``out_dir/three-quarter-annotated.png``."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        paths = []
        for view in (self.top_view(), self.three_quarter_view()):
            path = out / f"{view.name}-annotated.png"
            image = self.annotate(view, self.render(view))
            write_atomically(path, lambda tmp, image=image: iio.imwrite(tmp, image, extension=".png"))
            paths.append(path)
        return paths

    def write_turntable(self, path: str | Path, frames: int = 72, fps: float = 24.0) -> Path:
        """Write the turntable (:meth:`turntable_views`) as an H.264 MP4 at ``fps`` [frames/s], atomically
        (:class:`twin.video.VideoWriter`: width and height must be even)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with VideoWriter(path, fps=fps) as writer:
            for view in self.turntable_views(frames):
                writer.append(self.render(view))
        return path

    def close(self) -> None:
        """Free the renderer. Idempotent."""
        self._renderer.close()

    def __enter__(self) -> Gallery:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def _chip(image: np.ndarray, text: str, anchor: np.ndarray, colour: tuple[int, ...], taken: list) -> None:
    """A label on a chip of ``colour`` near ``anchor`` [px], with a leader line, clear of the rectangles in ``taken``
    (added to it): tried above-right of the anchor, then further up or down."""
    font, scale = cv2.FONT_HERSHEY_SIMPLEX, 0.42 if image.shape[1] >= 560 else 0.34
    (tw, th), _ = cv2.getTextSize(text, font, scale, 1)
    h, w = image.shape[:2]
    ax, ay = int(anchor[0]), int(anchor[1])
    x = int(np.clip(ax + 10, 2, max(w - tw - 8, 2)))
    for dy in (-18, -40, 16, 38, -62, 60, -84, 82):
        y = int(np.clip(ay + dy, th + 6, h - 6))
        box = (x - 4, y - th - 4, x + tw + 4, y + 4)
        if all(box[2] < t[0] or box[0] > t[2] or box[3] < t[1] or box[1] > t[3] for t in taken):
            break
    taken.append(box)
    dark = sum(colour) < 400
    cv2.line(image, (ax, ay), (box[0], (box[1] + box[3]) // 2), colour, 1, cv2.LINE_AA)
    cv2.rectangle(image, box[:2], box[2:], colour, -1)
    cv2.putText(image, text, (x, y), font, scale, (255, 255, 255) if dark else (20, 20, 20), 1, cv2.LINE_AA)
