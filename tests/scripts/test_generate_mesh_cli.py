"""``generate.py mesh SPEC --out DIR``: the box as GLB, OBJ and STL files, and one-line failures."""

import json
import subprocess
import sys
from pathlib import Path

import trimesh

from models import save_spec
from models.generator import paper_family

ROOT = Path(__file__).resolve().parents[2]


def generate(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "generate.py"), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
    )


def assert_one_line_failure(result, *words):
    assert result.returncode == 2 and result.stdout == ""
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert result.stderr.startswith("error: ") and all(w in result.stderr for w in words), result.stderr


def test_mesh_writes_glb_obj_and_stl_per_part(tmp_path):
    spec = paper_family("test")[0]
    path = save_spec(spec, tmp_path / "box.json")
    result = generate("mesh", path, "--out", tmp_path / "out")
    assert result.returncode == 0, result.stderr
    parts = ["box", *(c.name for c in spec.components)]
    files = {f"{spec.name}.{ext}" for ext in ("glb", "obj", "stl")} | {f"{spec.name}-{p}.stl" for p in parts}
    assert {p.name for p in (tmp_path / "out").iterdir()} == files
    glb = trimesh.load(tmp_path / "out" / f"{spec.name}.glb", force="scene")
    assert set(glb.graph.nodes_geometry) == set(parts)
    # metres in the lid frame: the box spans its length along x and stands on z = -height
    length, width, height = spec.box.size
    lo, hi = trimesh.load(tmp_path / "out" / f"{spec.name}-box.stl", force="mesh").bounds
    assert abs((hi - lo)[0] - length) < 1e-6 and abs(lo[2] + height) < 1e-6 and abs(hi[2]) < 1e-6


def test_a_missing_spec_is_one_line_and_exit_2(tmp_path):
    result = generate("mesh", tmp_path / "absent.json", "--out", tmp_path / "out")
    assert_one_line_failure(result, "absent.json", "cannot read")
    assert not (tmp_path / "out").exists()


def test_an_invalid_spec_is_one_line_and_exit_2(tmp_path):
    (tmp_path / "bad.json").write_text('{"name": 1}')
    assert_one_line_failure(generate("mesh", tmp_path / "bad.json", "--out", tmp_path / "out"), "invalid puzzle spec")


def test_a_disassembly_scene_is_refused_in_one_line(tmp_path):
    scene = {
        "format": "puzzlebox-spec/1",
        "name": "one-screw",
        "components": [
            {"name": "s1", "kind": "screw", "pose": [0.0, 0.0, 0.0, 0, 0, 0]},
            {"name": "panel", "kind": "panel", "pose": [-0.23, 0.02, -0.2, 0, 0, 1.5708]},
        ],
        "locks": [{"locker": "s1", "locker_state": 0, "locked": "panel", "locked_state": 0}],
        "goal": {"component": "panel", "state": 1},
    }
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    result = generate("mesh", tmp_path / "scene.json", "--out", tmp_path / "out")
    assert_one_line_failure(result, "disassembly scene", "no box")
    assert not (tmp_path / "out").exists()
