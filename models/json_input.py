"""Reading a JSON input file the one way every loader does: bounded in size and depth, each problem one sentence.

``json.loads`` raises :class:`RecursionError` on a value nested a few thousand levels deep (and code walking a
value nested a few hundred deep may too); a file of gigabytes is read whole. :func:`read_json` refuses both up
front with :class:`JsonInputError` (a :class:`ValueError`), as it refuses a file that cannot be read, is not UTF-8
or is not JSON, so that each loader (specs, calibrations, cell configs, reality profiles, sweep files, checkpoint
metadata) wraps one exception into its own typed error. Numbers that JSON cannot hold (``NaN``, ``Infinity``,
which Python's parser accepts) are refused too, unless asked for.
"""

from __future__ import annotations

import json
import math
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = [
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "JsonInputError",
    "depth_of",
    "finite",
    "parse_json",
    "read_input_text",
    "read_json",
]

MAX_DEPTH = 64
"""Deepest nesting of arrays and objects any input file of the project may have (a spec has 4 levels)."""

MAX_FILE_BYTES = 64 * 1024 * 1024
"""Largest input file read [bytes]."""


class JsonInputError(ValueError):
    """A JSON input that cannot be used (the message says why, in one sentence, without the file's name)."""


def depth_of(value: Any, limit: int = MAX_DEPTH) -> int:
    """How deep arrays and objects nest in ``value`` (a scalar is 0), counted without recursion; stops counting
    past ``limit`` (returns ``limit + 1``)."""
    deepest = 0
    stack: list[tuple[Any, int]] = [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict | list):
            depth += 1
            deepest = max(deepest, depth)
            if deepest > limit:
                return deepest
            stack.extend((child, depth) for child in (item.values() if isinstance(item, dict) else item))
    return deepest


def _no_constant(name: str) -> float:
    raise JsonInputError(f"{name} is not a JSON number (use a finite number)")


def parse_json(
    text: str,
    *,
    object_pairs_hook: Callable[[list[tuple[str, Any]]], Any] | None = None,
    allow_non_finite: bool = False,
    max_depth: int = MAX_DEPTH,
) -> Any:
    """Parse ``text``: :class:`JsonInputError` for invalid JSON, nesting deeper than ``max_depth``, or (unless
    ``allow_non_finite``) ``NaN``/``Infinity``. Errors of ``object_pairs_hook`` pass through."""
    constant = (lambda name: float(name)) if allow_non_finite else _no_constant
    try:
        value = json.loads(text, object_pairs_hook=object_pairs_hook, parse_constant=constant)
    except json.JSONDecodeError as err:
        raise JsonInputError(f"not valid JSON: {err.msg} at line {err.lineno} column {err.colno}") from None
    except RecursionError:
        raise JsonInputError(f"nested too deep (arrays and objects deeper than {max_depth} levels)") from None
    if depth_of(value, max_depth) > max_depth:
        raise JsonInputError(f"nested too deep (arrays and objects deeper than {max_depth} levels)")
    return value


def read_json(path: str | Path, **options: Any) -> Any:
    """Read and parse the JSON file ``path`` (:func:`parse_json`'s ``options``); :class:`JsonInputError` if it
    cannot be read, is larger than :data:`MAX_FILE_BYTES`, is not UTF-8 or not JSON."""
    return parse_json(read_input_text(path), **options)


def read_input_text(path: str | Path) -> str:
    """The text of the input file ``path``; :class:`JsonInputError` if it is not a regular file (a device, a FIFO,
    a socket: ``/dev/zero`` was read until the kernel stopped it, a FIFO blocked for ever), cannot be read, is larger
    than :data:`MAX_FILE_BYTES` or is not UTF-8. At most that many bytes are read, whatever the file claims."""
    path = Path(path)
    try:
        mode = path.stat().st_mode  # (follows a link: a link to a device is a device)
        if stat.S_ISDIR(mode):
            raise IsADirectoryError
        if not stat.S_ISREG(mode):
            raise JsonInputError("not a regular file (a device, a FIFO or a socket)")
        with path.open("rb") as file:
            data = file.read(MAX_FILE_BYTES + 1)
        if len(data) > MAX_FILE_BYTES:
            raise JsonInputError(f"too large (over {MAX_FILE_BYTES} bytes)")
        text = data.decode("utf-8")
    except FileNotFoundError:
        raise JsonInputError("no such file") from None
    except IsADirectoryError:
        raise JsonInputError("a directory, not a file") from None
    except UnicodeDecodeError:
        raise JsonInputError("not UTF-8 text") from None
    except OSError as err:
        raise JsonInputError(f"cannot read it ({err.strerror or err})") from None
    return text


def finite(value: Any) -> bool:
    """``value`` is a real number (not a bool) and finite."""
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
