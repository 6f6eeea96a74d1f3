"""Atomic writes: unique temporaries, nothing left behind on failure, concurrent writers both succeed."""

from __future__ import annotations

import threading

import pytest

from puzzlebox.models.atomic import write_atomically, write_text_atomically


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "results.json"
    write_text_atomically(target, "old")

    def broken(tmp):
        tmp.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        write_atomically(target, broken)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.json"]


def test_concurrent_writers_of_one_path_never_share_a_temporary(tmp_path):
    target = tmp_path / "log.json"
    errors: list[BaseException] = []

    def writer(k: int) -> None:
        try:
            for i in range(50):
                write_text_atomically(target, f"{k}:{i}")
        except BaseException as err:  # noqa: BLE001 - collected and asserted below
            errors.append(err)

    threads = [threading.Thread(target=writer, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert target.read_text().endswith(":49")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.json"]


def test_the_written_file_has_ordinary_permissions(tmp_path):
    target = write_text_atomically(tmp_path / "a.txt", "x")
    plain = tmp_path / "b.txt"
    plain.write_text("x")
    assert target.stat().st_mode == plain.stat().st_mode  # mkstemp alone makes 0600
