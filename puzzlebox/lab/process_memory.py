"""The resident memory of a process that runs many twin trials, read and given back between trials.

What a twin trial leaves behind is bounded by the process caches (``twin.scene_cache``: 4 compiled scenes,
``twin.renderer_pool``: 2 idle renderers, the mechanism layouts, the true cameras' rays), yet a worker's resident
memory kept growing, ~50 MB per trial over the first dozen trials of paper boxes under ``realistic`` (469 MB after
trial 1, 1034 MB after trial 12, a full collection after each; issue 37): memory the trials had freed stayed in
the C allocator's heaps (glibc keeps freed chunks for reuse, and the compiled scenes' collision data, rendered
frames and MJCF trees come and go in blocks of every size), and each scene's MJCF tree holds reference cycles
that only a collection frees. :func:`release_freed_memory` after each trial frees the cycles and hands the freed
pages back to the OS (``malloc_trim``): ``bench.py --only soak --trials 200`` measured 679 MB after trial 20 and
701 MB after trial 200 (+22 MB; the bound is 50).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
import gc
import math
from collections.abc import Callable

__all__ = ["release_freed_memory", "resident_mb"]


def resident_mb() -> float:
    """This process's resident memory now [MB] (``VmRSS`` of ``/proc/self/status``; NaN where there is none)."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024  # reported in kB
    except (OSError, ValueError):
        pass
    return math.nan


@functools.cache
def _malloc_trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim`` (None elsewhere: musl, macOS, Windows return freed memory on their own terms)."""
    name = ctypes.util.find_library("c")
    try:
        libc = ctypes.CDLL(name)
        trim = libc.malloc_trim
    except (OSError, AttributeError, TypeError):
        return None
    trim.argtypes, trim.restype = [ctypes.c_size_t], ctypes.c_int
    return trim


def release_freed_memory() -> None:
    """Collect garbage in cycles, then give the allocator's free pages back to the OS (a few ms to ~0.1 s: run
    it between trials, not inside one)."""
    gc.collect()
    trim = _malloc_trim()
    if trim is not None:
        trim(0)  # 0: keep no padding at the top of the heap
