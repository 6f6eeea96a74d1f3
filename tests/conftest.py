"""Shared fixtures: the SPEC.md example as a dict, and a writer for spec files; the longest tests first
(:mod:`_schedule`)."""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # headless rendering, before anything imports mujoco

import copy
import json
import os
from pathlib import Path
from typing import Any

import pytest
from _schedule import load_costs, order_longest_first, recording
from hypothesis import settings

# CI explores the same examples every run (a failure there is reproducible); local runs explore anew.
settings.register_profile("ci", derandomize=True, deadline=None)
settings.register_profile("fuzz", max_examples=5000, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "default"))

SPEC_EXAMPLE: dict[str, Any] = {
    "format": "puzzlebox-spec/1",
    "name": "paper-test-0",
    "box": {"size": [0.40, 0.30, 0.08], "pose": [0.45, 0.0, 0.0]},
    "components": [
        {"name": "door-1", "kind": "door", "pose": [-0.12, 0.05, 0.0], "marker": 0},
        {"name": "slide-1", "kind": "slide", "pose": [-0.02, 0.05, 1.5708], "marker": 1},
    ],
    "locks": [
        {"locker": "door-1", "locker_state": 0, "locked": "slide-1", "locked_state": 0},
        {"locker": "slide-1", "locker_state": 1, "locked": "door-1", "locked_state": 1},
    ],
    "goal": {"component": "slide-1", "state": 1},
}


SCENE_EXAMPLE: dict[str, Any] = {
    "format": "puzzlebox-spec/1",
    "name": "small-computer",
    "components": [
        {"name": "s1", "kind": "screw", "pose": [0.0, 0.0, 0.0, 0, 0, 0]},
        {"name": "s2", "kind": "screw", "pose": [0.0, 0.0, -0.37, 0, 0, 0]},
        {"name": "panel", "kind": "panel", "pose": [-0.23, 0.02, -0.2, 0, 0, 1.5708]},
        {"name": "ram", "kind": "ram", "pose": [-0.17, -0.14, -0.07, 0, 0, 1.5708]},
        {"name": "board", "kind": "motherboard", "pose": [-0.12, -0.15, -0.1, 0, 0, 1.5708]},
    ],
    "locks": [
        {"locker": "s1", "locker_state": 0, "locked": "panel", "locked_state": 0},
        {"locker": "s2", "locker_state": 0, "locked": "panel", "locked_state": 0},
        {"locker": "panel", "locker_state": 0, "locked": "ram", "locked_state": 0},
        {"locker": "ram", "locker_state": 0, "locked": "board", "locked_state": 0},
    ],
    "goal": {"component": "board", "state": 1},
}
"""A small disassembly scene (no box, 6-DOF poses): two screws hold the panel, the panel the RAM, the RAM the
board."""


@pytest.fixture
def spec_dict() -> dict[str, Any]:
    """A fresh deep copy of the SPEC.md example (valid)."""
    return copy.deepcopy(SPEC_EXAMPLE)


@pytest.fixture
def scene_dict() -> dict[str, Any]:
    """A fresh deep copy of :data:`SCENE_EXAMPLE` (a valid disassembly scene)."""
    return copy.deepcopy(SCENE_EXAMPLE)


@pytest.fixture
def write_spec(tmp_path: Path):
    """Write a dict (or raw text) to a file in tmp_path and return its path."""

    def write(data: Any, name: str = "spec.json") -> Path:
        path = tmp_path / name
        path.write_text(data if isinstance(data, str) else json.dumps(data))
        return path

    return write


def pytest_collection_modifyitems(config, items):
    order_longest_first(items, load_costs())


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    with recording(item):
        yield
