"""One rule for names (``models/names.py``): whatever validation accepts as a spec's or a component's name — spaces,
unicode, HTML, ``/``, ``..`` — every command runs; record keys and file names are slugs of names (a plain name is its
own slug; any other one a slug plus a short hash), never the names themselves."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from puzzlebox.lab.runner import Task
from puzzlebox.models import load_spec
from puzzlebox.models.generator import paper_family
from puzzlebox.models.names import KEY_PATTERN, MAX_NAME_LENGTH, name_problem, name_slug
from puzzlebox.models.validation import validate_data

ROOT = Path(__file__).resolve().parents[2]

NAMES = ["a box with spaces", "ünïcödé ✓ 箱", "dir/sub/name", "../../escape", "<b>bold</b> & 'quoted'", "..", "."]


def renamed(name: str) -> dict:
    """The first paper test box with ``name`` for the spec and ``name``-prefixed component names."""
    data = json.loads(paper_family("test")[0].to_json())
    new = {c["name"]: f"{name} {c['name']}" for c in data["components"]}
    data["name"] = name
    data["components"] = [dict(c, name=new[c["name"]]) for c in data["components"]]
    data["locks"] = [dict(rule, locker=new[rule["locker"]], locked=new[rule["locked"]]) for rule in data["locks"]]
    data["goal"] = dict(data["goal"], component=new[data["goal"]["component"]])
    return data


@pytest.mark.parametrize("name", NAMES)
def test_validation_accepts_the_name_and_its_slug_is_a_key_part(name):
    assert validate_data(renamed(name)) == [] and name_problem(name) is None
    slug = name_slug(name)
    assert KEY_PATTERN.match(f"000-{slug}-seed0") and "/" not in slug and ".." not in slug
    assert slug != name and slug == name_slug(name)  # deterministic, and not the name itself


def test_plain_names_are_their_own_slug_and_distinct_names_keep_distinct_slugs():
    assert name_slug("paper-test-0") == "paper-test-0"  # directories made before keep their keys
    assert name_slug("a b") != name_slug("a-b") != name_slug("a/b") != name_slug("a b ")
    assert len({name_slug(n) for n in NAMES}) == len(NAMES)
    Task(f"000-{name_slug('x' * 200)}-seed0", json.dumps)  # a long name's slug still makes a key


def test_names_validation_refuses_are_named():
    for bad, why in (("", "non-empty"), ("a\nb", "control character"), ("x" * (MAX_NAME_LENGTH + 1), "longer")):
        data = renamed("ok")
        data["name"] = bad
        assert any(why in str(p) for p in validate_data(data)), bad
        assert name_problem(bad) is not None


def test_names_with_spaces_unicode_and_slashes_run_end_to_end_in_trial_py(tmp_path):
    files = []
    for k, name in enumerate(NAMES):
        path = tmp_path / f"s{k}.json"
        path.write_text(json.dumps(renamed(name), ensure_ascii=False), encoding="utf-8")
        assert load_spec(path).name == name
        files.append(path)
    out = tmp_path / "out"
    command = [sys.executable, ROOT / "scripts/trial.py", "--specs", *files, "--sim", "symbolic", "--agent", "dual",
               "--runs", 2, "--seed", 0, "--max-actions", 30, "--out", out]  # fmt: skip
    result = subprocess.run(list(map(str, command)), capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    results = json.loads((out / "results.json").read_text())
    assert results["runs_done"] == results["runs_planned"] == 2 * len(NAMES) and results["success_rate"] == 1.0
    assert [r["spec"] for r in results["runs"]] == [n for n in NAMES for _ in range(2)], "names kept, as they are"
    assert {p.parent for p in out.rglob("*")} <= {out, out / "runs"}, "nothing written outside --out's layout"
    keys = sorted(p.stem for p in (out / "runs").glob("*.json"))
    assert len(keys) == 2 * len(NAMES) and all(KEY_PATTERN.match(k) for k in keys)
    again = subprocess.run(list(map(str, [*command, "--resume"])), capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr  # a plain rerun continues what is there (nothing to redo)


def test_a_sweep_of_such_names_and_labels_keys_every_cell(tmp_path):
    for k, name in enumerate(NAMES[:3]):
        (tmp_path / f"s{k}.json").write_text(json.dumps(renamed(name)), encoding="utf-8")
    sweep = tmp_path / "grid.json"
    sweep.write_text(json.dumps({"sim": "symbolic", "specs": ["s*.json"], "seeds": [1, 2], "max_actions": 30,
                                 "agents": ["oracle", {"name": "dual", "label": "dual / the one"}]}))  # fmt: skip
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, str(ROOT / "scripts/sweep.py"), str(sweep), "--out", str(out),
                             "--workers", "1"], capture_output=True, text=True, timeout=600)  # fmt: skip
    assert result.returncode == 0, result.stderr
    results = json.loads((out / "results.json").read_text())
    assert results["runs_done"] == 3 * 2 * 2 and {c["agent"] for c in results["cells"]} == {"oracle", "dual / the one"}
