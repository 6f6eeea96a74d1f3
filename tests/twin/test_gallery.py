"""puzzlebox.twin.gallery: standard views of a box, checked on what they show (segmentation: geom id per pixel)."""

from __future__ import annotations

import difflib
import math

import imageio.v3 as iio
import mujoco
import numpy as np
import pytest
from conftest import SCENE_EXAMPLE

from puzzlebox.models import spec_from_dict
from puzzlebox.models.generator import generate_chain, paper_family
from puzzlebox.models.scene import SceneConfig, SceneError, build_scene
from puzzlebox.twin.gallery import CAMERA, Gallery, component_view_name, frame_view, rule_text
from puzzlebox.twin.rendering import RenderConfig

WIDTH, HEIGHT = 400, 300
FIVE_KINDS = ["lever", "slide", "door", "drawer", "wheel"]


def _specs():
    return {"chain": generate_chain(FIVE_KINDS, seed=0), "paper": paper_family("test")[1]}


SPECS = _specs()


class Segmenter:
    """What each pixel of a gallery view shows: the share of the image each named geom covers."""

    def __init__(self, gallery: Gallery) -> None:
        self.gallery = gallery
        self.renderer = mujoco.Renderer(gallery.model, HEIGHT, WIDTH)
        self.renderer.enable_segmentation_rendering()
        model = gallery.model
        self.names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) for i in range(model.ngeom)]

    def shares(self, view) -> dict[str, float]:
        self.gallery.place(view)
        self.renderer.update_scene(self.gallery.data, camera=CAMERA)
        ids = self.renderer.render()
        geom = np.where(ids[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM), ids[..., 0], -1)
        counts = np.bincount(geom.ravel() + 1, minlength=len(self.names) + 1)[1:]
        return {name: count / geom.size for name, count in zip(self.names, counts, strict=True)}


@pytest.fixture(scope="module", params=sorted(SPECS))
def gallery(request):
    with Gallery(SPECS[request.param], RenderConfig(width=WIDTH, height=HEIGHT)) as gallery:
        segmenter = Segmenter(gallery)
        gallery.segmenter = segmenter
        yield gallery
        segmenter.renderer.close()


@pytest.mark.parametrize("name", sorted(SPECS))
def test_default_scene_is_unchanged_and_lock_features_only_add_geoms(name):
    spec = SPECS[name]
    default = build_scene(spec).root.to_xml_string()
    assert default == build_scene(spec, SceneConfig(lock_features=False)).root.to_xml_string()
    assert ":lock:" not in default
    with_locks = build_scene(spec, SceneConfig(lock_features=True)).root.to_xml_string()
    diff = list(difflib.ndiff(default.splitlines(), with_locks.splitlines()))
    removed = [line for line in diff if line.startswith("- ")]
    added = [line for line in diff if line.startswith("+ ")]
    assert not removed and added and all(":lock:" in line for line in added)


def test_views_are_written_as_pngs_of_the_requested_size(gallery, tmp_path):
    paths = gallery.write_views(tmp_path)
    expected = ["top", "three-quarter", *(component_view_name(c.name) for c in gallery.spec.components)]
    assert [p.stem for p in paths] == expected
    for path in paths:
        image = iio.imread(path)
        assert image.shape == (HEIGHT, WIDTH, 3) and image.std() > 10, path.name


@pytest.mark.parametrize("view", ["top", "three-quarter"])
def test_every_component_marker_is_seen_in_the_whole_box_views(gallery, view):
    views = {v.name: v for v in gallery.views()}
    shares = gallery.segmenter.shares(views[view])
    for component in gallery.spec.components:
        marker = gallery.scene.names.components[component.name].marker
        assert shares[marker] > 0.001, (view, marker, shares[marker])
    assert shares["box/shell"] > 0.05  # the box fills the picture, it is not a speck


def test_each_close_up_shows_its_component_marker_and_handle_large(gallery):
    for component in gallery.spec.components:
        names = gallery.scene.names.components[component.name]
        shares = gallery.segmenter.shares(gallery.component_view(component.name))
        assert shares[names.marker] > 0.02, (component.name, shares[names.marker])
        assert shares[names.handle] > 0.005, (component.name, shares[names.handle])


def test_lock_features_appear_in_the_three_quarter_view(gallery):
    shares = gallery.segmenter.shares(gallery.three_quarter_view())
    features = [name for name in shares if ":lock:" in name]
    assert gallery.spec.locks and features
    assert all(shares[name] > 0 for name in features), {name: shares[name] for name in features}


def test_lock_features_take_their_lockers_colour_and_the_legend_says_who_holds_whom(gallery):
    spec, model = gallery.spec, gallery.model
    assert len(gallery.features) == len({(r.locker, r.locked) for r in spec.locks})
    for name, (locker, _) in gallery.features.items():
        np.testing.assert_allclose(model.geom_rgba[model.geom(name).id, :3], gallery.colours[locker])
    assert len(set(gallery.colours.values())) == len(spec.components)  # a colour per part
    lines = gallery.legend()
    assert len(lines) == 1 + len(spec.locks)
    assert f"goal {spec.goal.component}" in lines[0][0] and lines[0][0].endswith("its locker's colour")
    for rule, (text, colour) in zip(spec.locks, lines[1:], strict=True):
        assert text.startswith(rule_text(spec, rule)) and colour == gallery.colours[rule.locker]
        assert f"on {rule.locker}]" in text  # the feature that shows it, on its locker
    assert rule_text(spec, spec.locks[0]).split(" keeps ")[0].endswith(("closed", "open"))


def _exact(image: np.ndarray, rgb) -> int:
    return int(np.all(image == np.asarray(rgb, dtype=np.uint8), axis=-1).sum())


def test_the_annotated_views_label_every_part_mark_the_goal_and_append_the_legend(gallery, tmp_path):
    spec = gallery.spec
    paths = gallery.write_annotated(tmp_path)
    assert [p.name for p in paths] == ["top-annotated.png", "three-quarter-annotated.png"]
    for path in paths:
        image = iio.imread(path)
        assert image.shape[1] == WIDTH and image.shape[0] > HEIGHT + 14 * (1 + len(spec.locks)), path.name
        view, legend = image[:HEIGHT], image[HEIGHT:]
        for c in spec.components:  # a label chip in the part's colour
            chip = [int(255 * v) for v in gallery.colours[c.name]]
            assert _exact(view, chip) > 150, (path.name, c.name)
        assert _exact(view, (220, 20, 20)) > 100, "the goal's red rim"
        for rule in spec.locks:  # the legend's chip of each rule, in its locker's colour
            assert _exact(legend, [int(255 * v) for v in gallery.colours[rule.locker]]) > 100
    plain = gallery.render(gallery.top_view())
    assert np.abs(iio.imread(paths[0])[:HEIGHT].astype(int) - plain).max(axis=-1).astype(bool).mean() > 0.02


def test_turntable_has_its_frames_and_the_box_in_every_one(gallery, tmp_path):
    frames = 24
    views = gallery.turntable_views(frames)
    assert len(views) == frames
    distances = {round(math.dist(v.position, v.target), 9) for v in views}
    assert len(distances) == 1  # one circle: the camera neither zooms nor wobbles
    for view in views[::4]:
        shares = gallery.segmenter.shares(view)
        assert shares["box/shell"] > 0.05, view.name
        assert sum(share for name, share in shares.items() if name.endswith(":marker")) > 0.002, view.name
    video = iio.imread(gallery.write_turntable(tmp_path / "turntable.mp4", frames=frames, fps=12))
    assert video.shape == (frames, HEIGHT, WIDTH, 3)


def test_frame_view_fits_every_point_inside_the_image_with_the_margin():
    rng = np.random.default_rng(0)
    points = rng.uniform(-0.2, 0.2, size=(50, 3)) + [0.4, 0.1, 0.05]
    for direction in ([1.0, -1.0, 1.0], [0.0, 0.3, 1.0], [-1.0, 0.2, 0.4]):
        view = frame_view("v", np.array(direction), points, aspect=4 / 3, fovy=40.0, margin=1.1)
        matrix = np.empty(9)
        mujoco.mju_quat2Mat(matrix, np.array(view.quat))
        camera = (points - view.position) @ matrix.reshape(3, 3)  # MuJoCo camera axes: x right, y up, looks -z
        depth = -camera[:, 2]
        assert np.all(depth > 0)
        tan_v = math.tan(math.radians(20.0))
        u, v = camera[:, 0] / depth / (4 / 3 * tan_v), camera[:, 1] / depth / tan_v  # -1..1 across the image
        assert np.all(np.abs(u) <= 1 / 1.1 + 1e-9) and np.all(np.abs(v) <= 1 / 1.1 + 1e-9)
        assert max(np.abs(u).max(), np.abs(v).max()) == pytest.approx(1 / 1.1)  # as close as it can be
        assert max(u) + min(u) == pytest.approx(0, abs=1e-9) or max(v) + min(v) == pytest.approx(0, abs=1e-9)


def test_a_disassembly_scene_has_no_gallery():
    with pytest.raises(SceneError, match="no box"):
        Gallery(spec_from_dict(SCENE_EXAMPLE))
