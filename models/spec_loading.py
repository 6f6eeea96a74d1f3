"""Reading spec files: parse, validate (every problem listed), build. Above both :mod:`models.spec` (the data
classes and the writer) and :mod:`models.validation` (which reads the lock table), so none of the three import in
a circle."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from puzzlebox.models.errors import SpecError, SpecProblem
from puzzlebox.models.json_input import JsonInputError, parse_json, read_input_text
from puzzlebox.models.spec import PuzzleSpec, build_from_valid_data
from puzzlebox.models.validation import validate_data


def spec_from_dict(data: Any, source: str | None = None) -> PuzzleSpec:
    """Validate a parsed JSON value and build the spec; :class:`SpecError` lists every problem."""
    problems = validate_data(data)
    if problems:
        raise SpecError(problems, source)
    return build_from_valid_data(data)


class _DuplicateKey(ValueError):
    pass


def _refuse_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``json.loads`` keeps the last of two equal keys silently; a spec with one is ambiguous."""
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(key)
        out[key] = value
    return out


def spec_from_json(text: str, source: str | None = None) -> PuzzleSpec:
    """Parse and validate JSON text."""
    try:  # bounded depth: a value nested thousands deep is one problem, not a RecursionError
        data = parse_json(text, object_pairs_hook=_refuse_duplicate_keys, allow_non_finite=True)
    except JsonInputError as err:
        raise SpecError([SpecProblem("file", str(err))], source) from None
    except _DuplicateKey as err:
        raise SpecError([SpecProblem("file", f"duplicate key {err.args[0]!r} in one JSON object")], source) from None
    return spec_from_dict(data, source)


def load_spec(path: str | Path) -> PuzzleSpec:
    """Read, parse and validate a spec file."""
    path = Path(path)
    try:
        text = read_input_text(path)
    except JsonInputError as err:
        raise SpecError([SpecProblem("file", f"cannot read: {err}")], str(path)) from None
    return spec_from_json(text, str(path))
