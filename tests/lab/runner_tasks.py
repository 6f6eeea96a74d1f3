"""Task functions for the runner tests: module-level, so that workers (spawned, or Ray's) import them."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import numpy as np


def draws(settings):
    """A seeded record: the same on every executor."""
    rng = np.random.default_rng(settings["seed"])
    return {"seed": settings["seed"], "draws": rng.random(4).tolist(), "solved": bool(settings["seed"] % 2)}


def fails_on_three(settings):
    if settings["seed"] == 3:
        raise ValueError("seed 3 is cursed")
    return draws(settings)


def dies_once(settings):
    """SIGKILLs its own worker the first time it runs (a flag file remembers), then returns its record."""
    flag = Path(settings["flag"])
    if not flag.exists():
        flag.write_text("died")
        os.kill(os.getpid(), signal.SIGKILL)
    return draws(settings)


def always_dies(settings):
    os.kill(os.getpid(), signal.SIGKILL)


def sleeps(settings):
    time.sleep(settings["seconds"])
    return draws(settings)


def noop(settings):
    return {}
