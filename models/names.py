"""One rule for names: what a spec may call itself and its parts, and the file-name part derived from any name.

A name (a spec's, a component's, an agent's label, a profile's) is any text validation accepts
(:func:`name_problem`: non-empty, at most :data:`MAX_NAME_LENGTH` characters, no control characters): spaces,
unicode, HTML, ``/`` or ``..`` included. No command ever makes a file name or a record key of a name itself:
:func:`name_slug` gives the part of a key or file name that stands for it — the name when it is already a plain
file name (ASCII letters, digits, ``._-``, not hidden, no ``..``: existing results keep their keys), else a slug of
it and a short hash of the whole name (two names never share a slug). :data:`KEY_PATTERN` is what a record key
(``DIR/runs/KEY.json``) may be; every key made of slugs matches it. Validation (``models.validation``) and the
task runner (``puzzlebox.lab.runner``) both use this module.
"""

from __future__ import annotations

import hashlib
import re
import unicodedata

__all__ = ["KEY_PATTERN", "MAX_NAME_LENGTH", "MAX_SLUG_LENGTH", "is_key", "name_problem", "name_slug"]

MAX_NAME_LENGTH = 200
"""Longest name [characters]."""
MAX_SLUG_LENGTH = 48
"""Longest slug [characters] (a key joins several, within a file name's 255 bytes)."""
KEY_PATTERN = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9._+=@-]{0,199}$")
"""A record key: a file name of letters, digits and ``._+=@-``, not hidden, at most 200 characters."""

_PLAIN = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9._-]*$")
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")


def name_problem(name: object) -> str | None:
    """Why ``name`` is not a name (None: it is)."""
    if not isinstance(name, str) or not name:
        return "missing or not a non-empty string"
    if len(name) > MAX_NAME_LENGTH:
        return f"longer than {MAX_NAME_LENGTH} characters ({len(name)})"
    if _CONTROL.search(name):
        return "holds a control character (a newline, a tab, NUL...)"
    return None


def is_key(key: str) -> bool:
    """``key`` may name a record file (:data:`KEY_PATTERN`)."""
    return bool(KEY_PATTERN.match(key))


def name_slug(name: str) -> str:
    """The file-name part that stands for ``name`` (see the module docstring): ``paper-test-0`` stays
    ``paper-test-0``; ``a box/ü`` becomes ``a-box-u-`` plus 8 hex digits of the name's SHA-256."""
    if len(name) <= MAX_SLUG_LENGTH and _PLAIN.match(name) and ".." not in name:
        return name
    ascii_text = unicodedata.normalize("NFKD", name).encode("ascii", "ignore").decode()
    slug = re.sub(r"[^A-Za-z0-9_]+", "-", ascii_text).strip("-")[: MAX_SLUG_LENGTH - 9] or "name"
    digest = hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    return f"{slug}-{digest}"
