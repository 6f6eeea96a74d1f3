"""``docs/settings.md``: every setting of the hand (:mod:`skills.settings`) with its phase, unit, default and the
reason for it, generated from the dataclasses and their attribute docstrings.

Regenerate it with ``python -m puzzlebox.lab.settings_table > docs/settings.md``; a test fails while it is stale.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import re
import sys

from puzzlebox.skills import settings

UNIT = re.compile(r"\[([^\]]+)\]")
"""A unit in a docstring: its first bracket (``[N]``, ``[m/(N s)]``, ``[rad]``, ``[-]``)."""
IMPLIED = (
    ("fraction of the travel", "fraction of the travel"),
    ("times the", "times the noise"),
    ("closure", "closure (0 open, 1 shut)"),
    ("readings", "readings"),
    ("Ticks", "ticks"),
)
"""A setting without a bracketed unit: the unit its docstring implies (first phrase found)."""


def attribute_docs(cls: type) -> dict[str, str]:
    """Field name -> the docstring under it in ``cls``'s source ("" if none: attribute docstrings are not kept at
    run time, so they are read from the source)."""
    tree = ast.parse(inspect.getsource(cls))
    body = tree.body[0].body  # type: ignore[attr-defined]
    docs: dict[str, str] = {}
    for statement, after in zip(body, [*body[1:], None], strict=True):
        if isinstance(statement, ast.AnnAssign) and isinstance(statement.target, ast.Name):
            doc = ""
            if isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant):
                doc = inspect.cleandoc(str(after.value.value))
            docs[statement.target.id] = doc
    return docs


def _first_sentence(doc: str) -> str:
    """The first sentence of ``doc`` on one line, in Markdown (``x`` and :role:`x` as `x`)."""
    text = " ".join(doc.split())
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"`\1`", text).replace("``", "`")
    cut = re.search(r"(?<=[a-z0-9\)\]`])\. (?=[A-Z(])", text)
    return text[: cut.start() + 1] if cut else text


def _unit(doc: str, value: object) -> str:
    doc = " ".join(doc.split())
    found = UNIT.search(doc)
    if found:
        return found.group(1)
    if isinstance(value, bool):
        return "on/off"
    return next((unit for phrase, unit in IMPLIED if phrase in doc), "-")


def _default(value: object) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return repr(value)


def table() -> str:
    """The Markdown of ``docs/settings.md``."""
    lines = [
        "# The hand's settings",
        "",
        "Every setting of the hand (`skills/settings.py`), by the phase of a try it governs: its name (change it with",
        "`PrimitiveConfig.of(name=value)`, a door's push setting with `config.push.changed(name=value)`), its",
        "default, its unit and the first sentence of the reason the source gives for it. Generated: "
        "`python -m puzzlebox.lab.settings_table > docs/settings.md`.",
        "",
    ]
    top = settings.PrimitiveConfig()
    parts = [(f"`PrimitiveConfig.{f.name}`", getattr(top, f.name)) for f in dataclasses.fields(top) if f.name != "push"]
    parts += [(f"`PrimitiveConfig.push.{f.name}`", getattr(top.push, f.name)) for f in dataclasses.fields(top.push)]
    parts = [(name, value) for name, value in parts if dataclasses.is_dataclass(value)]
    own = [
        ("`PrimitiveConfig`", top, ("door_push",)),
        ("`PrimitiveConfig.push`", top.push, ("close_by_push", "top_up")),
    ]
    for title, part in parts:
        docs = attribute_docs(type(part))
        lines += [f"## {type(part).__name__} ({title})", "", _first_sentence(inspect.getdoc(type(part)) or ""), ""]
        lines += _rows(part, docs, [f.name for f in dataclasses.fields(part)])
    for title, config, names in own:
        docs = attribute_docs(type(config))
        lines += [f"## Switches of {title}", ""]
        lines += _rows(config, docs, list(names))
    return "\n".join(lines).rstrip() + "\n"


def _rows(config: object, docs: dict[str, str], names: list[str]) -> list[str]:
    rows = ["| setting | default | unit | why |", "|---|---|---|---|"]
    for name in names:
        doc = docs.get(name, "")
        why = _first_sentence(doc).replace("|", "\\|")
        rows.append(f"| `{name}` | {_default(getattr(config, name))} | {_unit(doc, getattr(config, name))} | {why} |")
    return [*rows, ""]


def main() -> None:
    sys.stdout.write(table())


if __name__ == "__main__":
    main()
