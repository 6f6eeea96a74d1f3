"""Atomic file writes: a crash or an interrupted run never leaves a half-written file behind.

The data goes to a temporary file with a unique name in the target's directory (so two writers of one
path never share a temporary, and the rename stays on one file system), is flushed to disk (``fsync``)
and then renamed over the target in one step (``os.replace``). A failed write removes its temporary.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Self


def current_umask() -> int:
    """The process's umask, read without changing it where Linux tells it (``/proc/self/status``), else by setting
    and restoring it."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    umask = os.umask(0o022)
    os.umask(umask)
    return umask


def apply_umask(path: str | Path, mode: int = 0o666) -> None:
    """Give ``path`` the permissions a plain ``open()`` (``mode``) would have given it under the process's umask:
    a file made by ``mkstemp`` (0600) and published under its final name is not private."""
    os.chmod(path, mode & ~current_umask())


def write_atomically(path: str | Path, write: Callable[[Path], object]) -> Path:
    """Call ``write(tmp)`` on a fresh temporary file beside ``path`` (parents created), flush it to disk,
    then rename it to ``path`` in one step; on any error the temporary is removed and the error raised."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    tmp = Path(name)
    try:
        apply_umask(tmp)  # mkstemp makes it 0600
        write(tmp)
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        raise
    return path


def write_text_atomically(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically. A lone surrogate (a byte of a non-UTF-8 path, as Python decodes
    command-line arguments) is written as its escape ``\\udcff``: in JSON that escape reads back to the same string
    (the path round-trips); in Markdown and HTML it is shown as is. Strict UTF-8 ended ``trial.py --out`` such a path
    in a ``UnicodeEncodeError`` traceback."""
    return write_atomically(path, lambda tmp: tmp.write_text(text, encoding="utf-8", errors="backslashreplace"))


class PublishedOnExit:
    """A writer used in a ``with`` block: on a clean exit :meth:`close` publishes what it wrote, on an error
    :meth:`abort` discards it (a crash never leaves a half-made output). Subclasses define both."""

    def close(self) -> object:
        raise NotImplementedError

    def abort(self) -> None:
        raise NotImplementedError

    def __enter__(self) -> Self:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, *exc_info: object) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()
