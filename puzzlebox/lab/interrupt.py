"""Stop a long command cleanly: the first Ctrl-C (SIGINT) or SIGTERM asks it to stop after the current
unit of work; a second one aborts that unit at once (:class:`KeyboardInterrupt`). A command of many nested units,
each saved as it ends (``experiment.py``), stops at once instead (:class:`AbortOnSignal`)."""

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
        self._signum: int | None = None
        self._previous: dict[int, _Handler] = {}

    def __enter__(self) -> StopRequests:
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._previous[sig] = signal.signal(sig, self._handle)
        return self

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True
        self._signum = signum
        name = signal.Signals(signum).name
        print(f"\n{name}: stopping after the current {self.what} (again to stop at once)", file=sys.stderr, flush=True)

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        # inside a command that stops at once (AbortOnSignal): the unit is done, now the command stops too
        previous = self._previous.get(self._signum) if self._signum is not None else None
        if self.requested and exc[0] is None and isinstance(getattr(previous, "__self__", None), AbortOnSignal):
            assert callable(previous) and self._signum is not None
            previous(self._signum, None)


class Interrupted(BaseException):  # noqa: N818 - what it is, as KeyboardInterrupt
    """A stop signal arrived under :class:`AbortOnSignal` (a :class:`BaseException`: no ``except Exception`` on
    the way swallows it); :attr:`signal_name` names it."""

    def __init__(self, signum: int) -> None:
        self.signal_name = signal.Signals(signum).name
        super().__init__(f"{self.signal_name}: stopped")


class AbortOnSignal:
    """Context manager for a command whose units of work are saved as they end (``experiment.py``'s jobs, records
    and steps): SIGINT or SIGTERM raises :class:`Interrupted` at once — whatever the process inherited (a SIGINT
    ignored by a shell's ``&`` or ``nohup`` included) — so the command ends in one line and what finished is
    kept. Inside it, a :class:`StopRequests` scope still finishes its current unit first, then the command stops."""

    def __init__(self) -> None:
        self._previous: dict[int, _Handler] = {}

    def _handle(self, signum: int, frame: FrameType | None) -> None:
        for sig in self._previous:  # a second signal while unwinding is ignored: the first one is being obeyed
            signal.signal(sig, signal.SIG_IGN)
        raise Interrupted(signum)

    def __enter__(self) -> AbortOnSignal:
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._previous[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
