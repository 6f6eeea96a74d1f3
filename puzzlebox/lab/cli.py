"""Helpers shared by the command-line scripts: run metadata and atomic JSON output."""

from __future__ import annotations

import argparse
import importlib.util
import json
import platform
import sys
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
