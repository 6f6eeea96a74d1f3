"""Stop a long command cleanly: the first Ctrl-C (SIGINT) or SIGTERM asks it to stop after the current
unit of work; a second one aborts that unit at once (:class:`KeyboardInterrupt`)."""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable
from types import FrameType
from typing import Any

_Handler = Callable[[int, FrameType | None], Any] | int | signal.Handlers | None
"""What ``signal.signal`` installs and returns: a function, ``SIG_DFL``/``SIG_IGN``, or None (not set from Python)."""


class StopRequests:
    """Context manager installing the handlers; :attr:`requested` is set by the first signal."""

    def __init__(self, what: str = "run") -> None:
        self.what = what
        self.requested = False
        self._previous: dict[int, _Handler] = {}

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True
        name = signal.Signals(signum).name
        print(f"\n{name}: stopping after the current {self.what} (again to stop at once)", file=sys.stderr, flush=True)

    def __enter__(self) -> StopRequests:
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._previous[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
