"""Every kind of input file, fuzzed (issue 56): arbitrary JSON, valid documents with one value replaced or one key
dropped anywhere, and text that is not JSON, each written to a file and read by the library's own loader. A loader
either returns or raises its typed error (the one the command-line scripts print in one line); anything else (a
``KeyError``, a ``TypeError``, a hang) is a fault. 2,000 inputs per kind, 10,000 in all (~1 min on 2 cores).

The kinds: a spec (``models.load_spec``), a cell calibration (``CellCalibration.load``), a cell config
(``load_cell_config``), a reality profile (``twin.reality.load_profile``) and a sweep (``lab.sweep_grid.load_sweep``,
types and sizes; its grid is built from a sweep that passed).
"""

from __future__ import annotations

import copy
import functools
import json
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from puzzlebox.lab.input_faults import ideal_cell_calibration
from puzzlebox.lab.sweep_grid import SweepError, load_sweep
from puzzlebox.models import ModelsError, load_spec
from puzzlebox.models.calibration import CellCalibration
from puzzlebox.models.cell_config import EXAMPLE, CellConfigError, load_cell_config
from puzzlebox.models.generator import paper_family
from puzzlebox.twin.errors import TwinError
from puzzlebox.twin.reality import REALISTIC, load_profile

EXAMPLES = 2000
"""Inputs per kind of file."""

JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=10), children, max_size=5),
    max_leaves=20,
)
"""Any JSON value (floats finite: ``NaN`` is not JSON, and its text is fuzzed below)."""

NOT_JSON = st.sampled_from(["", "{", "[1,", "NaN", "Infinity", '{"a": 1}}', "\x00\x01", "nul", "{'a': 1}"]) | st.text(
    max_size=40
)
"""Text that is mostly not JSON."""


def _spec(tmp: Path) -> dict[str, Any]:
    return json.loads(paper_family("test")[0].to_json())


def _calibration(tmp: Path) -> dict[str, Any]:
    spec = tmp / "spec.json"
    spec.write_text(paper_family("test")[0].to_json())
    return ideal_cell_calibration(spec)


def _sweep(tmp: Path) -> dict[str, Any]:
    return {"sim": "twin", "specs": ["*.json"], "seeds": {"start": 0, "count": 2}, "agents": ["oracle", {"name":
            "memory", "memory": "m.sqlite", "label": "mem"}], "profiles": ["realistic"], "max_actions": 20}  # fmt: skip


KINDS: dict[str, tuple[Callable[[Path], dict[str, Any]], Callable[[Path], Any], tuple[type[BaseException], ...]]] = {
    "spec": (_spec, load_spec, (ModelsError,)),
    "calibration": (_calibration, CellCalibration.load, (ModelsError,)),
    "cell config": (lambda tmp: copy.deepcopy(EXAMPLE), load_cell_config, (CellConfigError,)),
    "reality profile": (lambda tmp: REALISTIC.to_dict(), load_profile, (TwinError,)),
    "sweep": (_sweep, load_sweep, (SweepError,)),
}
"""Kind -> (a valid document, its loader, the errors it may raise)."""


def _paths(document: Any) -> list[tuple[Any, ...]]:
    """Every place in ``document`` (keys and indices from the root), the root included."""
    places: list[tuple[Any, ...]] = [()]
    if isinstance(document, dict):
        for key, value in document.items():
            places += [(key, *p) for p in _paths(value)]
    elif isinstance(document, list):
        for index, value in enumerate(document):
            places += [(index, *p) for p in _paths(value)]
    return places


@st.composite
def _inputs(draw: st.DrawFn, valid: dict[str, Any]) -> str:
    """A file's text: arbitrary JSON, the valid document with one place replaced or dropped, or not JSON."""
    how = draw(st.sampled_from(["replaced", "replaced", "dropped", "any", "text"]))
    if how == "any":
        return json.dumps(draw(JSON_VALUES))
    if how == "text":
        return draw(NOT_JSON)
    document = copy.deepcopy(valid)
    place = draw(st.sampled_from(_paths(document)))
    if not place:
        return json.dumps(draw(JSON_VALUES))
    parent = document
    for step in place[:-1]:
        parent = parent[step]
    if how == "dropped" and isinstance(parent, dict):
        del parent[place[-1]]
    else:
        parent[place[-1]] = draw(JSON_VALUES)
    return json.dumps(document)


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_input_file_kind_fuzzed_is_read_or_refused_with_its_typed_error(kind, tmp_path):
    make_valid, load, allowed = KINDS[kind]
    valid = make_valid(tmp_path)
    path = tmp_path / f"{kind.replace(' ', '-')}.json"
    path.write_text(json.dumps(valid))
    load(path)  # the valid document loads
    seen = {"read": 0, "refused": 0}

    @settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
    @given(_inputs(valid))
    def read_or_refused(text: str) -> None:
        target = tmp_path / f"{uuid.uuid4().hex}.json"
        target.write_text(text, encoding="utf-8", errors="surrogatepass")
        try:
            load(target)
            seen["read"] += 1
        except allowed:
            seen["refused"] += 1
        finally:
            target.unlink()

    read_or_refused()
    assert seen["read"] + seen["refused"] >= EXAMPLES and seen["refused"] > EXAMPLES // 4, seen


class _Chooser:
    """An agent that chooses ``choice`` (whatever it is), or raises it if it is an exception."""

    name = "fuzzed"

    def __init__(self, choice: Any) -> None:
        self.choice = choice

    def begin_episode(self, observation: Any, rng: Any) -> None:
        pass

    def choose(self, observation: Any) -> Any:
        if isinstance(self.choice, BaseException):
            raise self.choice
        return self.choice

    def record(self, index: int, result: Any, observation: Any) -> None:
        pass

    def end_episode(self, solved: bool) -> None:
        pass


CHOICES = (
    st.integers(-10, 10) | st.integers() | st.floats() | st.booleans() | st.none() | st.text(max_size=3)
    | st.builds(lambda v: __import__("numpy").int64(v), st.integers(-10, 10)) | JSON_VALUES
    | st.sampled_from([ValueError("x"), KeyError("k"), SystemExit(0), RuntimeError("r"), IndexError(3)])
)  # fmt: skip
"""What an agent's ``choose`` may give: indices in and out of range, other types, or an exception."""


@functools.cache
def _paper_test_0() -> Any:
    return paper_family("test")[0]


@settings(max_examples=EXAMPLES // 4, deadline=None, suppress_health_check=list(HealthCheck))
@given(CHOICES)
def test_the_agent_seam_fuzzed_takes_a_part_or_refuses_with_an_agent_error(choice):
    """Whatever an agent chooses, the episode takes one of the parts or ends with ``AgentError`` naming the agent,
    before the world tries anything (a choice of -1 had the twin's arm try the last part)."""
    from puzzlebox.learning import AgentError, SymbolicWorld, run_episode

    spec = _paper_test_0()
    world = SymbolicWorld(spec, 0)
    parts = len(spec.components)
    valid = isinstance(choice, int | __import__("numpy").integer) and not isinstance(choice, bool) and (
        0 <= choice < parts)  # fmt: skip
    try:
        result = run_episode(_Chooser(choice), world, spec.name, 0, max_actions=2)
    except AgentError as err:
        assert not valid and "'fuzzed'" in str(err), (choice, err)
    else:
        assert valid and result.num_actions >= 1, (choice, result)
