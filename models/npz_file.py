"""A file of records as one ``.npz``: a JSON header naming its format, beside named arrays, written atomically
(the toggle logs of :mod:`models.toggle_log`, the tries of ``puzzlebox.lab.try_corpus``)."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np

from puzzlebox.models.atomic import write_atomically


def save_npz(path: str | Path, header: dict[str, Any], arrays: dict[str, np.ndarray]) -> Path:
    """Write ``header`` (JSON) and ``arrays`` to ``path`` (compressed ``.npz``) atomically."""
    named = {"header": np.frombuffer(json.dumps(header).encode(), dtype=np.uint8), **arrays}

    def write(tmp: Path) -> None:
        buffer = io.BytesIO()
        # the checker matches **named against allow_pickle too: its keys are "header" and the arrays' names
        np.savez_compressed(buffer, **named)  # pyright: ignore[reportArgumentType]
        tmp.write_bytes(buffer.getvalue())

    return write_atomically(path, write)


def load_header(data: Any, path: str | Path, fmt: str, what: str) -> dict[str, Any]:
    """The header of an opened ``.npz`` (``data``, from :func:`numpy.load`) that :func:`save_npz` wrote in format
    ``fmt``.

    Raises:
        ValueError: not such a file (``what`` it should have been, and its format, are named).
    """
    try:
        header = json.loads(bytes(data["header"]).decode())
    except (KeyError, UnicodeDecodeError, json.JSONDecodeError) as err:
        raise ValueError(f"{path}: not {what} ({err})") from None
    if header.get("format") != fmt:
        raise ValueError(f"{path}: format {header.get('format')!r}, expected {fmt!r}")
    return header


__all__ = ["load_header", "save_npz"]
