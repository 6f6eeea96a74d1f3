"""A twin-learning checkpoint says what its memory copy holds, even when its chain was resumed after the copy was
taken and the memory has grown since."""

from __future__ import annotations

from puzzlebox.lab.twin_learning import checkpoint_entry, snapshot_memory
from puzzlebox.learning import MemoryAgent, SymbolicWorld, run_episode
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models.generator import TRAIN_INDICES, paper_variant


def test_a_checkpoint_reads_its_copy_not_the_store_that_grew_after_it(tmp_path):
    store = MemoryStore(tmp_path / "chain.sqlite")
    specs = [paper_variant(i, seed=0) for i in TRAIN_INDICES[:3]]
    run_episode(MemoryAgent(store, learn=True), SymbolicWorld(specs[0], 0), specs[0].name, 0, 30)
    copy = tmp_path / "chain@0h.sqlite"
    snapshot_memory(tmp_path / "chain.sqlite", copy)
    for e, spec in enumerate(specs[1:], start=1):  # the chain goes on (as a resumed chain's had, before it stopped)
        run_episode(MemoryAgent(store, learn=True), SymbolicWorld(spec, e), spec.name, e, 30)
    assert store.num_episodes == 3
    store.close()
    checkpoint = checkpoint_entry(copy, 0.0)
    assert checkpoint == {"hours": 0.0, "robot_hours": 0.0, "memory": "chain@0h.sqlite", "twin_episodes": 0,
                          "episodes": 1}  # fmt: skip
    assert checkpoint_entry(tmp_path / "chain.sqlite", 0.0)["episodes"] == 3
