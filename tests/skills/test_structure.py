"""The hand stays readable: no class in ``skills/`` over 20 methods or 400 lines, no function over 80 lines, and no
code anywhere reads a try's reason text (its cause is a type: ``models.try_outcome.Cause``)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = ("skills", "models", "learning", "twin", "real", "puzzlebox", "scripts")


def _sizes(path: Path) -> list[str]:
    too_big = []
    for node in ast.walk(ast.parse(path.read_text())):
        lines = getattr(node, "end_lineno", 0) - getattr(node, "lineno", 0) + 1
        if isinstance(node, ast.ClassDef):
            methods = sum(isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef) for n in node.body)
            if methods > 20 or lines > 400:
                too_big.append(f"{path.name}: class {node.name}: {methods} methods, {lines} lines")
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and lines > 80:
            too_big.append(f"{path.name}: {node.name}: {lines} lines")
    return too_big


def test_no_class_or_function_in_skills_is_too_big_to_read():
    too_big = [problem for path in sorted((ROOT / "skills").glob("*.py")) for problem in _sizes(path)]
    assert too_big == []


def test_the_size_check_finds_a_function_too_long(tmp_path):
    body = "\n".join(f"    x{i} = {i}" for i in range(81))
    (tmp_path / "long.py").write_text(f"def long():\n{body}\n")
    assert _sizes(tmp_path / "long.py") == ["long.py: long: 82 lines"]


READS_A_REASON = re.compile(r"""(\.reason|\[["']reason["']\])\s*\.(startswith|endswith|split|lower|find)\(""")


def test_no_code_reads_a_reason_string_but_the_legacy_loader():
    readers = [
        f"{path.relative_to(ROOT)}:{n}"
        for package in PACKAGES
        for path in sorted((ROOT / package).rglob("*.py"))
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if READS_A_REASON.search(line)
    ]
    assert readers == []
    assert READS_A_REASON.search('if result.reason.startswith("IKFailure"):')
    assert READS_A_REASON.search('a["reason"].split(":")[0]')
