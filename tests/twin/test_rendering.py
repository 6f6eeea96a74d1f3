"""Headless rendering (both OpenGL backends, camera models) and MP4 writing of rendered frames."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

# The project's rendering default, before anything imports dm_control or mujoco (an explicit MUJOCO_GL,
# e.g. osmesa, wins). Unset, dm_control would pick GLFW and warn that there is no display.
os.environ.setdefault("MUJOCO_GL", "egl")

import imageio_ffmpeg  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from puzzlebox.twin.errors import RenderingError, TwinError, UnknownCamera, VideoError  # noqa: E402
from puzzlebox.twin.rendering import RenderConfig, Renderer, gl_backend  # noqa: E402
from puzzlebox.twin.video import VideoWriter  # noqa: E402

REPO = Path(__file__).resolve().parents[2]

DISCS = [(0.0, 0.0), (0.09, 0.05), (-0.12, 0.07), (0.05, -0.1), (-0.07, -0.06)]
"""Centres of the small emissive discs on the floor, (x, y) in the world [m]."""
DISC_RADIUS = 0.005
"""Radius of the emissive discs [m]. Discs, not squares: a square's edges along the pixel grid all fall at the
same sub-pixel offset, and the rendered blob's centroid then moves with the anti-aliasing pattern."""
DISC_TOP = 0.0002
"""Height of the emissive discs' top faces above the floor [m]."""

DISCS_XML = "".join(
    f'<geom name="disc{i}" type="cylinder" size="{DISC_RADIUS} {DISC_TOP / 2}" pos="{x} {y} {DISC_TOP / 2}" '
    'material="glow"/>'
    for i, (x, y) in enumerate(DISCS)
)

SCENE_XML = f"""
<mujoco model="render_test">
  <visual><headlight ambient="0 0 0" diffuse="0 0 0" specular="0 0 0"/></visual>
  <asset>
    <!-- Dim enough that lit and emitted light stay below 1: clipped pixels would skew blob centroids. -->
    <material name="glow" rgba="0.4 0.4 0.4 1" emission="1" specular="0"/>
  </asset>
  <worldbody>
    <light name="sun" pos="0.4 -0.3 1.2" dir="-0.4 0.3 -1" directional="true" castshadow="true"
           diffuse="0.8 0.8 0.8" ambient="0.2 0.2 0.2"/>
    <geom name="floor" type="plane" size="1 1 0.05" rgba="0.05 0.05 0.05 1"/>
    <geom name="block" type="box" size="0.04 0.04 0.04" pos="0.2 0.15 0.04" rgba="0.9 0.1 0.1 1"/>
    {DISCS_XML}
    <camera name="down" pos="0 0 0.5" fovy="45"/>
    <camera name="oblique" pos="0.05 -0.45 0.38" xyaxes="0.995 0.1 0 -0.06 0.6 0.8" fovy="55"/>
    <camera name="sensor" pos="-0.02 0.01 0.45" sensorsize="0.0064 0.0048" focal="0.005 0.0052"
            principal="0.0003 -0.0002" resolution="640 480"/>
    <camera name="flat" pos="0 0 0.5" projection="orthographic" fovy="0.4"/>
  </worldbody>
</mujoco>
"""


@pytest.fixture(scope="module")
def scene() -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The test scene: a dark floor with emissive discs, a red block, one light, four cameras."""
    model = mujoco.MjModel.from_xml_string(SCENE_XML)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


def run_python(code: str, **env: str) -> subprocess.CompletedProcess[str]:
    """Run ``code`` in a fresh interpreter from the repository root, with ``env`` added to the environment."""
    environment = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "PYOPENGL_PLATFORM")}
    environment.update(env)
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        cwd=REPO,
        env=environment,
        capture_output=True,
        text=True,
        timeout=120,
    )


TINY_SCENE = """
    import mujoco, numpy as np
    from puzzlebox.twin.rendering import Renderer, RenderConfig
    model = mujoco.MjModel.from_xml_string('''<mujoco><worldbody>
        <light pos="0 0 2"/><geom type="plane" size="1 1 .1" rgba=".1 .6 .1 1"/>
        <geom type="box" size=".05 .05 .05" pos="0 0 .05" rgba="1 0 0 1"/><camera name="top" pos="0 0 .6"/>
        </worldbody></mujoco>''')
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
"""


@pytest.mark.parametrize("backend", ["egl", "osmesa"])
def test_each_backend_renders_the_scene_and_exits_silently(backend):
    result = run_python(
        TINY_SCENE
        + """
    with Renderer(model, RenderConfig(width=160, height=120)) as renderer:
        image = renderer.render(data, "top")
        print(renderer.backend, *image[60, 80], *image[5, 5])
    """,
        MUJOCO_GL=backend,
    )
    assert result.returncode == 0, result.stderr
    name, *pixels = result.stdout.split()
    centre, corner = np.array(pixels[:3], int), np.array(pixels[3:], int)
    assert name == backend
    assert centre[0] > 150 and centre[0] > 2 * centre[1]  # the red box in the middle
    assert corner[1] > corner[0] and corner[1] > corner[2]  # the green floor around it
    assert result.stderr == ""


def test_renderer_left_open_at_exit_prints_no_traceback():
    # mujoco.Renderer left open prints EGLError tracebacks from __del__ at interpreter exit.
    result = run_python(
        TINY_SCENE
        + """
    renderer = Renderer(model)
    renderer.render(data, "top")
    forgotten = [Renderer(model), Renderer(model, RenderConfig(width=64, height=48))]
    print("done")
    """,
        MUJOCO_GL="egl",
    )
    assert result.returncode == 0 and result.stdout.strip() == "done"
    assert result.stderr == ""


def test_egl_failure_raises_rendering_error_that_points_to_osmesa():
    result = run_python(
        TINY_SCENE
        + """
    from puzzlebox.twin.errors import RenderingError
    try:
        Renderer(model)
    except RenderingError as error:
        print(error)
    """,
        MUJOCO_GL="egl",
        MUJOCO_EGL_DEVICE_ID="99",  # no such device: mujoco.egl cannot open a display
    )
    assert result.returncode == 0, result.stderr
    assert "MUJOCO_GL=osmesa" in result.stdout


def test_backend_follows_mujoco_gl_and_defaults_to_egl(monkeypatch):
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    assert gl_backend() == "osmesa"
    monkeypatch.delenv("MUJOCO_GL")
    monkeypatch.delenv("PYOPENGL_PLATFORM", raising=False)
    assert gl_backend() == "egl"
    monkeypatch.setenv("MUJOCO_GL", "off")
    with pytest.raises(RenderingError, match="disabled"):
        gl_backend()
    monkeypatch.setenv("MUJOCO_GL", "vulkan")
    with pytest.raises(RenderingError, match="egl"):
        gl_backend()


@pytest.fixture(scope="module")
def renderer(scene):
    model, _ = scene
    with Renderer(model, RenderConfig(width=640, height=480)) as renderer:
        yield renderer


def test_render_returns_an_rgb_image_of_the_configured_size_with_the_scene_in_it(renderer, scene):
    _, data = scene
    image = renderer.render(data, "down")
    assert image.shape == (480, 640, 3) and image.dtype == np.uint8
    # The down camera sees the emissive disc under it at the image centre, bright on the dark floor.
    assert image[239:241, 319:321].min() > 150
    assert image[5:40, 5:40].max() < 80
    # The red block at +x, +y of the world appears right and up: right of and above the centre.
    block = image[:, :, 0].astype(int) - image[:, :, 1]
    rows, cols = np.nonzero(block > 100)
    assert rows.size > 100 and rows.mean() < 240 and cols.mean() > 320


def test_rendering_the_same_state_twice_gives_the_same_image(renderer, scene):
    _, data = scene
    np.testing.assert_array_equal(renderer.render(data, "oblique"), renderer.render(data, "oblique"))


def disc_centres(model, data) -> np.ndarray:
    """Centres of the top faces of the scene's emissive discs in the world [m], shape (n, 3)."""
    ids = [i for i in range(model.ngeom) if (model.geom(i).name or "").startswith("disc")]
    assert len(ids) >= 4
    return np.array([data.geom_xpos[i] + data.geom_xmat[i].reshape(3, 3) @ [0, 0, model.geom_size[i, 1]] for i in ids])


def projected_disc_centres(renderer, data, camera):
    """Where the camera model says the discs' centres appear [px], from the OpenCV intrinsics and pose."""
    K = renderer.camera_intrinsics(camera)
    T_camera_world = np.linalg.inv(renderer.camera_pose_in_world(data, camera))
    centres = disc_centres(renderer.model, data)
    points = np.hstack([centres, np.ones((len(centres), 1))]) @ T_camera_world.T
    assert (points[:, 2] > 0).all()  # in front of the camera: z forward
    return points[:, :2] / points[:, 2:3] @ K[:2, :2].T + K[:2, 2]


def brightness_centroid(image, near, radius=12):
    """Intensity-weighted centroid of the bright blob near a pixel position [px], background removed."""
    col, row = np.round(near).astype(int)
    window = image[row - radius : row + radius + 1, col - radius : col + radius + 1].astype(float).mean(axis=2)
    weights = window - np.median(window)
    weights[weights < 10] = 0  # the lit floor's gradient would pull the centroid uphill
    rows, cols = np.mgrid[-radius : radius + 1, -radius : radius + 1]
    return np.array([col + (weights * cols).sum() / weights.sum(), row + (weights * rows).sum() / weights.sum()])


@pytest.mark.parametrize("camera", ["down", "oblique", "sensor"])
def test_intrinsics_and_pose_project_points_onto_their_rendered_pixels(renderer, scene, camera):
    _, data = scene
    image = renderer.render(data, camera)
    for predicted in projected_disc_centres(renderer, data, camera):
        measured = brightness_centroid(image, predicted)
        # A (W/2, H/2) principal point would be half a pixel off; a wrong frame, many pixels.
        assert np.linalg.norm(measured - predicted) < 0.2, (camera, measured, predicted)


def test_intrinsics_of_a_fovy_camera_are_square_pixels_centred_on_the_image(renderer):
    K = renderer.camera_intrinsics("down")
    assert K[0, 0] == pytest.approx(240 / np.tan(np.radians(45 / 2)))
    assert K[0, 0] == K[1, 1]
    assert (K[0, 2], K[1, 2]) == (319.5, 239.5)


def test_camera_pose_is_opencv_frame_looking_along_z(renderer, scene):
    _, data = scene
    T_world_camera = renderer.camera_pose_in_world(data, "down")
    np.testing.assert_allclose(T_world_camera[:3, 3], [0, 0, 0.5])
    # Looking down: z forward is world -z; image right is world +x; image down is world -y.
    np.testing.assert_allclose(T_world_camera[:3, :3], np.diag([1.0, -1.0, -1.0]), atol=1e-12)


def test_orthographic_camera_has_no_pinhole_intrinsics(renderer):
    with pytest.raises(RenderingError, match="orthographic"):
        renderer.camera_intrinsics("flat")


def test_unknown_camera_names_the_cameras_that_exist(renderer, scene):
    _, data = scene
    with pytest.raises(UnknownCamera, match=r"Available camera names: \['down', 'flat', 'oblique', 'sensor'\]"):
        renderer.render(data, "overview")
    with pytest.raises(KeyError):
        renderer.camera_intrinsics("overview")
    with pytest.raises(TwinError):
        renderer.camera_pose_in_world(data, "overview")


def test_shadows_darken_the_floor_only_when_enabled(scene):
    model, data = scene
    images = {}
    for shadows in (False, True):
        with Renderer(model, RenderConfig(width=320, height=240, shadows=shadows)) as renderer:
            images[shadows] = renderer.render(data, "oblique").astype(float)
    darker = images[False].mean(axis=2) - images[True].mean(axis=2)
    # The block's shadow darkens a patch of lit floor; nothing gets brighter.
    assert (darker > 10).sum() > 200
    assert (darker < -10).sum() == 0


def test_images_larger_than_the_model_offscreen_buffer_are_rendered_whole(scene):
    model, data = scene
    with Renderer(model, RenderConfig(width=1024, height=768)) as renderer:
        image = renderer.render(data, "down")
    assert image.shape == (768, 1024, 3)
    assert image[383:385, 511:513].min() > 150  # the centre disc, where the camera model puts it


def test_closed_renderer_refuses_to_render_and_closing_twice_is_harmless(scene):
    model, data = scene
    renderer = Renderer(model, RenderConfig(width=64, height=48))
    with renderer:
        renderer.render(data, "down")
    assert renderer.closed
    renderer.close()
    with pytest.raises(RenderingError, match="closed"):
        renderer.render(data, "down")


def test_render_config_rejects_empty_images():
    with pytest.raises(ValueError, match="positive"):
        RenderConfig(width=0)


# Video: rendered frames written to MP4.


def read_video(path: Path) -> tuple[dict, list[np.ndarray]]:
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader]
    return meta, frames


def gray_frames(n: int, height: int = 48, width: int = 64) -> list[np.ndarray]:
    return [np.full((height, width, 3), 20 + 20 * i, np.uint8) for i in range(n)]


def test_video_reads_back_with_every_frame_at_its_size_and_brightness(tmp_path):
    path = tmp_path / "rollout.mp4"
    with VideoWriter(path, fps=25) as video:
        for frame in gray_frames(10):
            video.append(frame)
        assert not path.exists()  # published only on close
    meta, frames = read_video(path)
    assert len(frames) == 10
    assert all(f.shape == (48, 64, 3) for f in frames)
    assert meta["codec"].startswith("h264") and meta["fps"] == pytest.approx(25)
    np.testing.assert_allclose([f.mean() for f in frames], [20 + 20 * i for i in range(10)], atol=3)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rollout.mp4"]  # no temporary left


def test_video_of_rendered_frames_keeps_the_image_content(tmp_path, renderer, scene):
    _, data = scene
    frame = renderer.render(data, "down")
    with VideoWriter(tmp_path / "render.mp4") as video:
        video.append(frame)
        video.append(frame)
    _, frames = read_video(tmp_path / "render.mp4")
    assert len(frames) == 2 and frames[0].shape == frame.shape
    assert np.abs(frames[1].astype(int) - frame).mean() < 3


def test_error_inside_the_writer_leaves_no_file_behind(tmp_path):
    path = tmp_path / "crashed.mp4"
    with pytest.raises(RuntimeError, match="simulated crash"), VideoWriter(path) as video:
        video.append(gray_frames(1)[0])
        raise RuntimeError("simulated crash")
    assert list(tmp_path.iterdir()) == []


def test_frame_of_another_size_is_rejected_and_the_video_goes_on(tmp_path):
    path = tmp_path / "mixed.mp4"
    with VideoWriter(path) as video:
        video.append(gray_frames(1)[0])
        with pytest.raises(VideoError, match=r"shape \(480, 640, 3\).*\(48, 64, 3\)"):
            video.append(np.zeros((480, 640, 3), np.uint8))
        video.append(gray_frames(2)[1])
    assert len(read_video(path)[1]) == 2


@pytest.mark.parametrize(
    ("frame", "message"),
    [
        (np.zeros((47, 64, 3), np.uint8), "even"),
        (np.zeros((48, 64), np.uint8), "RGB"),
        (np.zeros((48, 64, 3), np.float32), "uint8"),
    ],
)
def test_frames_a_playable_mp4_cannot_hold_are_rejected(tmp_path, frame, message):
    video = VideoWriter(tmp_path / "bad.mp4")
    with pytest.raises(VideoError, match=message):
        video.append(frame)
    video.abort()
    assert list(tmp_path.iterdir()) == []


def test_closing_a_video_without_frames_says_nothing_was_written(tmp_path):
    with pytest.raises(VideoError, match="no frames"):
        VideoWriter(tmp_path / "empty.mp4").close()
    assert list(tmp_path.iterdir()) == []
