"""The generate.py verbs behave as DESIGN.md's command-line contract states, malformed input included."""

import json
import subprocess
import sys
from pathlib import Path

import pytest
import trimesh

from puzzlebox.models import save_spec
from puzzlebox.models.generator import paper_family
from puzzlebox.models.lock_features import layout_lock_features

ROOT = Path(__file__).resolve().parents[2]


def generate(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "generate.py"), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=120,
    )


def test_paper_writes_one_valid_spec_per_variant_of_the_split(tmp_path):
    result = generate("paper", "--split", "test", "--out", tmp_path)
    assert result.returncode == 0, result.stderr
    names = sorted(p.name for p in tmp_path.glob("*.json"))
    assert names == ["paper-test-0.json", "paper-test-1.json", "paper-test-2.json"]
    check = generate("validate", *sorted(tmp_path.glob("*.json")))
    assert check.returncode == 0 and check.stdout.count(": valid (") == 3


def test_paper_all_writes_twelve_and_is_byte_identical_twice(tmp_path):
    assert generate("paper", "--split", "all", "--out", tmp_path / "a").returncode == 0
    assert generate("paper", "--split", "all", "--out", tmp_path / "b").returncode == 0
    a, b = sorted((tmp_path / "a").glob("*.json")), sorted((tmp_path / "b").glob("*.json"))
    assert len(a) == 12
    assert [p.read_bytes() for p in a] == [p.read_bytes() for p in b]


def test_chain_and_random_write_valid_reproducible_files(tmp_path):
    assert (
        generate("chain", "--kinds", "door,slide,wheel,slide", "--seed", 3, "--out", tmp_path / "c1.json").returncode
        == 0
    )
    assert (
        generate("chain", "--kinds", "door,slide,wheel,slide", "--seed", 3, "--out", tmp_path / "c2.json").returncode
        == 0
    )
    assert (tmp_path / "c1.json").read_bytes() == (tmp_path / "c2.json").read_bytes()
    result = generate("random", "--components", 7, "--seed", 1, "--multi-locker", "--out", tmp_path / "r.json")
    assert result.returncode == 0, result.stderr
    assert len(json.loads((tmp_path / "r.json").read_text())["components"]) == 7
    assert generate("validate", tmp_path / "c1.json", tmp_path / "r.json").returncode == 0


def test_plot_writes_a_top_view_png_beside_the_json(tmp_path):
    result = generate("random", "--components", 6, "--seed", 0, "--out", tmp_path / "r.json", "--plot")
    assert result.returncode == 0, result.stderr
    png = (tmp_path / "r.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000


def test_chain_with_forbidden_neighbours_fails_cleanly(tmp_path):
    result = generate("chain", "--kinds", "door,wheel", "--seed", 0, "--out", tmp_path / "x.json")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr and "door-slide" in result.stderr
    assert not (tmp_path / "x.json").exists()


MALFORMED = {
    "not_json.json": "{this is not json",
    "empty.json": "",
    "wrong_format.json": json.dumps({"format": "other/9"}),
    "list.json": "[1, 2, 3]",
}


@pytest.mark.parametrize("name", sorted(MALFORMED))
def test_validate_reports_malformed_files_one_line_per_problem_without_traceback(tmp_path, name):
    path = tmp_path / name
    path.write_text(MALFORMED[name])
    result = generate("validate", path)
    assert result.returncode == 1
    assert "Traceback" not in result.stderr + result.stdout
    lines = result.stdout.strip().splitlines()
    assert lines and all(line.startswith(f"{path}: ") for line in lines)


def test_validate_lists_every_problem_and_still_checks_the_other_files(tmp_path, spec_dict, write_spec):
    good = write_spec(spec_dict, "good.json")
    spec_dict["components"][0]["kind"] = "drawer"  # mid-lid: not on the lid edge, and over the slide
    spec_dict["locks"][0]["locked"] = "ghost"
    bad = write_spec(spec_dict, "bad.json")
    result = generate("validate", bad, good, tmp_path / "missing.json")
    assert result.returncode == 1
    bad_lines = [line for line in result.stdout.splitlines() if line.startswith(str(bad))]
    assert len(bad_lines) == 3
    assert f"{good}: valid" in result.stdout
    assert f"{tmp_path / 'missing.json'}: file: cannot read" in result.stdout


def test_unknown_verb_is_a_usage_error():
    result = generate("teleport")
    assert result.returncode == 2 and "invalid choice" in result.stderr


def test_mjcf_writes_a_scene_plain_mujoco_loads(tmp_path):
    import mujoco

    assert generate("paper", "--split", "test", "--out", tmp_path / "specs").returncode == 0
    result = generate("mjcf", tmp_path / "specs" / "paper-test-0.json", "--out", tmp_path / "scene")
    assert result.returncode == 0, result.stderr
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "scene" / "scene.xml"))
    assert model.nu == 8 and model.neq == 8  # 7 arm servos + gripper; 3 gripper couplings + 5 latches


def test_mjcf_refuses_an_invalid_spec_without_traceback(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    result = generate("mjcf", bad, "--out", tmp_path / "scene")
    assert result.returncode == 2 and "Traceback" not in result.stderr and "format" in result.stderr


# -- datasets: --count N --------------------------------------------------------------------------------


def _tree(directory: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(directory.iterdir())}


def test_a_dataset_is_byte_identical_across_runs_and_worker_counts(tmp_path):
    args = ("random", "--components", 7, "--multi-locker", "--seed", 40, "--count", 10)
    for name, workers in (("a", 1), ("b", 2), ("c", 1)):
        result = generate(*args, "--out", tmp_path / name, "--workers", workers)
        assert result.returncode == 0, result.stderr
    assert _tree(tmp_path / "a") == _tree(tmp_path / "b") == _tree(tmp_path / "c")
    manifest = json.loads((tmp_path / "a" / "manifest.json").read_text())
    assert manifest["count"] == 10 and [e["seed"] for e in manifest["specs"]] == list(range(40, 50))
    from puzzlebox.models import LockTable, load_spec

    for entry in manifest["specs"]:
        path = tmp_path / "a" / entry["file"]
        spec = load_spec(path)
        assert spec.name == entry["name"] and len(spec.components) == entry["components"] == 7
        import hashlib

        assert hashlib.sha256(path.read_bytes()).hexdigest() == entry["sha256"]
        plan = LockTable.from_spec(spec).shortest_solution()
        assert entry["shortest_solution"] == [spec.components[i].name for i in plan]
    single = generate("random", "--components", 7, "--multi-locker", "--seed", 43, "--out", tmp_path / "one.json")
    assert single.returncode == 0
    assert (tmp_path / "one.json").read_bytes() == (tmp_path / "a" / "random-n7-multi-s43.json").read_bytes(), (
        "spec i of a dataset is the single spec of seed S + i"
    )


def test_chain_datasets_and_dataset_mistakes(tmp_path):
    ok = generate("chain", "--kinds", "door,slide,wheel", "--seed", 0, "--count", 3, "--out", tmp_path / "c")
    assert ok.returncode == 0, ok.stderr
    assert len(json.loads((tmp_path / "c" / "manifest.json").read_text())["specs"]) == 3
    (tmp_path / "file").write_text("x")
    for args, message in (
        (("random", "--components", 5, "--seed", 0, "--count", 0, "--out", tmp_path / "d"), "--count must be >= 1"),
        (("random", "--components", 5, "--seed", 0, "--workers", 2, "--out", tmp_path / "e.json"), "go with --count"),
        (("random", "--components", 5, "--seed", 0, "--count", 2, "--out", tmp_path / "file"), "is a file"),
        (("chain", "--kinds", "door,wheel", "--seed", 0, "--count", 2, "--out", tmp_path / "f"), "cannot lock"),
    ):
        bad = generate(*args)
        assert bad.returncode == 2 and message in bad.stderr and "Traceback" not in bad.stderr, (args, bad.stderr)
        assert len(bad.stderr.strip().splitlines()) == 1


def test_a_dataset_directory_holds_one_dataset(tmp_path):
    """Generated into the folder of another dataset, the old specs stayed beside the new ones under a replaced
    manifest; now anything but this dataset's own files is refused before a file is written. The same command again,
    or after a stop, writes the same files."""
    chain = ("chain", "--kinds", "door,slide,wheel", "--seed", 0, "--count", 3, "--out", tmp_path / "c")
    assert generate(*chain).returncode == 0
    before = _tree(tmp_path / "c")
    other = generate("random", "--components", 5, "--seed", 0, "--count", 2, "--out", tmp_path / "c")
    assert other.returncode == 2 and "holds another dataset (manifest.json:" in other.stderr, other.stderr
    assert _tree(tmp_path / "c") == before
    again = generate(*chain)
    assert again.returncode == 0, again.stderr
    assert _tree(tmp_path / "c") == before
    (tmp_path / "c" / "manifest.json").unlink()  # as a stopped run leaves it: specs and the marker of its run
    (tmp_path / "c" / ".dataset-started.json").write_text(json.dumps({"generator": json.loads(
        before["manifest.json"])["generator"]}))  # fmt: skip
    assert generate(*chain).returncode == 0 and _tree(tmp_path / "c") == before
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "todo.txt").write_text("x")
    stray = generate("random", "--components", 5, "--seed", 0, "--count", 2, "--out", tmp_path / "notes")
    assert stray.returncode == 2 and "holds 1 file(s) of no dataset (todo.txt)" in stray.stderr, stray.stderr


# -- generate.py mesh SPEC --out DIR: the box as GLB, OBJ and STL files, and one-line failures ----------------


def assert_one_line_failure(result, *words):
    assert result.returncode == 2 and result.stdout == ""
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert result.stderr.startswith("error: ") and all(w in result.stderr for w in words), result.stderr


def test_mesh_writes_glb_obj_and_stl_per_part(tmp_path):
    spec = paper_family("test")[0]
    path = save_spec(spec, tmp_path / "box.json")
    result = generate("mesh", path, "--out", tmp_path / "out")
    assert result.returncode == 0, result.stderr
    # the box, each component, and each lock mechanism's wall and rod (a pair of rules each here) as its own part
    pairs = [(r.locker, r.locked) for r in spec.locks[::2]]
    mechanisms = [f"{a}-interlocks-{b}-{role}" for a, b in pairs for role in ("wall", "rod")]
    parts = ["box", *(c.name for c in spec.components), *mechanisms]
    files = {f"{spec.name}.{ext}" for ext in ("glb", "obj", "stl")} | {f"{spec.name}-{p}.stl" for p in parts}
    assert {p.name for p in (tmp_path / "out").iterdir()} == files
    glb = trimesh.load(tmp_path / "out" / f"{spec.name}.glb", force="scene")
    assert set(glb.graph.nodes_geometry) == set(parts)
    for name in parts:  # every part prints as one closed solid
        assert trimesh.load(tmp_path / "out" / f"{spec.name}-{name}.stl", force="mesh").is_watertight, name
    # metres in the lid frame: the box spans its length along x and stands on z = -height
    length, width, height = spec.box.size
    lo, hi = trimesh.load(tmp_path / "out" / f"{spec.name}-box.stl", force="mesh").bounds
    assert abs((hi - lo)[0] - length) < 1e-6 and abs(lo[2] + height) < 1e-6 and abs(hi[2]) < 1e-6
    layout = layout_lock_features(spec)  # what the user is told of the locks the meshes show, and of any not shown
    told = f"lock features: {len(layout.features)} shown, {len(layout.skipped)} without room on their locker"
    assert told in result.stdout and len(layout.features) > 0, result.stdout
    assert result.stdout.count("not shown:") == len(layout.skipped)


def test_a_missing_spec_is_one_line_and_exit_2(tmp_path):
    result = generate("mesh", tmp_path / "absent.json", "--out", tmp_path / "out")
    assert_one_line_failure(result, "absent.json", "cannot read")
    assert not (tmp_path / "out").exists()


def test_an_invalid_spec_is_one_line_and_exit_2(tmp_path):
    (tmp_path / "bad.json").write_text('{"name": 1}')
    assert_one_line_failure(generate("mesh", tmp_path / "bad.json", "--out", tmp_path / "out"), "invalid puzzle spec")


def test_a_disassembly_scene_is_refused_in_one_line(tmp_path, scene_dict):
    scene = scene_dict
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    result = generate("mesh", tmp_path / "scene.json", "--out", tmp_path / "out")
    assert_one_line_failure(result, "disassembly scene", "no box")
    assert not (tmp_path / "out").exists()


# -- generate.py mjcf --box-only and check-locks: the box alone holds its lock rules by contact ----------------


@pytest.fixture(scope="module")
def paper_box(tmp_path_factory):
    """A paper test box's spec file (five components, every rule realized by a mechanism)."""
    out = tmp_path_factory.mktemp("paper")
    assert generate("paper", "--split", "test", "--out", out).returncode == 0
    return out / "paper-test-0.json"


def test_mjcf_box_only_writes_a_box_without_robot_that_plain_mujoco_steps_without_warning(tmp_path, paper_box):
    import mujoco

    result = generate("mjcf", paper_box, "--box-only", "--out", tmp_path / "box")
    assert result.returncode == 0, result.stderr
    assert "box.xml" in result.stdout and "latches only" not in result.stdout  # every rule has its mechanism
    assert not (tmp_path / "box" / "scene.xml").exists()
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "box" / "box.xml"))
    assert model.nu == 0 and model.nlight >= 1  # no robot; a light to render by
    assert model.neq == 5 and model.opt.timestep == 0.002  # the five latches, inactive; the scene's step
    door = model.joint("door-0:joint")
    assert 1.0 < model.jnt_range[door.id][1] < 1.6, "hinge ranges read as radians, not degrees"
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=100)
    assert all(data.warning[i].number == 0 for i in range(len(data.warning)))


def test_check_locks_finds_every_transition_of_a_paper_box_agrees_wherever_its_parts_stand_in_their_bands(
    tmp_path, paper_box
):
    result = generate("check-locks", paper_box, "--json", tmp_path / "check.json")
    assert result.returncode == 0, result.stderr
    # the band check: each of the 30 pushes with the others at their stops, 10 % and 20 % inside their bands
    assert "paper-test-0: 90/90 transitions agree" in result.stdout and "0 rule(s) without a mechanism" in result.stdout
    assert result.stdout.strip().splitlines()[-1].startswith("total (1 box(es)): 90/90")
    record = json.loads((tmp_path / "check.json").read_text())
    (box,) = record["boxes"]
    assert (box["agreeing"], box["total"], box["disagreements"], box["unrealized"]) == (90, 90, [], [])
    assert record["offsets"] == [0.0, 0.1, 0.2]
    assert box["held_move_max"] < 0.5


def test_check_locks_at_the_stops_only_makes_each_push_once(paper_box):
    result = generate("check-locks", paper_box, "--stops-only")
    assert result.returncode == 0, result.stderr
    assert "paper-test-0: 30/30 transitions agree" in result.stdout


def test_check_locks_without_mechanisms_finds_held_parts_moving_and_exits_1(paper_box):
    result = generate("check-locks", paper_box, "--locks", "latch")
    assert result.returncode == 1, result.stderr
    assert "paper-test-0: 30/90 transitions agree" in result.stdout, result.stdout
    # nothing holds the slide under a door, wherever the door stands in its band
    assert "  open [none], the others at their stops: slide-1 should be held, moved" in result.stdout
    assert "  open [none], the others 20 % inside their bands: slide-1 should be held, moved" in result.stdout


def test_check_locks_names_an_invalid_spec_in_one_line_and_exits_2(tmp_path, paper_box):
    (tmp_path / "bad.json").write_text('{"name": 1}')
    result = generate("check-locks", paper_box, tmp_path / "bad.json")
    assert_one_line_failure(result, "bad.json", "invalid puzzle spec")


@pytest.mark.parametrize("script", ["generate", "trial"])
def test_a_reader_that_closes_stdout_early_ends_nothing(tmp_path, script):
    # (`generate.py paper | head -1` wrote 2 of 12 specs, trial.py ended in a BrokenPipeError traceback)
    specs = tmp_path / "specs"
    args = ["paper", "--split", "all", "--out", specs]
    if script == "trial":
        assert generate("paper", "--split", "test", "--out", specs).returncode == 0
        args = ["--specs", *sorted(specs.glob("*.json")), "--sim", "symbolic", "--agent", "dual", "--runs", 4,
                "--seed", 0, "--max-actions", 30, "--out", tmp_path / "out"]  # fmt: skip
    reader_gone = subprocess.Popen([sys.executable, ROOT / "scripts" / f"{script}.py", *map(str, args)],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    assert reader_gone.stdout is not None
    reader_gone.stdout.close()  # before the script prints anything
    _, err = reader_gone.communicate(timeout=300)
    assert reader_gone.returncode == 0 and "Traceback" not in err and "Broken pipe" not in err, err
    if script == "generate":
        assert len(list(specs.glob("*.json"))) == 12
    else:
        assert len(json.loads((tmp_path / "out" / "results.json").read_text())["runs"]) == 12
