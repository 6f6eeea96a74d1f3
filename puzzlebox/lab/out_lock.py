"""An output owned by one process at a time: an OS lock (``fcntl.flock``) on a lock file, held for the whole run.

A directory ``DIR`` is locked through ``DIR/.lock``, a file output ``FILE`` through ``.FILE.lock`` beside it. The
lock file holds the owner's pid and command line, so that a second writer is refused in one line naming who holds
it (:class:`~puzzlebox.lab.errors.OutputInUse`) before it reads, removes or writes anything there. The kernel
drops the lock when its holder exits, however it ends (a SIGKILL included); a lock file a killed holder left is
taken over by the next writer. A normal release removes the lock file (under the lock, so that no two processes
ever hold locks on two generations of it).

Within one process the lock is re-entrant (a command that locked its ``--out`` may open a
:class:`~puzzlebox.lab.run_store.RunStore` on it): it is released when every holder released it, or when the
process exits. The lock is never passed on to child processes (its descriptor is not inheritable, and the
runner's workers are spawned).
"""

from __future__ import annotations

import atexit
import errno
import fcntl
import json
import os
import shlex
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from puzzlebox.lab.errors import OutputInUse, OutputNotADirectory, OutputNotWritable

__all__ = ["OutputLock", "command_line", "lock_path"]

LOCK_NAME = ".lock"


def lock_path(out: Path, directory: bool = True) -> Path:
    """The lock file of an output: ``DIR/.lock`` for a directory, ``.FILE.lock`` beside a file."""
    return out / LOCK_NAME if directory else out.parent / f".{out.name}.lock"


def command_line(limit: int = 300) -> str:
    """This process's command line, as the lock file records it (shortened to ``limit`` characters)."""
    argv = [Path(sys.argv[0]).name if sys.argv and sys.argv[0] else "python", *sys.argv[1:]]
    text = shlex.join(argv)
    return text if len(text) <= limit else text[: limit - 3] + "..."


@dataclass
class _Held:
    fd: int
    count: int
    pid: int


_HELD: dict[str, _Held] = {}
"""The locks this process holds, by lock file (re-entrant)."""


def _holder(path: Path) -> str:
    """Who holds ``path`` as its file says (pid and command), read a few times while a new holder writes it."""
    for _ in range(20):
        try:
            info = json.loads(path.read_text(encoding="utf-8"))
            return f"pid {int(info['pid'])}: {info.get('command', '?')}"
        except (OSError, ValueError, KeyError, TypeError):
            time.sleep(0.01)
    return "pid unknown"


class OutputLock:
    """The lock of ``out`` (a directory, or a file with ``directory=False``), taken at construction; ``what`` names
    the flag in messages (``--out``, ``--checkpoint``). Raises :class:`OutputInUse` if another process holds it,
    :class:`OutputNotADirectory` if a directory output is a file, :class:`OutputNotWritable` if the lock file
    cannot be made there. A context manager; :meth:`release` is idempotent."""

    def __init__(self, out: Path, *, directory: bool = True, what: str = "--out") -> None:
        self.out, self.what = Path(out), what
        if directory and self.out.exists() and not self.out.is_dir():
            raise OutputNotADirectory(f"{what} {self.out} is a file, not a directory")
        if not directory and self.out.is_dir():
            raise OutputNotADirectory(f"{what} {self.out} is a directory; give a file name")
        self.path = lock_path(self.out, directory)
        try:
            self._key = str(self.path.resolve())
        except RuntimeError as err:  # (Python 3.11 raises this for a loop of symbolic links)
            raise OutputNotWritable(f"{what} {self.out}: a loop of symbolic links") from err
        self._released = False
        held = _HELD.get(self._key)
        if held is not None and held.pid == os.getpid():
            held.count += 1
            return
        _HELD[self._key] = _Held(self._acquire(), 1, os.getpid())

    def _acquire(self) -> int:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise OutputNotWritable(f"{self.what} {self.out}: cannot create it ({err.strerror})") from err
        while True:
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
            except OSError as err:
                raise OutputNotWritable(f"{self.what} {self.out}: cannot write there ({err.strerror})") from err
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as err:
                os.close(fd)
                if err.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise OutputNotWritable(f"{self.what} {self.out}: cannot lock it ({err.strerror})") from err
                raise OutputInUse(
                    f"{self.what} {self.out} is in use by another process ({_holder(self.path)}); wait for it to "
                    f"end or give another {self.what}"
                ) from None
            try:  # the file may have been released (unlinked) between our open and our lock: lock the current one
                same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if not same:
                os.close(fd)
                continue
            try:
                os.ftruncate(fd, 0)
                os.write(fd, json.dumps({"pid": os.getpid(), "command": command_line()}).encode())
            except OSError as err:  # a full disk: the lock holds, its file just says less
                if err.errno != errno.ENOSPC:
                    os.close(fd)
                    raise OutputNotWritable(f"{self.what} {self.out}: cannot write there ({err.strerror})") from err
            return fd

    def release(self) -> None:
        if self._released:
            return
        self._released = True
        held = _HELD.get(self._key)
        if held is None:
            return
        held.count -= 1
        if held.count > 0:
            return
        del _HELD[self._key]
        if held.pid == os.getpid():  # removed while still locked: a waiting opener sees a new file, not ours
            try:
                self.path.unlink(missing_ok=True)
            except OSError:
                pass
        os.close(held.fd)

    def __enter__(self) -> OutputLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def __del__(self) -> None:
        try:
            self.release()
        except Exception:  # noqa: BLE001 - at interpreter exit the modules may be gone
            pass


@atexit.register
def _release_all() -> None:
    """Remove this process's lock files at a normal exit (the kernel drops the locks anyway)."""
    for key, held in list(_HELD.items()):
        if held.pid == os.getpid():
            Path(key).unlink(missing_ok=True)
            os.close(held.fd)
    _HELD.clear()
