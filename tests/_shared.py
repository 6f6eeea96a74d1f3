"""Outputs several test modules read, made once per test session whatever the worker that first asks.

pytest-xdist runs a module-scoped fixture once per worker that runs one of the module's tests, and a
session-scoped one once per worker; an output two modules need (a twin trial with its video) would be made
twice. :func:`shared_output` makes it once in the directory the workers share, under a file lock; a reader that
changes what it got copies it first (:func:`private_copy`).
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from filelock import FileLock

DONE = ".made"
"""Written last into a shared output: a maker that failed part-way leaves no such file, and the next asks again."""


def shared_output(factory: pytest.TempPathFactory, name: str, make: Callable[[Path], None]) -> Path:
    """The folder ``name`` made by ``make(folder)`` once per test session (under xdist: for every worker)."""
    base = factory.getbasetemp()
    root = base.parent if base.name.startswith("popen-gw") else base  # xdist: the workers' common folder
    folder = root / f"shared-{name}"
    with FileLock(str(folder) + ".lock"):
        if not (folder / DONE).exists():
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir(parents=True)
            make(folder)
            (folder / DONE).touch()
    return folder


def private_copy(shared: Path, target: Path) -> Path:
    """A copy of a shared output at ``target``, for a reader that writes into it."""
    shutil.copytree(shared, target, ignore=shutil.ignore_patterns(DONE))
    return target


ROOT = Path(__file__).resolve().parents[1]


def _make_video_trial(folder: Path) -> None:
    import subprocess
    import sys

    specs = folder / "specs"
    subprocess.run([sys.executable, str(ROOT / "scripts/generate.py"), "paper", "--split", "test", "--out",
                    str(specs)], check=True, capture_output=True)  # fmt: skip
    for name, extra in (("video", ["--video"]), ("plain", [])):
        done = subprocess.run(
            [sys.executable, str(ROOT / "scripts/trial.py"), "--specs", str(specs / "paper-test-1.json"), "--sim",
             "twin", "--agent", "oracle", "--runs", "1", "--seed", "3", "--max-actions", "3", "--out",
             str(folder / name), "--workers", "1", *extra],
            capture_output=True, text=True, timeout=600,
        )  # fmt: skip
        assert done.returncode == 0, done.stderr[-2000:]


def video_trial(factory: pytest.TempPathFactory) -> Path:
    """One twin trial with ``--video`` (``video/``) and the same trial without (``plain/``): paper-test-1 (in
    ``specs/``), the oracle agent, seed 3, its first 3 actions (a video costs ~7x its trial; three show every kind of
    frame)."""
    return shared_output(factory, "video-trial", _make_video_trial)
