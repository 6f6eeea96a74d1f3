"""Every file the project publishes gets the permissions a plain ``open()`` gives under the process's umask: written
under a private temporary name (``mkstemp``: 0600) and renamed, it is made readable as the umask allows first —
videos, Rerun recordings, atomic writes, memory files and their snapshots."""

import os
import stat
from pathlib import Path

import numpy as np
import pytest

from puzzlebox.lab.twin_learning import snapshot_memory
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models.atomic import current_umask, write_text_atomically
from puzzlebox.twin.video import VideoWriter


@pytest.fixture(params=[0o027, 0o002])
def umask(request):
    previous = os.umask(request.param)
    try:
        yield request.param
    finally:
        os.umask(previous)


def mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def test_the_umask_is_read_without_changing_it(umask):
    assert current_umask() == umask
    assert current_umask() == umask


def test_atomic_writes_videos_and_memory_files_follow_the_umask(umask, tmp_path):
    expected = 0o666 & ~umask
    assert mode(write_text_atomically(tmp_path / "a.json", "{}")) == expected
    with VideoWriter(tmp_path / "v.mp4", fps=5) as video:
        video.append(np.zeros((16, 16, 3), dtype=np.uint8))
    assert mode(tmp_path / "v.mp4") == expected
    store = MemoryStore(tmp_path / "mem.sqlite")
    store.close()
    assert mode(tmp_path / "mem.sqlite") == expected
    snapshot_memory(tmp_path / "mem.sqlite", tmp_path / "snapshot.sqlite")
    assert mode(tmp_path / "snapshot.sqlite") == expected
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary left behind


def test_a_rerun_recording_follows_the_umask(umask, tmp_path):
    pytest.importorskip("rerun")
    from puzzlebox.twin.rerun_log import TrialRecording

    with TrialRecording(tmp_path / "a.rrd", "test") as recording:
        recording.at(0.5)
        recording.decision("action 1: try x", 0.5)
    assert mode(tmp_path / "a.rrd") == 0o666 & ~umask
