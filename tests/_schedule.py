"""The order in which the suite's tests reach pytest-xdist's workers: the longest work first.

``make test`` runs ``pytest -n 2 --dist loadgroup --no-loadscope-reorder``: xdist hands each work unit (one test,
or every test of a module in :data:`GROUPED`, whose module-scoped fixture is costly and so is set up once) to the
next idle worker, in collection order. Collected longest first by the CPU seconds recorded in
:data:`COSTS`, the units pack onto the two workers the way a greedy scheduler packs jobs (longest processing time
first): the run ends within about the shortest tests of each other instead of one worker idling while the other
finishes a two-minute end-to-end experiment it picked up last.

The table is only an ordering hint: a test missing from it (short, new, renamed) costs :data:`UNKNOWN_COST_S`, and a
stale figure changes the order, never a result. Refresh it after the suite changes::

    PUZZLEBOX_TEST_COSTS=/tmp/costs.tsv make test && .venv/bin/python tests/_schedule.py /tmp/costs.tsv
"""

from __future__ import annotations

import json
import os
import resource
import sys
from collections import defaultdict
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

COSTS = Path(__file__).with_name("durations.json")
"""Test node id -> CPU seconds of its setup, call and teardown (the test process and its children)."""

UNKNOWN_COST_S = 0.1
"""The cost assumed of a test the table does not list [s] (it lists those of :data:`LISTED_FROM_S` or more; the
others averaged 0.06 s)."""

LISTED_FROM_S = 0.5
"""The table lists the tests that took at least this long [s]: the order of the rest hardly matters."""

GROUPED = (
    "tests/lab/test_hard_sets.py",
    "tests/scripts/test_report.py",
    "tests/scripts/test_train_twin.py",
    "tests/skills/test_cell_configured.py",
    "tests/skills/test_primitives.py",
    "tests/skills/test_robustness.py",
    "tests/skills/test_toggle_recorder.py",
    "tests/twin/test_calibration_rig.py",
    "tests/twin/test_gallery.py",
    "tests/twin/test_rerun_log.py",
    "tests/twin/test_rollout_video.py",
    "tests/twin/test_session.py",
    "tests/twin/test_system_id.py",
)
"""Modules whose module-scoped fixtures take seconds (a twin trial, a calibration, a generated box...): kept on one
worker so that the fixture is built once."""

SLOW_FROM_S = 1.0
"""A work unit (a test, or a :data:`GROUPED` module) recorded at this many CPU seconds or more is marked ``slow``
(:func:`mark_slow`): ``make test-fast`` leaves those out (``pytest -m "not slow"``), for the edit-test loop."""

RECORD_ENV = "PUZZLEBOX_TEST_COSTS"
"""Set to a path: every test's CPU seconds are appended there (``seconds<TAB>node id`` lines)."""


def _base_id(nodeid: str) -> str:
    """A node id without the ``@group`` suffix xdist's ``loadgroup`` adds."""
    bracket = nodeid.rfind("]")
    at = nodeid.rfind("@")
    return nodeid[:at] if at > bracket else nodeid


def load_costs(path: Path = COSTS) -> dict[str, float]:
    try:
        return {str(k): float(v) for k, v in json.loads(path.read_text()).items()}
    except (OSError, ValueError, AttributeError):
        return {}


def order_longest_first(items: list[pytest.Item], costs: dict[str, float]) -> None:
    """Mark the :data:`GROUPED` modules as xdist groups and sort ``items`` in place, longest unit first (a unit's
    tests keep their order)."""
    units: dict[str, list[pytest.Item]] = defaultdict(list)
    for item in items:
        module = item.nodeid.split("::", 1)[0]
        if module in GROUPED:
            item.add_marker(pytest.mark.xdist_group(name=module))
            units[module].append(item)
        else:
            units[item.nodeid].append(item)
    cost = {key: sum(costs.get(_base_id(i.nodeid), UNKNOWN_COST_S) for i in unit) for key, unit in units.items()}
    items[:] = [item for key in sorted(units, key=lambda k: -cost[k]) for item in units[key]]
    mark_slow(units, cost)


def mark_slow(units: dict[str, list[pytest.Item]], cost: dict[str, float]) -> None:
    """Mark ``slow`` every test of a unit that costs :data:`SLOW_FROM_S` or more (a grouped module as a whole: its
    module-scoped fixture, charged to its first test, is what costs)."""
    for key, unit in units.items():
        if cost[key] >= SLOW_FROM_S:
            for item in unit:
                item.add_marker(pytest.mark.slow)


def _cpu_s() -> float:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@contextmanager
def recording(item: pytest.Item) -> Iterator[None]:
    """Append the CPU seconds ``item`` took (its process and the children it waited for) to ``$RECORD_ENV``."""
    path = os.environ.get(RECORD_ENV)
    before = _cpu_s()
    yield
    if path:
        with open(path, "a") as f:
            f.write(f"{_cpu_s() - before:.2f}\t{_base_id(item.nodeid)}\n")


def refresh(log: Path, table: Path = COSTS) -> int:
    """Write ``table`` from a recorded log (the last figure of each test, those of :data:`LISTED_FROM_S` or more);
    returns how many tests it lists."""
    costs: dict[str, float] = {}
    for line in log.read_text().splitlines():
        seconds, _, nodeid = line.partition("\t")
        costs[nodeid] = round(float(seconds), 1)
    listed = {k: v for k, v in sorted(costs.items()) if v >= LISTED_FROM_S}
    table.write_text(json.dumps(listed, indent=0) + "\n")
    return len(listed)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(f"usage: {sys.argv[0]} RECORDED.tsv  (written by a run with {RECORD_ENV}=RECORDED.tsv)")
    print(f"{refresh(Path(sys.argv[1]))} tests -> {COSTS}")
