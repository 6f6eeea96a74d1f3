"""A box met in several episodes is one neighbour of the memory's k nearest: meeting it again (a twin episode on a box
the simulator also met, perceived a millimetre off) sharpens what is recalled of it, and pushes no other box out."""

import numpy as np
import pytest

from puzzlebox.learning.memory import MemoryConfig, MemoryStore, se3_pose_keys
from puzzlebox.learning.memory.prior import nearest_pairs, recall_memberships
from puzzlebox.learning.memory.store import pair_ids

KINDS = ("door", "slide")
QUERY = np.array([[0.0, 0.0, 0.0], [0.10, 0.0, 0.0]])
"""The task: a door at the origin and a slide 10 cm along x [m, m, rad]."""


def _meet(store: MemoryStore, box: str, dx: float, held: float, confidence: float = 0.9) -> None:
    """One episode on ``box``: the slide ``dx`` [m] further than in the task; P(door closed holds slide closed)
    = ``held``."""
    poses = QUERY + [[0.0, 0.0, 0.0], [dx, 0.0, 0.0]]
    keys = se3_pose_keys(poses, store.position_scale, store.rotation_weight)
    values = np.zeros((2, 2, 6))
    values[0, 1] = [held, 0.0, 0.0, 0.0, confidence, confidence]  # [i = door, j = slide]: (s_j, s_i) = (0, 0)
    values[1, 0, 4:] = confidence
    store.add_episode(KINDS, keys, values, np.full((2, 2), 0.5), spec=box)


def _held(store: MemoryStore) -> float:
    """The recalled P(door closed is among the closed slide's lockers)."""
    return float(recall_memberships(store, KINDS, QUERY, MemoryConfig())[1, 0, 1])


def _six_boxes(store: MemoryStore) -> None:
    """Boxes b0..b5, each 4 mm further than the last; b4, the fifth nearest, the only one that says "held"."""
    for n in range(6):
        _meet(store, f"b{n}", 0.004 * n, held=0.9 if n == 4 else 0.0)


def test_a_box_met_again_pushes_no_other_box_out_of_the_k_nearest():
    store = MemoryStore()
    _six_boxes(store)
    before = _held(store)
    assert before > 0.1  # b4 is among the k = 5 nearest
    _meet(store, "b0", -0.001, held=0.0)  # the nearest box again, perceived 1 mm off: now the nearest entry
    assert _held(store) == pytest.approx(before, abs=1e-3)  # b4 still recalled (it was pushed out: ~0.0)


def test_the_meetings_of_one_box_are_averaged_into_one_neighbour():
    twice, once = MemoryStore(), MemoryStore()
    _meet(twice, "b0", 0.0, held=0.2)
    _meet(twice, "b0", 0.0, held=0.6)
    _meet(once, "b0", 0.0, held=0.4)
    assert _held(twice) == pytest.approx(_held(once), rel=1e-12)


def test_boxes_are_told_apart_by_name_and_an_unnamed_episode_is_a_box_of_its_own():
    store = MemoryStore()
    _meet(store, "", 0.0, held=0.2)
    _meet(store, "", 0.0, held=0.6)
    bucket = store.pair_bucket("door", "slide")
    assert bucket is not None and len(set(bucket.pairs.tolist())) == 2
    _meet(store, "b0", 0.0, held=0.2)
    _meet(store, "b0", 0.0005, held=0.6)
    bucket = store.pair_bucket("door", "slide")
    assert bucket is not None and len(set(bucket.pairs.tolist())) == 3


def test_two_pairs_one_episode_stored_stay_two_pairs_however_alike_their_poses():
    keys = np.zeros((4, 12))
    boxes = [("slide", "slide", "grid")] * 4
    ids = pair_ids(keys, boxes, episodes=[1, 1, 2, 2])  # a grid box: two pairs at one relative pose, met twice
    assert len(set(ids.tolist())) == 2 and ids[0] != ids[1] and {ids[2], ids[3]} == {ids[0], ids[1]}
    far = pair_ids(np.array([[0.0] * 12, [1.0] + [0.0] * 11]), boxes[:2], episodes=[1, 2])  # 2 cm apart: two pairs
    assert far[0] != far[1]


def test_with_no_box_met_twice_the_nearest_pairs_are_the_k_nearest_entries_in_rank_order():
    rng = np.random.default_rng(0)
    for _ in range(50):
        distances = np.round(rng.uniform(0.0, 3.0, 40), 1)  # many ties
        expected = np.argsort(distances, kind="stable")[:5]
        assert nearest_pairs(distances, np.arange(40), 5).tolist() == expected.tolist()


def test_a_memory_file_recalls_its_repeated_boxes_as_it_did_before_it_was_closed(tmp_path):
    store = MemoryStore(tmp_path / "memory.sqlite")
    _six_boxes(store)
    _meet(store, "b0", -0.001, held=0.0)
    recalled = _held(store)
    store.close()
    again = MemoryStore.open_existing(tmp_path / "memory.sqlite")
    assert _held(again) == recalled
    bucket = again.pair_bucket("door", "slide")
    assert bucket is not None and len(set(bucket.pairs.tolist())) == 6


def test_layouts_of_one_name_are_boxes_of_their_own():
    store = MemoryStore()  # the paper's variants keep their name and are laid out anew for each episode
    _meet(store, "paper-train-0", 0.0, held=0.2)
    _meet(store, "paper-train-0", 0.03, held=0.6)  # the slide 3 cm further: another layout
    _meet(store, "paper-train-0", 0.0004, held=0.4)  # the first layout again, 0.4 mm off
    bucket = store.pair_bucket("door", "slide")
    assert bucket is not None and bucket.pairs.tolist() == [0, 1, 0]
