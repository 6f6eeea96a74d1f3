"""The house's structure (DESIGN.md, "Layers"): imports go down the layers, never sideways between skills and
learning, never in a cycle; every package folder installs under the one import root."""

from __future__ import annotations

import ast
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = {"models": "models", "twin": "twin", "skills": "skills", "learning": "learning", "real": "real",
           "lab": "puzzlebox/lab", "scripts": "scripts"}  # fmt: skip
MAY_IMPORT = {
    "models": set(),
    "twin": {"models"},
    "skills": {"models"},
    "learning": {"models"},
    "real": {"models"},
    "lab": {"models", "twin", "skills", "learning", "real"},
    "scripts": {"models", "twin", "skills", "learning", "real", "lab"},
}


def _modules() -> dict[str, Path]:
    out = {}
    for layer, folder in FOLDERS.items():
        for path in (ROOT / folder).rglob("*.py"):
            parts = [p for p in path.relative_to(ROOT / folder).with_suffix("").parts if p != "__init__"]
            out[".".join(["puzzlebox", layer, *parts])] = path
    return out


def _imports(modules: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the project modules it imports anywhere in its body (at the top, in functions, for typing)."""

    def resolve(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        found = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("puzzlebox."):
                found |= {resolve(f"{node.module}.{a.name}") for a in node.names}
            elif isinstance(node, ast.Import):
                found |= {resolve(a.name) for a in node.names if a.name.startswith("puzzlebox.")}
        graph[name] = {m for m in found if m and m != name}
    return graph


def test_imports_go_down_the_layers():
    graph = _imports(_modules())
    wrong = sorted(
        f"{m} imports {d}"
        for m, deps in graph.items()
        for d in deps
        if d.split(".")[1] != m.split(".")[1] and d.split(".")[1] not in MAY_IMPORT[m.split(".")[1]]
    )
    assert wrong == []


def test_no_import_cycle_anywhere():
    graph = _imports(_modules())
    cycles, state = [], {}

    def visit(node: str, path: list[str]) -> None:
        state[node] = "open"
        for dep in sorted(graph[node]):
            if state.get(dep) == "open":
                cycles.append(path[path.index(dep) :] + [dep])
            elif dep not in state:
                visit(dep, [*path, dep])
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node, [node])
    assert cycles == []


def test_every_package_folder_installs_under_the_import_root():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["setuptools"]
    listed = set(project["packages"])
    folders = {"puzzlebox": "puzzlebox", **{f"puzzlebox.{k}": v for k, v in FOLDERS.items() if k != "lab"}}
    on_disk = {"puzzlebox.lab"}
    for package, folder in folders.items():
        assert project["package-dir"][package] == folder
        for init in (ROOT / folder).rglob("__init__.py"):
            on_disk.add(".".join([package, *init.parent.relative_to(ROOT / folder).parts]))
    assert on_disk == listed


def test_nothing_imports_a_layer_by_its_folder_name():
    """``import twin.cell`` from the repository's folder would load a second copy of a module beside
    ``puzzlebox.twin.cell`` (a monkeypatch of one misses the other): every import goes through the root."""
    bare = []
    for path in [*ROOT.glob("tests/**/*.py"), *_modules().values()]:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            bare += [f"{path.relative_to(ROOT)}: {n}" for n in names if n.split(".")[0] in MAY_IMPORT]
    assert bare == []


def test_import_puzzlebox_registers_all_three_environments_and_imports_no_layer():
    # (Puzzle-v0 was registered only once puzzlebox.learning was imported)
    code = (
        "import sys, gymnasium, puzzlebox\n"
        "names = ('puzzlebox/Puzzle-v0', 'puzzlebox/TwinPuzzle-v0', 'puzzlebox/BoxManipulation-v0')\n"
        "assert all(n in gymnasium.registry for n in names), names\n"
        "assert not any(m.startswith(('puzzlebox.learning', 'puzzlebox.lab', 'puzzlebox.twin')) for m in sys.modules)\n"
        "from puzzlebox.models.generator import paper_family\n"
        "env = gymnasium.make('puzzlebox/Puzzle-v0', spec=paper_family('test')[0])\n"
        "print(sorted(env.reset(seed=0)[0]))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "['goal', 'kinds', 'poses', 'states']"


DISTRIBUTION_OF = {"xarm": "xarm-python-sdk", "cv2": "opencv-python-headless"}
"""The distribution of an import name that ``importlib.metadata`` may not map (an optional extra not installed)."""
TYPING_ONLY = {"_typeshed"}
"""Import names that exist only for the type checker (under ``if TYPE_CHECKING``)."""


def test_every_third_party_package_the_library_imports_is_declared():
    # (daqp, imported by skills/ik_qp.py, was installed only as another package's dependency)
    import re
    from importlib.metadata import packages_distributions

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    requirements = project["dependencies"] + [r for extra in project["optional-dependencies"].values() for r in extra]
    declared = {re.split(r"[<>=\[ ;]", r)[0].lower().replace("_", "-") for r in requirements}
    installed = packages_distributions()
    undeclared = set()
    for path in _modules().values():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            for top in {n.split(".")[0] for n in names} - set(sys.stdlib_module_names) - TYPING_ONLY - {"puzzlebox"}:
                dists = installed.get(top) or [DISTRIBUTION_OF.get(top, top)]
                if not {d.lower().replace("_", "-") for d in dists} & declared:
                    undeclared.add(f"{path.relative_to(ROOT)}: {top} ({', '.join(dists)})")
    assert sorted(undeclared) == []


def test_no_test_imports_a_private_name():
    # (tests reached into modules for _median_rows, _se3, _snapshot...: what a test needs is a public name)
    private = []
    for path in ROOT.glob("tests/**/*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("puzzlebox"):
                private += [f"{path.relative_to(ROOT)}: {node.module}.{a.name}" for a in node.names
                            if a.name.startswith("_") and not a.name.startswith("__")]  # fmt: skip
    assert private == []
