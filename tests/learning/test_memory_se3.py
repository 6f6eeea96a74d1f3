"""SE(3) memory keys (issue 14 part 3): invariant to moving and turning a whole scene in 3-D, distances with
the documented rotation weight, planar distances as before, and older memory files read, migrated or refused."""

from __future__ import annotations

import shutil
import sqlite3
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from legacy_memory import make_legacy
from scipy.spatial.transform import Rotation

from puzzlebox.learning import MemoryAgent, SymbolicWorld, run_episode
from puzzlebox.learning.errors import MemoryFileError
from puzzlebox.learning.memory import MemoryConfig, MemoryStore, recall_prior, relative_pose_keys, se3_pose_keys
from puzzlebox.learning.memory.keys import SE3_KEY_SIZE, se3_key_from_legacy
from puzzlebox.models.generator import TEST_INDICES, TRAIN_INDICES, paper_variant

ROOT = Path(__file__).resolve().parents[2]


def random_scene(rng: np.random.Generator, n: int) -> np.ndarray:
    """``(n, 6)`` poses [m, rad]: positions within 0.3 m, any orientation."""
    return np.column_stack([rng.uniform(-0.3, 0.3, (n, 3)), Rotation.random(n, rng=rng).as_euler("xyz")])


def moved_scene(poses: np.ndarray, rotation: Rotation, translation: np.ndarray) -> np.ndarray:
    """The scene moved as one rigid body: every pose premultiplied by ``(rotation, translation)``."""
    positions = rotation.apply(poses[:, :3]) + translation
    orientations = (rotation * Rotation.from_euler("xyz", poses[:, 3:])).as_euler("xyz")
    return np.column_stack([positions, orientations])


@pytest.mark.parametrize("seed", range(6))
def test_se3_keys_do_not_change_when_the_whole_scene_moves_and_turns_in_3d(seed):
    rng = np.random.default_rng(seed)
    poses = random_scene(rng, 7)
    moved = moved_scene(poses, Rotation.random(rng=rng), rng.uniform(-2.0, 2.0, 3))
    keys = se3_pose_keys(poses, 0.02, 1.5)
    np.testing.assert_allclose(se3_pose_keys(moved, 0.02, 1.5), keys, atol=1e-9)
    # and they do change when one component alone turns
    turned = poses.copy()
    turned[2, 3:] = (Rotation.from_euler("xyz", poses[2, 3:]) * Rotation.from_rotvec([0.0, 0.3, 0.0])).as_euler("xyz")
    changed = np.abs(se3_pose_keys(turned, 0.02, 1.5) - keys).max(axis=-1) > 1e-6
    expected = np.zeros((7, 7), dtype=bool)
    expected[2, :] = expected[:, 2] = True
    expected[2, 2] = False
    np.testing.assert_array_equal(changed, expected)


@pytest.mark.parametrize("weight", [0.0, 1.0, 2.5])
def test_key_distance_is_position_over_scale_and_weight_times_the_chord_of_the_relative_rotation(weight):
    rng = np.random.default_rng(1)
    scene_a, scene_b = random_scene(rng, 2), random_scene(rng, 2)
    key_a, key_b = se3_pose_keys(scene_a, 0.05, weight)[0, 1], se3_pose_keys(scene_b, 0.05, weight)[0, 1]

    def relative(scene):  # j's orientation in i's frame
        return Rotation.from_euler("xyz", scene[0, 3:]).inv() * Rotation.from_euler("xyz", scene[1, 3:])

    angle = (relative(scene_a).inv() * relative(scene_b)).magnitude()
    expected = np.hypot(np.linalg.norm(key_a[:3] - key_b[:3]), weight * 2.0 * np.sin(angle / 2.0))
    assert np.linalg.norm(key_a - key_b) == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_planar_distances_are_those_of_the_compact_planar_keys(seed):
    rng = np.random.default_rng(seed)
    poses = np.column_stack([rng.uniform(-0.2, 0.2, (6, 2)), rng.uniform(-np.pi, np.pi, 6)])
    compact, se3 = relative_pose_keys(poses, 0.02).reshape(36, 4), se3_pose_keys(poses, 0.02).reshape(36, 12)
    np.testing.assert_allclose(
        np.linalg.norm(se3[:, None] - se3[None], axis=-1),
        np.linalg.norm(compact[:, None] - compact[None], axis=-1),
        atol=1e-12,
    )


@pytest.mark.parametrize("spatial", [False, True])
def test_a_legacy_key_converts_to_the_se3_key_of_the_same_pose(spatial):
    rng = np.random.default_rng(2)
    poses = random_scene(rng, 5) if spatial else np.column_stack([rng.uniform(-0.2, 0.2, (5, 2)), rng.normal(size=5)])
    compact = relative_pose_keys(poses, 0.02)
    converted = np.apply_along_axis(se3_key_from_legacy, -1, compact, 0.7)
    np.testing.assert_allclose(converted, se3_pose_keys(poses, 0.02, 0.7), atol=1e-12)
    with pytest.raises(ValueError, match="4 or 9 numbers"):
        se3_key_from_legacy(np.zeros(12))


@pytest.fixture(scope="module")
def paper_memory(tmp_path_factory):
    """A memory file trained on the 9 paper training variants (one episode each), today's schema."""
    path = tmp_path_factory.mktemp("se3") / "paper.sqlite"
    store = MemoryStore(path)
    for index in TRAIN_INDICES:
        spec = paper_variant(index, seed=0)
        run_episode(MemoryAgent(store, learn=True), SymbolicWorld(spec, index), spec.name, index, max_actions=30)
    store.close()
    return path


def priors(store: MemoryStore) -> list[np.ndarray]:
    specs = [paper_variant(index, seed=4) for index in TEST_INDICES]
    return [recall_prior(store, spec.kinds, spec.poses_in_world(), MemoryConfig()) for spec in specs]


@pytest.mark.parametrize("schema", [1, 2, 3])
def test_an_older_memory_file_recalls_the_same_priors_and_is_migrated_when_trained(paper_memory, tmp_path, schema):
    today = MemoryStore.open_existing(paper_memory)
    expected = priors(today)
    path = tmp_path / "old.sqlite"
    shutil.copy(paper_memory, path)
    make_legacy(path, schema)
    before = path.read_bytes()
    old = MemoryStore.open_existing(path)
    assert old.schema == str(schema)
    for got, want in zip(priors(old), expected, strict=True):
        np.testing.assert_allclose(got, want, atol=1e-12)
    assert path.read_bytes() == before  # reading does not migrate
    spec = paper_variant(TEST_INDICES[0], seed=1)
    run_episode(MemoryAgent(old, learn=True), SymbolicWorld(spec, 0), spec.name, 0, max_actions=30)
    old.close()
    with sqlite3.connect(path) as conn:
        meta = dict(conn.execute("SELECT key, value FROM meta").fetchall())
        sizes = {len(key) // 8 for (key,) in conn.execute("SELECT key FROM pair_entries")}
    assert (meta["schema_version"], meta["rotation_weight"], sizes) == ("4", "1.0", {SE3_KEY_SIZE})
    migrated = MemoryStore.open_existing(path)
    assert migrated.num_episodes == len(TRAIN_INDICES) + 1 and migrated.schema == "4"


def test_memory_script_migrates_an_older_file_in_place_and_says_so(paper_memory, tmp_path):
    path = tmp_path / "old.sqlite"
    shutil.copy(paper_memory, path)
    make_legacy(path, 3)
    expected = priors(MemoryStore.open_existing(path))
    done = subprocess.run(
        [sys.executable, ROOT / "scripts/memory.py", path, "--migrate"], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert "migrated from schema 3 to 4" in done.stderr
    migrated = MemoryStore.open_existing(path)
    assert migrated.schema == "4"
    for got, want in zip(priors(migrated), expected, strict=True):
        np.testing.assert_array_equal(got, want)  # the file holds exactly what was recalled from it before


def test_malformed_keys_are_refused_clearly(paper_memory, tmp_path):
    wrong_size = tmp_path / "wrong-size.sqlite"
    shutil.copy(paper_memory, wrong_size)
    with sqlite3.connect(wrong_size) as conn:  # a schema 4 file holding a compact key
        conn.execute("UPDATE pair_entries SET key = ? WHERE rowid = 1", (np.zeros(4).tobytes(),))
    with pytest.raises(MemoryFileError, match="schema 4 keys have 12 numbers"):
        MemoryStore.open_existing(wrong_size)
    no_angle = tmp_path / "no-angle.sqlite"
    shutil.copy(paper_memory, no_angle)
    make_legacy(no_angle, 3)
    with sqlite3.connect(no_angle) as conn:  # sin = cos = 0 is no angle
        conn.execute("UPDATE pair_entries SET key = ? WHERE rowid = 1", (np.zeros(4).tobytes(),))
    with pytest.raises(MemoryFileError, match="is not an angle"):
        MemoryStore.open_existing(no_angle)
    no_weight = tmp_path / "no-weight.sqlite"
    shutil.copy(paper_memory, no_weight)
    with sqlite3.connect(no_weight) as conn:
        conn.execute("UPDATE meta SET value = 'nan' WHERE key = 'rotation_weight'")
    with pytest.raises(MemoryFileError, match="rotation_weight"):
        MemoryStore.open_existing(no_weight)
