"""Helpers shared by the command-line scripts: run metadata and atomic JSON output."""

from __future__ import annotations

import argparse
import importlib.util
import io
import json
import os
import platform
import sys
from collections.abc import Callable
from importlib import metadata
from pathlib import Path
from typing import Any, NoReturn

from puzzlebox.models.atomic import write_text_atomically
from puzzlebox.models.spec import dumps_compact


class OneLineParser(argparse.ArgumentParser):
    """An :class:`argparse.ArgumentParser` whose mistakes are one line on stderr, as :func:`fail`'s (``error: ...``,
    exit 2), the usage left to ``--help``: a command-line mistake is one clear line, never a screenful (its verbs'
    parsers, ``add_subparsers``, are of this class too)."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"error: {message} (see {self.prog} --help)\n")

    def parse_known_args(self, args: Any = None, namespace: Any = None) -> Any:
        """As argparse's, and an empty argument is refused: ``--out ""`` (an unset shell variable) wrote into the
        current folder, ``--specs ""`` read the folder as a spec."""
        given = list(sys.argv[1:] if args is None else args)
        for at, arg in enumerate(given):
            value = arg.split("=", 1)[1] if arg.startswith("--") and "=" in arg else arg
            if isinstance(value, str) and not value.strip():
                after = given[at - 1] if at and str(given[at - 1]).startswith("-") else ""
                self.error(f"{arg.split('=')[0] if arg.startswith('--') else after or 'an argument'} is empty "
                           "(an unset shell variable?)")  # fmt: skip
        return super().parse_known_args(given, namespace)


def versions() -> dict[str, str]:
    """Versions of Python and the packages a result depends on (written beside every result)."""
    out = {"python": platform.python_version()}
    for package in ("puzzlebox", "numpy", "scipy", "gymnasium", "mujoco"):
        try:
            out[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            out[package] = "not installed"
    return out


def write_json(path: Path, data: Any) -> Path:
    """Write JSON atomically (a crash never leaves a half-written file)."""
    return write_text_atomically(path, dumps_compact(data) if isinstance(data, dict) else json.dumps(data, indent=2))


def one_line(err: Exception) -> str:
    """An error's message on one line (for ``fail`` and logs)."""
    return " ".join(line.strip() for line in str(err).splitlines())


class _StdoutThatMayClose:
    """``sys.stdout`` for a script whose reader may go away (``| head -1``): once the pipe is closed, the rest of
    what the script prints is dropped (the descriptor is pointed at ``os.devnull``) and the script goes on."""

    def __init__(self, stream: Any) -> None:
        self._stream = stream

    def _guarded(self, call: Callable[[], Any]) -> Any:
        try:
            return call()
        except BrokenPipeError:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self._stream.fileno())  # (what is still buffered goes there too, at exit)
            os.close(devnull)
            return None

    def write(self, text: str) -> int:
        self._guarded(lambda: self._stream.write(text))
        return len(text)

    def flush(self) -> None:
        self._guarded(self._stream.flush)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def run_script(main: Callable[[], int | None]) -> NoReturn:
    """Run a script's ``main`` and exit with its code. A reader that closes stdout early (``... | head -1``) ends
    nothing: the script finishes its work and writes every file, and what it would still print is dropped. A path
    that is not UTF-8 (a byte the shell passed as is) is printed escaped, never a ``UnicodeEncodeError``."""
    for stream in (sys.stdout, sys.stderr):
        if isinstance(stream, io.TextIOWrapper):
            stream.reconfigure(errors="backslashreplace")
    sys.stdout = _StdoutThatMayClose(sys.stdout)
    raise SystemExit(main())


def fail(message: str, code: int = 2) -> NoReturn:
    """Print ``error: message`` on stderr, on one line (a message of several lines, e.g. every problem of a spec, is
    joined), and exit (no traceback for a user's mistake)."""
    print(f"error: {' '.join(line.strip() for line in message.splitlines() if line.strip())}", file=sys.stderr)
    raise SystemExit(code)


def scripts_folder() -> Path:
    """The folder of the command-line scripts (``puzzlebox.scripts``), found without importing them: the library
    runs them in processes of their own, as a user would (a fault suite, an experiment of several commands)."""
    spec = importlib.util.find_spec("puzzlebox.scripts")
    if spec is None or not spec.submodule_search_locations:
        raise ModuleNotFoundError("puzzlebox.scripts is not installed (pip install -e . from the repository)")
    return Path(next(iter(spec.submodule_search_locations))).resolve()
