"""``docs/settings.md`` is the table of the hand's settings as the source states them: regenerated, it is the same,
and every setting in it has a default, a unit and a reason."""

from __future__ import annotations

from pathlib import Path

from puzzlebox.lab.settings_table import table
from puzzlebox.skills.settings import PrimitiveConfig

DOC = Path(__file__).resolve().parents[2] / "docs" / "settings.md"


def test_the_settings_table_in_docs_is_current():
    assert DOC.read_text() == table(), "stale: python -m puzzlebox.lab.settings_table > docs/settings.md"


def test_every_setting_has_a_row_with_a_unit_and_a_reason():
    rows = [line.split(" | ") for line in table().splitlines() if line.startswith("| `")]
    names = [row[0].strip("|` ") for row in rows]
    flat = PrimitiveConfig().flat()
    assert sorted(names) == sorted(name.removeprefix("push.") for name in flat)
    for name, _default, unit, why in rows:
        assert unit.strip() and len(why.strip(" |")) > 10, name
