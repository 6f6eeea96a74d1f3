"""The soak of ``bench.py --only soak`` and what keeps a long worker's memory bounded: garbage in cycles is freed
between trials, the resident memory is read, the soak varies its boxes, keeps every point as it goes and judges
the growth from trial ``reference`` to the last against its bound (issue 37)."""

from __future__ import annotations

import functools
import gc
import json
import math
import subprocess
import sys
import weakref
from types import SimpleNamespace

from puzzlebox.lab import process_memory
from puzzlebox.lab.bench_soak import SoakConfig, SoakPoint, soak_boxes, soak_verdict
from puzzlebox.scripts import bench


class _Node:
    other: _Node | None = None


def test_releasing_freed_memory_frees_garbage_held_in_cycles():
    enabled = gc.isenabled()
    gc.disable()  # only the release may collect it
    try:
        a, b = _Node(), _Node()
        a.other, b.other = b, a
        gone = weakref.ref(a)
        del a, b
        assert gone() is not None
        process_memory.release_freed_memory()
        assert gone() is None
    finally:
        if enabled:
            gc.enable()


_RESIDENT_PROBE = """
import json
from puzzlebox.lab import process_memory
before = process_memory.resident_mb()
block = bytearray(b"\\x01") * (64 << 20)  # 64 MiB, every page written: resident
held = process_memory.resident_mb()
del block
process_memory.release_freed_memory()
print(json.dumps([before, held, process_memory.resident_mb()]))
"""


def test_the_resident_memory_is_read_in_megabytes():
    # In a fresh interpreter: a test worker that has run hundreds of tests may have pages reclaimed or freed by
    # its other threads between two readings (CI read +50 MB for a 64 MiB block in a 1.6 GB worker).
    probe = subprocess.run([sys.executable, "-c", _RESIDENT_PROBE], capture_output=True, text=True, check=True)
    before, held, after = json.loads(probe.stdout)
    assert math.isfinite(before) and 60 < held - before < 80, (before, held)  # 64 MiB
    assert held - after > 60, (held, after)  # and given back once freed


def _points(*rss: float) -> list[SoakPoint]:
    return [SoakPoint(k, "box", k - 1, True, 3, 1.0, value) for k, value in enumerate(rss, start=1)]


def test_the_verdict_compares_the_last_trial_with_the_reference_one():
    config = SoakConfig(trials=5, reference=2, bound_mb=50.0)
    held = soak_verdict(_points(400, 600, 620, 640, 649), config)
    assert held["holds"] is True and held["growth_mb"] == 49 and held["reference_rss_mb"] == 600
    grew = soak_verdict(_points(400, 600, 620, 640, 651), config)
    assert grew["holds"] is False and grew["per_trial_mb"] == 51 / 3
    early = soak_verdict(_points(400), config)
    assert early["holds"] is None and early["trials_run"] == 1 and len(early["points"]) == 1


def test_the_soak_mixes_paper_and_random_boxes_each_trial_seeded_anew():
    paper = list(soak_boxes(SoakConfig(trials=2, random_every=0)))
    assert [seed for _, seed in paper] == [0, 1]
    assert all(spec.name.startswith("paper-") for spec, _ in paper) and paper[0][0].name != paper[1][0].name
    ((random, seed),) = soak_boxes(SoakConfig(trials=1, random_every=1))  # the smallest random box (3 components)
    assert random.name.startswith("random-") and len(random.components) == 3 and seed == 0


def test_bench_only_soak_keeps_each_trial_in_its_file_as_it_goes(tmp_path, monkeypatch, capsys):
    written = []
    ran = iter(range(1, 100))

    def fake_trial(spec, config):  # the soak's bookkeeping, not the twin: no trial runs here
        return SimpleNamespace(solved=True, num_actions=2, wall_time_s=0.5)

    def keep_file(path, data):
        written.append(len(data["soak"]["points"]))
        return real_write(path, data)

    monkeypatch.setattr("puzzlebox.lab.trials.run_trial", fake_trial)
    monkeypatch.setattr("puzzlebox.lab.bench_soak.resident_mb", lambda: 500.0 + next(ran))
    real_write = bench.write_json
    monkeypatch.setattr(bench, "write_json", keep_file)
    monkeypatch.setattr(bench, "SoakConfig", functools.partial(SoakConfig, random_every=0))  # paper boxes: fast
    out = tmp_path / "soak.json"
    assert bench.main(["--only", "soak", "--trials", "3", "--out", str(out)]) == 0
    assert written == [1, 2, 3, 3]  # after every trial, then the verdict
    soak = json.loads(out.read_text())["soak"]
    assert [p["rss_mb"] for p in soak["points"]] == [501.0, 502.0, 503.0]
    assert soak["holds"] is None  # fewer trials than the reference one (20)
    assert capsys.readouterr().out.count("soak trial") == 3
