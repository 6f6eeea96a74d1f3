"""The memory: pose keys, the SQLite store and priors recalled from it."""

import dataclasses
import shutil
import sqlite3

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from puzzlebox.learning import MemoryAgent, SymbolicWorld, run_episode
from puzzlebox.learning.belief import Belief, default_prior, hypothesis_count
from puzzlebox.learning.errors import LearningError, MemoryFileError
from puzzlebox.learning.memory import (
    MEMORY_FORMAT,
    SCHEMA_VERSION,
    MemoryConfig,
    MemoryStore,
    episode_record,
    recall_prior,
    relative_pose_keys,
    se3_pose_keys,
)
from puzzlebox.learning.memory.keys import se3_key_from_legacy
from puzzlebox.models.generator import TEST_INDICES, TRAIN_INDICES, paper_variant

KINDS = ("door", "slide", "wheel")
PAPER_CONFIG = MemoryConfig(bandwidth=None, weight_by_confidence=False)
"""The paper's plain average of the k nearest memories."""


# -- keys --------------------------------------------------------------------------------------------------


def random_planar_poses(rng, n):
    return np.column_stack([rng.uniform(-0.3, 0.3, (n, 2)), rng.uniform(-np.pi, np.pi, n)])


def random_spatial_poses(rng, n):
    return np.column_stack([rng.uniform(-0.3, 0.3, (n, 3)), Rotation.random(n, rng=rng).as_euler("xyz")])


def move_planar(poses, dx, dy, dyaw):
    c, s = np.cos(dyaw), np.sin(dyaw)
    xy = poses[:, :2] @ np.array([[c, -s], [s, c]]).T + [dx, dy]
    yaw = (poses[:, 2] + dyaw + np.pi) % (2 * np.pi) - np.pi
    return np.column_stack([xy, yaw])


def move_spatial(poses, translation, rotation: Rotation):
    positions = rotation.apply(poses[:, :3]) + translation
    orientations = (rotation * Rotation.from_euler("xyz", poses[:, 3:])).as_euler("xyz")
    return np.column_stack([positions, orientations])


@settings(max_examples=60, deadline=None)
@given(
    st.integers(2, 7),
    st.integers(0, 2**32 - 1),
    st.floats(-2.0, 2.0),
    st.floats(-2.0, 2.0),
    st.floats(-10.0, 10.0),
    st.sampled_from([0.02, 0.1, 1.0]),
)
def test_planar_keys_do_not_change_when_the_whole_scene_moves_and_turns(n, seed, dx, dy, dyaw, scale):
    poses = random_planar_poses(np.random.default_rng(seed), n)
    keys = relative_pose_keys(poses, scale)
    assert keys.shape == (n, n, 4)
    np.testing.assert_allclose(relative_pose_keys(move_planar(poses, dx, dy, dyaw), scale), keys, atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.integers(2, 6), st.integers(0, 2**32 - 1), st.sampled_from([0.02, 1.0]))
def test_spatial_keys_do_not_change_when_the_whole_scene_moves_and_turns(n, seed, scale):
    rng = np.random.default_rng(seed)
    poses = random_spatial_poses(rng, n)
    moved = move_spatial(poses, rng.uniform(-1.0, 1.0, 3), Rotation.random(rng=rng))
    keys = relative_pose_keys(poses, scale)
    assert keys.shape == (n, n, 9)
    moved_keys = relative_pose_keys(moved, scale)
    np.testing.assert_allclose(moved_keys[..., :3], keys[..., :3], atol=1e-9)  # positions in i's frame
    # the relative rotation itself (not only its Euler angles) is unchanged
    for i in range(n):
        for j in range(n):
            a = Rotation.from_euler("xyz", np.arctan2(keys[i, j, 3:6], keys[i, j, 6:9]))
            b = Rotation.from_euler("xyz", np.arctan2(moved_keys[i, j, 3:6], moved_keys[i, j, 6:9]))
            assert (a.inv() * b).magnitude() < 1e-7


@pytest.mark.parametrize("seed", range(10))
def test_spatial_keys_away_from_gimbal_lock_are_identical_after_a_rigid_move(seed):
    rng = np.random.default_rng(seed)
    poses = np.column_stack([rng.uniform(-0.3, 0.3, (4, 3)), rng.uniform(-0.5, 0.5, (4, 3))])  # small angles
    rotation = Rotation.from_euler("xyz", rng.uniform(-np.pi, np.pi, 3))
    moved = move_spatial(poses, rng.uniform(-1.0, 1.0, 3), rotation)
    np.testing.assert_allclose(relative_pose_keys(moved, 0.05), relative_pose_keys(poses, 0.05), atol=1e-9)


@pytest.mark.parametrize("spatial", [False, True])
def test_keys_change_exactly_for_the_pairs_of_a_component_that_moves(spatial):
    rng = np.random.default_rng(7)
    n, moving = 5, 2
    poses = random_spatial_poses(rng, n) if spatial else random_planar_poses(rng, n)
    keys = relative_pose_keys(poses, 0.02)
    for change in ("translate", "rotate"):
        moved = poses.copy()
        if change == "translate":
            moved[moving, :2] += [0.01, -0.02]
        else:
            moved[moving, -1] += 0.3
        moved_keys = relative_pose_keys(moved, 0.02)
        differs = np.any(np.abs(moved_keys - keys) > 1e-9, axis=-1)
        expected = np.zeros((n, n), dtype=bool)
        expected[moving, :] = expected[:, moving] = True
        expected[moving, moving] = False
        np.testing.assert_array_equal(differs, expected, err_msg=change)


def test_planar_key_is_the_pose_of_j_in_i_frame_scaled():
    poses = np.array([[1.0, 2.0, np.pi / 2], [1.0, 2.5, np.pi / 2 + 0.4]])
    keys = relative_pose_keys(poses, 0.1)
    np.testing.assert_allclose(keys[0, 1], [5.0, 0.0, np.sin(0.4), np.cos(0.4)], atol=1e-12)  # j ahead of i
    np.testing.assert_allclose(keys[1, 0, :2], [-5.0 * np.cos(0.4), 5.0 * np.sin(0.4)], atol=1e-12)
    np.testing.assert_allclose(keys[0, 0], [0.0, 0.0, 0.0, 1.0], atol=1e-12)


# -- episodes and stores -------------------------------------------------------------------------------------


def random_episode(rng, n, spatial=False):
    kinds = tuple(rng.choice(KINDS, size=n))
    poses = random_spatial_poses(rng, n) if spatial else random_planar_poses(rng, n)
    probs = rng.random((n, 2, hypothesis_count(n))) ** 3
    probs[:, :, 0] += 0.1
    pair_values, independence = episode_record(Belief(probs).probs)
    return kinds, poses, pair_values, independence


def fill(store, seed, episodes=6, spatial=False):
    rng = np.random.default_rng(seed)
    for e in range(episodes):
        n = int(rng.integers(2, 6))
        kinds, poses, pair_values, independence = random_episode(rng, n, spatial)
        keys = se3_pose_keys(poses, store.position_scale, store.rotation_weight)
        store.add_episode(kinds, keys, pair_values, independence, spec=f"ep{e}", solved=bool(e % 2), num_actions=e)


def queries(seed, spatial=False):
    rng = np.random.default_rng(seed)
    out = []
    for n in (2, 3, 5):
        kinds = tuple(rng.choice(KINDS, size=n))
        out.append((kinds, random_spatial_poses(rng, n) if spatial else random_planar_poses(rng, n)))
    return out


@pytest.fixture(scope="module")
def trained_memory_file(tmp_path_factory):
    """A memory file trained by the memory agent on the 9 paper training variants (one episode each)."""
    path = tmp_path_factory.mktemp("memory") / "paper.sqlite"
    store = MemoryStore(path)
    agent = MemoryAgent(store, learn=True)
    for index in TRAIN_INDICES:
        spec = paper_variant(index, seed=0)
        agent.episode_label = spec.name
        run_episode(agent, SymbolicWorld(spec, index), spec.name, index, max_actions=30)
    summary = store.summary()
    store.close()
    return path, summary


def test_episode_record_reads_the_belief_blocks_of_every_pair():
    n = 3
    rng = np.random.default_rng(0)
    belief = Belief(rng.random((n, 2, hypothesis_count(n))))
    pair_values, independence = episode_record(belief.probs)
    assert pair_values.shape == (n, n, 6) and independence.shape == (n, 2)
    for i in range(n):
        for j in range(n):
            for k, (s_j, s_i) in enumerate([(0, 0), (0, 1), (1, 0), (1, 1)]):
                assert pair_values[i, j, k] == belief.probs[j, s_j, 1 + 2 * i + s_i]
    np.testing.assert_array_equal(independence, belief.probs[:, :, 0])
    resolved = np.zeros((n, 2, hypothesis_count(n)))
    resolved[:, :, 0] = 1.0
    confident, _ = episode_record(resolved)
    np.testing.assert_allclose(confident[..., 4:], 1.0)
    vague, _ = episode_record(Belief(np.ones((n, 2, hypothesis_count(n)))).probs)
    np.testing.assert_allclose(vague[..., 4:], 0.0, atol=1e-12)


@pytest.mark.parametrize("spatial", [False, True])
def test_memory_file_round_trip_keeps_summary_buckets_and_recalled_priors(tmp_path, spatial):
    path = tmp_path / "memory.sqlite"
    store = MemoryStore(path, position_scale=0.05)
    fill(store, seed=1, spatial=spatial)
    before_summary = store.summary()
    before_priors = [recall_prior(store, kinds, poses, MemoryConfig()) for kinds, poses in queries(2, spatial)]
    store.close()

    reopened = MemoryStore.open_existing(path)
    assert reopened.summary() == before_summary
    assert reopened.position_scale == 0.05  # the file's scale, not the default
    for (kinds, poses), before in zip(queries(2, spatial), before_priors, strict=True):
        np.testing.assert_array_equal(recall_prior(reopened, kinds, poses, MemoryConfig()), before)
    # adding to the reopened memory persists too
    fill(reopened, seed=3, episodes=2, spatial=spatial)
    grown = reopened.summary()
    reopened.close()
    assert MemoryStore(path).summary() == grown and grown["episodes"] == before_summary["episodes"] + 2


def test_memory_trained_by_the_agent_reopens_with_the_same_summary_and_priors(trained_memory_file, tmp_path):
    path, summary = trained_memory_file
    copy = tmp_path / "copy.sqlite"
    shutil.copy(path, copy)
    reopened = MemoryStore.open_existing(copy)
    assert reopened.summary() == summary
    assert summary["episodes"] == len(TRAIN_INDICES)
    again = MemoryStore.open_existing(copy)
    for index in TEST_INDICES:
        spec = paper_variant(index, seed=5)
        a = recall_prior(reopened, spec.kinds, spec.poses_in_world(), MemoryConfig())
        b = recall_prior(again, spec.kinds, spec.poses_in_world(), MemoryConfig())
        np.testing.assert_array_equal(a, b)


def test_ram_only_memory_matches_a_file_memory(tmp_path):
    ram, disk = MemoryStore(), MemoryStore(tmp_path / "m.sqlite")
    fill(ram, seed=4)
    fill(disk, seed=4)
    assert ram.summary() == disk.summary()
    for kinds, poses in queries(5):
        np.testing.assert_array_equal(
            recall_prior(ram, kinds, poses, MemoryConfig()), recall_prior(disk, kinds, poses, MemoryConfig())
        )


# -- files that are not usable memories ---------------------------------------------------------------------


def assert_not_a_memory(path):
    before = path.read_bytes() if path.exists() else None
    with pytest.raises(MemoryFileError):
        MemoryStore.open_existing(path)
    with pytest.raises(MemoryFileError):
        MemoryStore(path)  # the plain constructor refuses the file as well
    if before is not None:
        assert path.read_bytes() == before  # a refused file is left as it was


def test_opening_a_missing_memory_file_is_a_memory_file_error(tmp_path):
    with pytest.raises(MemoryFileError, match="no memory file"):
        MemoryStore.open_existing(tmp_path / "absent.sqlite")
    assert not (tmp_path / "absent.sqlite").exists()
    assert issubclass(MemoryFileError, LearningError)


@pytest.mark.parametrize("cut", ["header", "first-kb", "first-page", "half", "last-page", "mid-last-page"])
def test_a_truncated_memory_file_is_a_memory_file_error(trained_memory_file, tmp_path, cut):
    path, _ = trained_memory_file
    data = path.read_bytes()
    page = 4096
    assert len(data) >= 4 * page
    length = {
        "header": 100,
        "first-kb": 1024,
        "first-page": page,
        "half": (len(data) // 2 // page) * page,
        "last-page": len(data) - page,
        "mid-last-page": len(data) - page // 2,
    }[cut]
    truncated = tmp_path / "truncated.sqlite"
    truncated.write_bytes(data[:length])
    assert_not_a_memory(truncated)


def test_a_memory_file_truncated_to_zero_bytes_is_a_memory_file_error(trained_memory_file, tmp_path):
    truncated = tmp_path / "empty.sqlite"
    truncated.write_bytes(trained_memory_file[0].read_bytes()[:0])
    with pytest.raises(MemoryFileError):
        MemoryStore.open_existing(truncated)
    assert truncated.stat().st_size == 0


@pytest.mark.parametrize("size", [1, 16, 100, 5000, 40_000])
def test_a_file_of_random_bytes_is_a_memory_file_error(tmp_path, size):
    path = tmp_path / "random.sqlite"
    path.write_bytes(np.random.default_rng(size).bytes(size))
    assert_not_a_memory(path)


def test_another_applications_sqlite_file_is_a_memory_file_error(tmp_path):
    path = tmp_path / "other.sqlite"
    conn = sqlite3.connect(path)
    with conn:
        conn.execute("CREATE TABLE customers (id INTEGER PRIMARY KEY, name TEXT)")
        conn.execute("INSERT INTO customers (name) VALUES ('ada')")
    conn.close()
    assert_not_a_memory(path)


def test_an_sqlite_file_with_a_foreign_meta_table_is_a_memory_file_error(tmp_path):
    path = tmp_path / "other-meta.sqlite"
    conn = sqlite3.connect(path)
    with conn:
        conn.execute("CREATE TABLE meta (name TEXT, data BLOB)")
        conn.execute("INSERT INTO meta VALUES ('version', x'01')")
    conn.close()
    assert_not_a_memory(path)
    other_format = tmp_path / "other-format.sqlite"
    conn = sqlite3.connect(other_format)
    with conn:
        conn.execute("CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT NOT NULL)")
        conn.executemany("INSERT INTO meta VALUES (?, ?)", [("format", "something-else"), ("schema_version", "1")])
    conn.close()
    assert_not_a_memory(other_format)


@pytest.mark.parametrize("version", [str(SCHEMA_VERSION + 1), "0", "one"])
def test_a_memory_of_another_schema_version_is_a_memory_file_error(trained_memory_file, tmp_path, version):
    path = tmp_path / "schema.sqlite"
    shutil.copy(trained_memory_file[0], path)
    conn = sqlite3.connect(path)
    with conn:
        conn.execute("UPDATE meta SET value = ? WHERE key = 'schema_version'", (version,))
    conn.close()
    with pytest.raises(MemoryFileError, match="schema"):
        MemoryStore.open_existing(path)


def test_a_memory_with_a_malformed_entry_is_a_memory_file_error(trained_memory_file, tmp_path):
    path = tmp_path / "malformed.sqlite"
    shutil.copy(trained_memory_file[0], path)
    conn = sqlite3.connect(path)
    with conn:
        conn.execute("UPDATE pair_entries SET value = ? WHERE rowid = 1", (np.zeros(5).tobytes(),))
    conn.close()
    assert_not_a_memory(path)


@pytest.mark.parametrize(
    ("change", "says"),
    [
        ("UPDATE pair_entries SET kind_i = 'trapdoor' WHERE rowid = 1", "a pair entry of an unknown kind"),
        ("UPDATE independence_entries SET kind = 'trapdoor' WHERE rowid = 1", "an independence entry of an unknown"),
        ("INSERT INTO training_runs (started, config) VALUES (0, '{not json')", "whose config is not JSON"),
    ],
)
def test_a_memory_whose_contents_are_bad_is_refused_on_opening_and_left_unchanged(
    trained_memory_file, tmp_path, change, says
):
    # (train.py wrote to such a memory before failing with a traceback; the memory agent failed every trial)
    path = tmp_path / "bad.sqlite"
    shutil.copy(trained_memory_file[0], path)
    conn = sqlite3.connect(path)
    with conn:
        assert conn.execute(change).rowcount == 1
    conn.close()
    before = path.read_bytes()
    with pytest.raises(MemoryFileError, match=says):
        MemoryStore(path)
    assert path.read_bytes() == before


def test_a_memory_whose_meta_lacks_the_position_scale_is_a_memory_file_error(trained_memory_file, tmp_path):
    path = tmp_path / "no-scale.sqlite"
    shutil.copy(trained_memory_file[0], path)
    conn = sqlite3.connect(path)
    with conn:
        conn.execute("DELETE FROM meta WHERE key = 'position_scale'")
    conn.close()
    with pytest.raises(MemoryFileError):
        MemoryStore.open_existing(path)


def test_a_new_memory_file_records_format_version_and_scale(tmp_path):
    path = tmp_path / "new.sqlite"
    MemoryStore(path, position_scale=0.03).close()
    conn = sqlite3.connect(path)
    meta = dict(conn.execute("SELECT key, value FROM meta").fetchall())
    conn.close()
    assert meta == {
        "format": MEMORY_FORMAT,
        "schema_version": str(SCHEMA_VERSION),
        "position_scale": "0.03",
        "rotation_weight": "1.0",
    }


# -- recalled priors ------------------------------------------------------------------------------------------


def moved_box(spec, pose):
    return dataclasses.replace(spec, box=dataclasses.replace(spec.box, pose=pose))


BOX_POSES = [(0.1, -0.3, 1.0), (-0.5, 0.2, -2.5), (0.45, 0.0, np.pi), (0.3, 0.3, np.pi / 2), (0.0, 0.0, 0.0)]


@pytest.mark.parametrize("index", TRAIN_INDICES[:3] + TEST_INDICES)
def test_a_box_moved_and_turned_on_the_table_recalls_the_same_prior(trained_memory_file, index):
    store = MemoryStore.open_existing(trained_memory_file[0])
    spec = paper_variant(index, seed=0)  # train variants: the very boxes the memory was trained on
    prior = recall_prior(store, spec.kinds, spec.poses_in_world(), MemoryConfig())
    assert not np.allclose(prior, default_prior(5, 0.7))  # the memory does inform it
    for pose in BOX_POSES:
        moved = moved_box(spec, pose)
        assert not np.allclose(moved.poses_in_world(), spec.poses_in_world())
        np.testing.assert_allclose(
            recall_prior(store, moved.kinds, moved.poses_in_world(), MemoryConfig()), prior, atol=1e-6
        )


def test_memory_trained_on_a_turned_box_recalls_what_it_recalls_for_the_box_in_place():
    spec = paper_variant(TRAIN_INDICES[4], seed=0)
    turned = moved_box(spec, (0.2, 0.25, 2.0))
    priors = []
    for trained_on in (spec, turned):
        store = MemoryStore()
        agent = MemoryAgent(store, learn=True)
        run_episode(agent, SymbolicWorld(trained_on, 0), trained_on.name, 0, max_actions=30)
        priors.append(recall_prior(store, spec.kinds, spec.poses_in_world(), MemoryConfig()))
    np.testing.assert_allclose(priors[0], priors[1], atol=1e-9)


def store_with_two_tied_memories():
    """Two memories of a door-slide pair, mirror images about the door's x axis: "door closed holds the slide"
    with the slide 2 key units to the door's left, "door open holds it" 2 units to its right."""
    store = MemoryStore()
    for y, locker_state in ((2.0, 0), (-2.0, 1)):
        probs = default_prior(2)
        probs[1, 0] = 0.0
        probs[1, 0, 1 + locker_state] = 1.0
        pair_values, independence = episode_record(Belief(probs).probs)
        compact = np.zeros((2, 2, 4))  # (x, y, sin, cos)
        compact[..., 3] = 1.0
        compact[0, 1, 1], compact[1, 0, 1] = y, -y
        keys = np.apply_along_axis(se3_key_from_legacy, -1, compact)
        store.add_episode(("door", "slide"), keys, pair_values, independence)
    return store


def test_equidistant_memories_are_recalled_the_same_wherever_the_box_stands():
    store = store_with_two_tied_memories()
    config = MemoryConfig(k=1, bandwidth=None, weight_by_confidence=False, uniform_mass=0.0)
    poses = np.array([[0.0, 0.0, 0.0], [0.04, 0.0, 0.0]])  # the slide straight ahead: key (2, 0, 0, 1)
    prior = recall_prior(store, ("door", "slide"), poses, config)
    for turn in (0.5, 1.0, 1.5, 2.0):
        turned = move_planar(poses, 0.3, -0.2, turn)
        np.testing.assert_array_equal(
            recall_prior(store, ("door", "slide"), turned, config), prior, err_msg=f"box turned by {turn} rad"
        )


def test_paper_knn_prior_does_not_depend_on_where_the_box_stands(trained_memory_file):
    store = MemoryStore.open_existing(trained_memory_file[0])
    for index in TRAIN_INDICES + TEST_INDICES:
        spec = paper_variant(index, seed=0)
        prior = recall_prior(store, spec.kinds, spec.poses_in_world(), PAPER_CONFIG)
        for pose in BOX_POSES:
            moved = moved_box(spec, pose)
            np.testing.assert_allclose(
                recall_prior(store, moved.kinds, moved.poses_in_world(), PAPER_CONFIG),
                prior,
                atol=1e-6,
                err_msg=f"{spec.name} with the box at {pose}",
            )


@pytest.mark.parametrize("config", [MemoryConfig(), PAPER_CONFIG, MemoryConfig(k=1, uniform_mass=0.0)])
def test_recalled_priors_are_valid_beliefs(config):
    store = MemoryStore()
    fill(store, seed=8, episodes=10)
    for kinds, poses in queries(9):
        n = len(kinds)
        prior = recall_prior(store, kinds, poses, config)
        assert prior.shape == (n, 2, hypothesis_count(n))
        np.testing.assert_allclose(prior.sum(axis=-1), 1.0)
        possible = default_prior(n) > 0.0
        assert np.all(prior[~possible] == 0.0)  # nothing holds itself
        if config.uniform_mass > 0.0:
            assert np.all(prior[possible] > 0.0)  # a bad prior can still be unlearned
        Belief(prior)  # accepted as a belief


def test_empty_memory_recalls_the_uninformed_prior():
    prior = recall_prior(
        MemoryStore(),
        ("door", "slide", "wheel"),
        random_planar_poses(np.random.default_rng(0), 3),
        MemoryConfig(),
        prior_independent=0.6,
    )
    np.testing.assert_array_equal(prior, default_prior(3, 0.6))


def test_unseen_kind_pair_falls_back_to_the_uninformed_prior():
    store = MemoryStore()
    rng = np.random.default_rng(0)
    poses = random_planar_poses(rng, 2)
    probs = default_prior(2)
    probs[1, 0] = [0.0, 1.0, 0.0, 0.0, 0.0]  # "door in state 0 holds slide in state 0", resolved
    pair_values, independence = episode_record(Belief(probs).probs)
    store.add_episode(("door", "slide"), se3_pose_keys(poses, 0.02), pair_values, independence)
    config = MemoryConfig(uniform_mass=0.0, back_off=False)
    recalled = recall_prior(store, ("door", "slide"), poses, config)
    assert recalled[1, 0, 1] > 0.5  # the same pose recalls the lock
    unseen = recall_prior(store, ("wheel", "wheel"), poses, config)
    np.testing.assert_allclose(unseen, default_prior(2))
    backed_off = recall_prior(store, ("wheel", "wheel"), poses, MemoryConfig(uniform_mass=0.0))
    assert backed_off[1, 0, 1] > 0.5  # with back-off, the pose alone recalls the lock


def test_memory_recalls_which_locker_state_at_the_pose_it_was_learned_and_not_far_away():
    store = MemoryStore()
    poses = np.array([[0.0, 0.0, 0.0], [0.05, 0.0, 0.0]])
    probs = default_prior(2)
    probs[1, 0] = [0.0, 1.0, 0.0, 0.0, 0.0]
    pair_values, independence = episode_record(Belief(probs).probs)
    store.add_episode(("door", "slide"), se3_pose_keys(poses, 0.02), pair_values, independence)
    near = recall_prior(store, ("door", "slide"), poses, MemoryConfig())
    far_poses = np.array([[0.0, 0.0, 0.0], [0.0, 0.4, 2.0]])
    far = recall_prior(store, ("door", "slide"), far_poses, MemoryConfig())
    # near: door closed holds slide closed, not door open; far: the pose says nothing about which
    # door state holds the slide (its independence is pooled per kind, so it is still held)
    assert near[1, 0, 1] > near[1, 0, 2] + 0.5
    assert far[1, 0, 1] == pytest.approx(far[1, 0, 2], abs=1e-6)


def test_the_content_digest_says_what_a_memory_teaches_not_when_it_was_stored(tmp_path):
    from puzzlebox.learning.memory.store import content_sha256

    def trained(path, episodes):
        store = MemoryStore(path)
        for e in range(episodes):
            spec = paper_variant(TRAIN_INDICES[e], seed=0)
            run_episode(MemoryAgent(store, learn=True), SymbolicWorld(spec, e), spec.name, e, 30)
        store.close()
        return path

    first, again = trained(tmp_path / "a.sqlite", 2), trained(tmp_path / "b.sqlite", 2)  # stored at other times
    with sqlite3.connect(again) as conn:
        assert conn.execute("SELECT COUNT(*) FROM episodes").fetchone()[0] == 2
        conn.execute("UPDATE episodes SET created = created + 3600")
    assert content_sha256(first) == content_sha256(again)
    assert content_sha256(trained(tmp_path / "c.sqlite", 3)) != content_sha256(first)  # one episode more
    with sqlite3.connect(again) as conn:  # one learned probability changed
        rowid, value = conn.execute("SELECT rowid, value FROM pair_entries LIMIT 1").fetchone()
        conn.execute("UPDATE pair_entries SET value = ? WHERE rowid = ?", (bytes(reversed(value)), rowid))
    assert content_sha256(again) != content_sha256(first)
    for name in ("empty.sqlite", "empty-too.sqlite"):
        MemoryStore(tmp_path / name).close()
    assert content_sha256(tmp_path / "empty.sqlite") == content_sha256(tmp_path / "empty-too.sqlite")
