"""The bounds every command checks its numbers against, before any work: seeds, counts and sizes.

A seed is an integer in ``[0, MAX_SEED]`` (what every generator of the project takes: numpy's, torch's, MuJoCo's),
and so is the last seed a command derives from it (run ``r`` uses ``S + r``). A count (runs, episodes, specs,
views) is at least 1 and at most a bound far above any experiment's but below what exhausts the memory: a typo of
``--runs 1000000000`` is one line, not a :class:`MemoryError` minutes later. Each mistake is an
:class:`InputError` naming the flag.
"""

from __future__ import annotations

from puzzlebox.lab.errors import LabError

__all__ = [
    "MAX_ACTIONS",
    "MAX_COUNT",
    "MAX_EPISODES",
    "MAX_IMAGE_SIDE",
    "MAX_SEED",
    "MAX_TASKS",
    "MAX_VIEWS",
    "MAX_WORKERS",
    "InputError",
    "check_count",
    "check_seed",
]

MAX_SEED = 2**32 - 1
"""Largest seed (numpy's legacy generator and MuJoCo's take 32 bits; torch's 64)."""
MAX_TASKS = 1_000_000
"""Most trials one command plans (runs x specs, a sweep's grid)."""
MAX_EPISODES = 10_000_000
"""Most training episodes one command runs."""
MAX_ACTIONS = 100_000
"""Largest action budget per run."""
MAX_COUNT = 1_000_000
"""Most specs one dataset holds."""
MAX_IMAGE_SIDE = 8192
"""Largest rendered image side [px] (beyond the offscreen buffers of common GL drivers)."""
MAX_VIEWS = 1000
"""Most calibration views or turntable frames."""
MAX_WORKERS = 1024
"""Most worker processes."""


class InputError(LabError, ValueError):
    """A number on the command line or in an input file out of its range (the message names the flag)."""


def check_count(value: object, flag: str, maximum: int, minimum: int = 1) -> int:
    """``value`` is an integer (not a bool) in ``[minimum, maximum]``; returns it."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{flag} must be an integer, got {value!r}")
    if value < minimum:
        raise InputError(f"{flag} must be >= {minimum}, got {value}")
    if value > maximum:
        raise InputError(f"{flag} must be <= {maximum}, got {value}")
    return value


def check_seed(value: object, flag: str = "--seed", count: int = 1) -> int:
    """``value`` is a seed and so is ``value + count - 1`` (the last seed derived from it); returns it."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{flag} must be an integer, got {value!r}")
    if value < 0:
        raise InputError(f"{flag} must be >= 0, got {value}")
    if value + max(count, 1) - 1 > MAX_SEED:
        span = "" if count <= 1 else f" with its {count} derived seeds"
        raise InputError(f"{flag} must be <= {MAX_SEED - max(count, 1) + 1}{span}, got {value}")
    return value
