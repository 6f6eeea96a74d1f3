"""Every command's ``--help``: its description prints as written (a usage block wrapped with backslashes in a plain
docstring was joined into one line: ``--seed S                             --max-actions M``)."""

import importlib
import pkgutil
import re

import pytest

import puzzlebox.scripts

SCRIPTS = sorted(m.name for m in pkgutil.iter_modules(puzzlebox.scripts.__path__))


@pytest.mark.parametrize("name", SCRIPTS)
def test_a_command_s_description_keeps_its_lines(name):
    doc = importlib.import_module(f"puzzlebox.scripts.{name}").__doc__ or ""
    joined = [line for line in doc.splitlines() if re.search(r"\S {8,}\S", line)]
    assert joined == [], joined
