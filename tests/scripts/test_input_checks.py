"""Every input is checked in full before any work, by the shared loaders (``models/json_input.py``,
``puzzlebox/lab/inputs.py``, the sweep loader, the calibration and checkpoint loaders), and every mistake is one
line on stderr and exit 2, never a traceback: sweep files of wrong types, JSON nested too deep, seeds and sizes out
of range, an ``--out`` that is a file or read-only, checkpoint metadata out of range, a calibration that is not
rigid or lacks a camera, a profile's ``cell_seed`` below 0; a full disk says what was kept and how to resume.

Most cases call a script's ``main`` in this process (a traceback would be an uncaught exception here); the full
disk is also run for real, in a process writing into a 1 MB tmpfs, where the system allows mounting one."""

from __future__ import annotations

import errno
import importlib
import json
import math
import os
import sqlite3
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from puzzlebox.models.generator import paper_family
from puzzlebox.models.json_input import MAX_DEPTH

ROOT = Path(__file__).resolve().parents[2]
READ_ONLY = Path("/sys/puzzlebox-test-out")  # a place nobody writes, root included


def one_line_exit_2(capsys, script: str, *argv) -> str:
    """Run ``scripts/<script>.py`` in this process; assert it exits 2 with one line on stderr; return the line."""
    main = importlib.import_module(f"puzzlebox.scripts.{script}").main
    capsys.readouterr()
    with pytest.raises(SystemExit) as stopped:
        main(list(map(str, argv)))
    err = capsys.readouterr().err.strip()
    assert stopped.value.code == 2, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in err, err
    return lines[0]


@pytest.fixture(scope="module")
def spec(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("inputs") / "paper-test-0.json"
    path.write_text(paper_family("test")[0].to_json())
    return path


def deep(depth: int = 70_000) -> str:
    """JSON nested ``depth`` levels (140 KB), beyond what ``json.loads`` itself survives."""
    return "[" * depth + "]" * depth


# -- sweep files ----------------------------------------------------------------------------------------------

GOOD = {"sim": "symbolic", "generate": {"generator": "random", "components": 4, "count": 1}, "max_actions": 20,
        "agents": ["oracle"]}  # fmt: skip
SWEEP_CASES = {
    "specs a number": ({k: v for k, v in GOOD.items() if k != "generate"} | {"specs": 5}, "'specs' must be a list"),
    "specs a string": ({k: v for k, v in GOOD.items() if k != "generate"} | {"specs": "dir/*.json"}, "the string"),
    "seeds a string": (GOOD | {"seeds": "a"}, "'seeds' must be"),
    "a seed a string": (GOOD | {"seeds": [1, "a"]}, "'seeds' must be an integer"),
    "seed count a string": (GOOD | {"seeds": {"start": 0, "count": "9"}}, "'count' must be an integer"),
    "a huge seed count": (GOOD | {"seeds": {"start": 0, "count": 10**9}}, "<= 1000000"),
    "a seed beyond 32 bits": (GOOD | {"seeds": [2**40]}, "must be <="),
    "agents of numbers": (GOOD | {"agents": [5]}, "'agents'"),
    "no agents": (GOOD | {"agents": []}, "non-empty"),
    "agents a string": (GOOD | {"agents": "oracle"}, "non-empty list"),
    "no profiles": (GOOD | {"sim": "twin", "profiles": []}, "'profiles' must name at least one"),
    "max_actions a bool": (GOOD | {"max_actions": True}, "'max_actions' must be an integer"),
    "a recipe count a float": (GOOD | {"generate": GOOD["generate"] | {"count": 2.5}}, "'count' must be an integer"),
    "a grid too large": (GOOD | {"seeds": {"start": 0, "count": 600_000}, "agents": ["oracle", "dual"]}, "the grid"),
    "placements of text": (GOOD | {"sim": "twin", "placements": ["x"]}, "'placements' must be"),
    "a calibration for no profile": (GOOD | {"sim": "twin", "calibrations": {"harsh": "c.json"}}, "does not run"),
    "a label with a newline": (GOOD | {"agents": [{"name": "oracle", "label": "a\nb"}]}, "'label' must be printable"),
    "a label with a bar": (GOOD | {"agents": [{"name": "oracle", "label": "a|b"}]}, "without '|'"),
}


@pytest.mark.parametrize("case", sorted(SWEEP_CASES))
def test_sweep_files_of_wrong_types_and_sizes_are_one_line(capsys, tmp_path, case):
    content, message = SWEEP_CASES[case]
    path = tmp_path / "grid.json"
    path.write_text(json.dumps(content))
    assert message in one_line_exit_2(capsys, "sweep", path, "--out", tmp_path / "out")
    assert not (tmp_path / "out").exists(), "nothing written"


# -- JSON nested too deep, in every loader -------------------------------------------------------------------


def test_json_nested_too_deep_is_one_line_in_every_loader(capsys, tmp_path, spec):
    bad = tmp_path / "deep.json"
    bad.write_text(deep())
    shallow_but_deep = tmp_path / "deep-value.json"  # parses, but nests deeper than any input may
    shallow_but_deep.write_text(json.dumps({"name": "x", "components": [[[[[[[]]]]]]] * 1} | {"x": json.loads(
        "[" * (MAX_DEPTH + 5) + "]" * (MAX_DEPTH + 5))}))  # fmt: skip
    out = tmp_path / "out"
    trial = ["--sim", "symbolic", "--agent", "dual", "--runs", 1, "--seed", 0, "--max-actions", 5, "--out", out]
    for path in (bad, shallow_but_deep):
        assert "nested too deep" in one_line_exit_2(capsys, "trial", "--specs", path, *trial)  # a spec
        assert "nested too deep" in one_line_exit_2(capsys, "sweep", path, "--out", out)  # a sweep
    twin = ["--specs", spec, "--sim", "twin", "--agent", "oracle", "--runs", 1, "--seed", 0, "--max-actions", 5,
            "--out", out]  # fmt: skip
    assert "nested too deep" in one_line_exit_2(capsys, "trial", *twin, "--reality", bad)  # a reality profile
    assert "nested too deep" in one_line_exit_2(capsys, "trial", *twin, "--calibration", bad)  # a calibration
    checkpoint = tmp_path / "net.pt"
    checkpoint.write_bytes(b"not read")
    Path(f"{checkpoint}.json").write_text(deep())
    trial[3] = "dqn"
    assert "nested too deep" in one_line_exit_2(capsys, "trial", "--specs", spec, *trial, "--checkpoint", checkpoint)
    from puzzlebox.models.cell_config import CellConfigError, load_cell_config

    with pytest.raises(CellConfigError, match="nested too deep"):  # a real cell's config (trial.py --robot xarm)
        load_cell_config(bad)
    assert not out.exists()


# -- seeds and sizes out of range ----------------------------------------------------------------------------

TRIAL = ["trial", "--specs", "SPEC", "--sim", "symbolic", "--agent", "dual", "--out", "OUT"]
NUMBER_CASES = {
    "train --seed 2**70": (["train", "--specs", "SPEC", "--episodes", 1, "--memory", "OUT/m.sqlite", "--seed", 2**70],
                           "--seed must be <="),
    "train --episodes 1e9": (["train", "--specs", "SPEC", "--episodes", 10**9, "--memory", "OUT/m.sqlite"],
                             "--episodes must be <="),
    "generate chain --seed -1": (["generate", "chain", "--kinds", "door,slide", "--seed", -1, "--out", "OUT/c.json"],
                                 "--seed must be >= 0"),
    "generate paper --seed 2**40": (["generate", "paper", "--split", "test", "--seed", 2**40, "--out", "OUT"],
                                    "--seed must be <="),
    "generate a dataset past the last seed": (["generate", "random", "--components", 4, "--seed", 2**32 - 2,
                                               "--count", 5, "--out", "OUT"], "derived seeds"),
    "calibrate --seed -1": (["calibrate", "--seed", -1, "--out", "OUT/c.json"], "--seed must be >= 0"),
    "calibrate --cell-seed 2**33": (["calibrate", "--cell-seed", 2**33, "--out", "OUT/c.json"], "--cell-seed must"),
    "trial --seed 2**40": ([*TRIAL, "--runs", 1, "--seed", 2**40, "--max-actions", 5], "--seed must be <="),
    "trial --runs 1e9": ([*TRIAL, "--runs", 10**9, "--seed", 0, "--max-actions", 5], "--runs must be <="),
    "trial --max-actions 1e9": ([*TRIAL, "--runs", 1, "--seed", 0, "--max-actions", 10**9],
                                "--max-actions must be <="),
    "render 100000 px": (["render", "SPEC", "--out", "OUT", "--width", 100_000, "--height", 100_000], "--width"),
    "experiment --runs 1e9": (["experiment", "variants", "--agents", "dual", "--runs", 10**9, "--out", "OUT"],
                              "--runs must be <="),
    "experiment --seeds 1e9": (["experiment", "variants", "--agents", "dual", "--seeds", 10**9, "--out", "OUT"],
                               "--seeds must be <="),
    "sweep --workers 1e9": (["sweep", "SPEC", "--workers", 10**9, "--out", "OUT"], "--workers must be <="),
    "bench --trials without --only soak": (["bench", "--trials", 5, "--out", "OUT/b.json"], "--trials goes with"),
    "bench --only soak --trials 0": (["bench", "--only", "soak", "--trials", 0, "--out", "OUT/b.json"],
                                     "must be >= 1"),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(NUMBER_CASES))
def test_seeds_and_sizes_out_of_range_are_one_line_before_any_work(capsys, tmp_path, spec, case):
    argv, message = NUMBER_CASES[case]
    out = tmp_path / "out"
    words = [str(spec) if w == "SPEC" else str(w).replace("OUT", str(out)) for w in argv[1:]]
    assert message in one_line_exit_2(capsys, argv[0], *words)
    assert not out.exists() or not any(out.iterdir()), "nothing written"


# -- an --out that is a file or read-only, refused before the work --------------------------------------------

OUT_CASES = {
    "render": ["render", "SPEC", "--out", "OUT"],
    "experiment": ["experiment", "variants", "--agents", "dual", "--quick", "--out", "OUT"],
    "calibrate": ["calibrate", "--out", "OUT/calibration.json"],
    "bench": ["bench", "--quick", "--scale-trials", 0, "--out", "OUT/bench.json"],
}


@pytest.mark.parametrize("script", sorted(OUT_CASES))
def test_an_out_that_is_a_file_or_read_only_is_refused_before_the_work(capsys, tmp_path, spec, script):
    a_file = tmp_path / "a-file"
    a_file.write_text("not a directory")
    places = {"under a file": a_file / "sub", "read-only": READ_ONLY}
    if script in ("calibrate", "bench"):
        places["a directory"] = tmp_path  # a file output given a directory (bench used to measure, then hang)
    else:
        places["a file"] = a_file
    for what, place in places.items():
        words = [str(spec) if w == "SPEC" else str(w) for w in OUT_CASES[script]]
        words = [w.replace("OUT/calibration.json", str(place)).replace("OUT/bench.json", str(place))
                 .replace("OUT", str(place)) for w in words]  # fmt: skip
        line = one_line_exit_2(capsys, script, *words[1:])
        assert str(place) in line and any(w in line for w in ("file", "directory", "cannot")), (what, line)
    assert a_file.read_text() == "not a directory"


# -- checkpoints, calibrations, profiles: values out of range ------------------------------------------------


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory, spec) -> Path:
    from puzzlebox.scripts import train

    path = tmp_path_factory.mktemp("checkpoint") / "dqn.pt"
    assert train.main(["--specs", str(spec), "--episodes", "1", "--agent", "dqn", "--checkpoint", str(path)]) == 0
    return path


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda m: m["config"]["network"].update(hidden=-5), "hidden must be an integer in [1, 4096], got -5"),
        (lambda m: m["config"].update(epsilon_eval=float("nan")), "NaN is not a JSON number"),
        (lambda m: m["config"].update(epsilon_eval=1.5), "epsilon_eval must be in [0, 1]"),
        (lambda m: m["config"].update(batch_size=0), "batch_size must be"),
        (lambda m: m.update(episodes=-3), "'episodes' must be a count"),
    ],
    ids=["hidden -5", "epsilon_eval NaN", "epsilon_eval 1.5", "batch_size 0", "episodes -3"],
)
def test_checkpoint_metadata_out_of_range_is_one_line(capsys, tmp_path, spec, checkpoint, edit, message):
    copy = tmp_path / "dqn.pt"
    copy.write_bytes(checkpoint.read_bytes())
    meta = json.loads(Path(f"{checkpoint}.json").read_text())
    edit(meta)
    Path(f"{copy}.json").write_text(json.dumps(meta))
    line = one_line_exit_2(capsys, "trial", "--specs", spec, "--sim", "symbolic", "--agent", "dqn", "--checkpoint",
                           copy, "--runs", 1, "--seed", 0, "--max-actions", 5, "--out", tmp_path / "out")  # fmt: skip
    assert message in line


def _calibration(spec: Path) -> dict:
    """A calibration of the ideal cell (not a good one: only its form matters here, it is refused before use)."""
    from puzzlebox.models.calibration import CameraCalibration, CellCalibration

    K = np.array([[600.0, 0, 319.5], [0, 600.0, 239.5], [0, 0, 1]])
    height = json.loads(spec.read_text())["box"]["size"][2]
    cameras = {
        "overview": CameraCalibration(K, np.zeros(5), (640, 480), T_base_camera=np.eye(4)),
        "xarm7/gripper/wrist_camera": CameraCalibration(K, np.zeros(5), (640, 480), T_tcp_camera=np.eye(4)),
    }
    return CellCalibration(cameras, cell={"profile": "ideal", "cell_seed": 0, "box_height": height}).to_dict()


def _scaled(data: dict) -> dict:
    data["cameras"]["overview"]["T_base_camera"] = (np.eye(4) * [1.5, 1.5, 1.5, 1]).tolist()  # rotation x 1.5
    return data


CALIBRATION_CASES = {
    "a camera null": (lambda d: d["cameras"].update(overview=None), "must be an object"),
    "rotation scaled by 1.5": (_scaled, "not a rigid transform"),
    "a reflection": (lambda d: d["cameras"]["overview"].update(T_base_camera=np.diag([1.0, 1, -1, 1]).tolist()),
                     "a reflection"),
    "a last row not 0 0 0 1": (lambda d: d["cameras"]["overview"]["T_base_camera"][3].__setitem__(0, 0.5),
                               "last row"),
    "a translation of 1 km": (lambda d: d["cameras"]["overview"]["T_base_camera"][0].__setitem__(3, 1000.0),
                              "1000.0 m away"),
    "a reprojection error of 40 px": (lambda d: d["cameras"]["overview"].update(reprojection_error_px=40.0),
                                      "reprojection_error_px"),
    "a missing wrist camera": (lambda d: d["cameras"].pop("xarm7/gripper/wrist_camera"), "does not calibrate"),
    "a wrist camera fixed": (lambda d: d["cameras"]["xarm7/gripper/wrist_camera"].update(
        T_base_camera=np.eye(4).tolist(), T_tcp_camera=None), "calibrated as fixed"),
    "cell_seed -1": (lambda d: d["cell"].update(cell_seed=-1), "'cell_seed' must be"),
    "image size of text": (lambda d: d["cameras"]["overview"].update(image_size=["a", 480]), "image_size"),
    "a distortion of 1000": (lambda d: d["cameras"]["overview"].update(dist=[1000.0, 0, 0, 0, 0]),
                             "radial terms k1 = 1000"),
    "fx three times fy": (lambda d: d["cameras"]["overview"]["K"][0].__setitem__(0, 1800.0), "differ by more"),
    "the principal point off the image": (lambda d: d["cameras"]["overview"]["K"][0].__setitem__(2, 3195.0),
                                          "principal point"),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(CALIBRATION_CASES))
def test_a_calibration_that_is_not_rigid_or_lacks_a_camera_is_refused_before_the_arm_moves(capsys, tmp_path, spec,
                                                                                         case):  # fmt: skip
    edit, message = CALIBRATION_CASES[case]
    data = _calibration(spec)
    edit(data)
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(data))
    twin = ["--specs", spec, "--sim", "twin", "--agent", "oracle", "--runs", 1, "--seed", 0, "--max-actions", 5]
    line = one_line_exit_2(capsys, "trial", *twin, "--calibration", path, "--out", tmp_path / "out")
    assert message in line and not (tmp_path / "out").exists()


def test_non_finite_numbers_in_a_calibration_and_a_profile_cell_seed_below_0_are_one_line(capsys, tmp_path, spec):
    data = _calibration(spec)
    data["cameras"]["overview"]["T_base_camera"][0][3] = math.inf
    path = tmp_path / "calibration.json"
    path.write_text(json.dumps(data))  # writes Infinity: not JSON
    common = ["--specs", spec, "--sim", "twin", "--agent", "oracle", "--runs", 1, "--seed", 0, "--max-actions", 5,
              "--out", tmp_path / "o"]  # fmt: skip
    assert "Infinity is not a JSON number" in one_line_exit_2(capsys, "trial", *common, "--calibration", path)
    profile = tmp_path / "profile.json"
    profile.write_text(json.dumps({"name": "mine", "cell_seed": -1}))
    assert "cell_seed: must be an integer" in one_line_exit_2(capsys, "trial", *common, "--reality", profile)
    assert "cell_seed" in one_line_exit_2(capsys, "calibrate", "--reality", profile, "--out", tmp_path / "c.json")


# -- a full disk -----------------------------------------------------------------------------------------------


def test_a_full_disk_in_a_trial_says_what_was_kept_and_how_to_resume(capsys, tmp_path, spec, monkeypatch):
    from puzzlebox.lab.runner import records

    write, calls = records.write_text_atomically, []

    def filling(path, text):
        calls.append(path)
        if len(calls) > 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        return write(path, text)

    monkeypatch.setattr(records, "write_text_atomically", filling)
    out = tmp_path / "out"
    argv = ["--specs", spec, "--sim", "symbolic", "--agent", "dual", "--runs", 8, "--seed", 0, "--max-actions", 30,
            "--out", out]  # fmt: skip
    line = one_line_exit_2(capsys, "trial", *argv)
    assert "No space left on device" in line and "3 finished run(s) are kept" in line and "--resume" in line
    monkeypatch.setattr(records, "write_text_atomically", write)
    from puzzlebox.scripts import trial

    assert trial.main(list(map(str, [*argv, "--resume"]))) == 0  # space again: the same command continues
    assert json.loads((out / "results.json").read_text())["runs_done"] == 8


def test_a_full_disk_in_training_says_what_was_kept_and_how_to_resume(capsys, tmp_path, spec, monkeypatch):
    from puzzlebox.learning.memory import MemoryStore

    add, calls = MemoryStore.add_episode, []

    def filling(self, *args, **kwargs):
        calls.append(1)
        if len(calls) > 2:
            raise sqlite3.OperationalError("database or disk is full")
        return add(self, *args, **kwargs)

    monkeypatch.setattr(MemoryStore, "add_episode", filling)
    memory = tmp_path / "m.sqlite"
    argv = ["--specs", spec, "--episodes", 5, "--memory", memory]
    line = one_line_exit_2(capsys, "train", *argv)
    assert "disk is full" in line and "2 episode(s)" in line and "--resume" in line
    monkeypatch.setattr(MemoryStore, "add_episode", add)
    assert MemoryStore.open_existing(memory).num_episodes == 2


def test_a_real_full_disk_is_one_line_and_the_runs_written_are_whole(tmp_path, spec):
    """trial.py writing into a 1 MB tmpfs until it is full (skipped where the system allows no mount)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1m", "tmpfs", str(disk)], capture_output=True).returncode:
        pytest.skip("cannot mount a tmpfs here")
    try:
        out = disk / "out"
        result = subprocess.run(
            [sys.executable, str(ROOT / "scripts/trial.py"), "--specs", str(spec), "--sim", "symbolic", "--agent",
             "dual", "--runs", "3000", "--seed", "0", "--max-actions", "30", "--out", str(out)],
            capture_output=True, text=True, timeout=900,
        )  # fmt: skip
        assert result.returncode == 2, result.stderr[-2000:]
        last = result.stderr.strip().splitlines()[-1]
        assert "Traceback" not in result.stderr and "No space left on device" in last and "--resume" in last, last
        kept = sorted((out / "runs").glob("*.json"))
        assert kept and all(json.loads(p.read_text())["record"]["seed"] >= 0 for p in kept), "every kept run whole"
    finally:
        subprocess.run(["umount", str(disk)], check=False)


@pytest.mark.parametrize(
    ("script", "argv", "says"),
    [
        ("trial", ["--specs", "x.json", "--sim", "moon"], "argument --sim: invalid choice: 'moon'"),
        ("generate", ["teleport"], "invalid choice: 'teleport'"),
        ("generate", ["mjcf"], "the following arguments are required: spec, --out (see "),
        ("experiment", ["hard-sets", "--out", "x", "--calibration", "sometimes"], "invalid choice: 'sometimes'"),
        ("train", ["--specs", "x.json", "--episodes", "many"], "argument --episodes: invalid int value: 'many'"),
        ("sweep", [], "the following arguments are required"),
    ],
)
def test_an_argument_the_parser_refuses_is_one_line_without_the_usage(capsys, script, argv, says):
    line = one_line_exit_2(capsys, script, *argv)
    assert says in line and "usage:" not in line, line


# -- empty arguments ------------------------------------------------------------------------------------------

TRIAL = ["--sim", "symbolic", "--runs", "1", "--seed", "0", "--max-actions", "3"]
EMPTY_CASES = [
    ("trial", ["--specs", "{spec}", *TRIAL, "--out", ""], "--out is empty"),
    ("trial", ["--specs", "", *TRIAL, "--out", "x"], "--specs is empty"),
    ("sweep", ["{spec}", "--out="], "--out is empty"),
    ("render", ["--spec", "{spec}", "--out", " "], "--out is empty"),
    ("generate", ["paper", "--split", "test", "--out", ""], "--out is empty"),
    ("calibrate", ["--out", ""], "--out is empty"),
]  # fmt: skip


@pytest.mark.parametrize(("script", "argv", "says"), EMPTY_CASES, ids=[f"{c[0]}-{c[2]}" for c in EMPTY_CASES])
def test_an_empty_argument_is_refused_before_anything_is_written(
    capsys, tmp_path, monkeypatch, spec, script, argv, says
):
    # an unset shell variable (--out "$OUT") wrote into the current folder
    monkeypatch.chdir(tmp_path)
    line = one_line_exit_2(capsys, script, *(a.replace("{spec}", str(spec)) for a in argv))
    assert says in line
    assert not any(tmp_path.iterdir())


# -- inputs that are not regular files -------------------------------------------------------------------------


@pytest.fixture
def fifo(tmp_path) -> Path:
    path = tmp_path / "a-fifo.json"
    os.mkfifo(path)
    return path


def test_a_device_or_a_fifo_as_an_input_is_refused_without_reading_it(capsys, tmp_path, fifo):
    # /dev/zero was read until the kernel killed the process (23.7 GB), a FIFO blocked for ever
    for source in ("/dev/zero", "/dev/urandom", fifo):
        line = one_line_exit_2(capsys, "trial", "--specs", source, *TRIAL, "--agent", "dual", "--out", tmp_path / "o")
        assert "not a regular file" in line
        assert "not a regular file" in one_line_exit_2(capsys, "sweep", source, "--out", tmp_path / "s")
    assert not (tmp_path / "o").exists() and not (tmp_path / "s").exists()


def test_an_input_read_is_bounded_whatever_the_file_claims(tmp_path, monkeypatch):
    from puzzlebox.models import json_input

    path = tmp_path / "big.json"
    path.write_text("[" + "0," * 600 + "0]")
    monkeypatch.setattr(json_input, "MAX_FILE_BYTES", 1000)
    with pytest.raises(json_input.JsonInputError, match="too large"):
        json_input.read_input_text(path)


@pytest.mark.parametrize("script", ["trial", "generate", "render"])
def test_a_mujoco_gl_typo_is_one_line(script):
    # MuJoCo refuses it at its first import, before a script's own checks: a 16-22-line traceback
    env = {**os.environ, "MUJOCO_GL": "eglx"}
    result = subprocess.run([sys.executable, ROOT / "scripts" / f"{script}.py", "--help"], env=env,
                            capture_output=True, text=True, timeout=120)  # fmt: skip
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert result.stderr.strip() == ("error: MUJOCO_GL='eglx' is not a value MuJoCo knows: egl (headless), osmesa, "
                                     "glfw or glx, or unset")  # fmt: skip


def test_an_out_that_is_a_loop_of_links_is_one_line(capsys, tmp_path, spec):
    (tmp_path / "a").symlink_to(tmp_path / "b")
    (tmp_path / "b").symlink_to(tmp_path / "a")
    line = one_line_exit_2(capsys, "trial", "--specs", spec, *TRIAL, "--agent", "dual", "--out", tmp_path / "a")
    assert "a loop of symbolic links" in line


def test_a_path_that_is_not_utf8_is_printed_escaped(tmp_path, spec):
    # a byte the shell passes as is (0xff): UnicodeEncodeError tracebacks under a strict UTF-8 stdout
    out = os.fsencode(tmp_path) + b"/out\xff"
    env = {**os.environ, "PYTHONIOENCODING": "utf-8:strict"}
    argv = [sys.executable, str(ROOT / "scripts/trial.py"), "--specs", str(spec), *TRIAL, "--agent", "dual", "--out"]
    result = subprocess.run([*map(os.fsencode, argv), out], env=env, capture_output=True, timeout=300)
    assert result.returncode == 0 and b"Traceback" not in result.stderr, result.stderr
    assert b"out\\udcff" in result.stdout and os.path.exists(out + b"/results.json")


def test_a_box_given_twice_or_two_boxes_of_one_name_are_refused(capsys, tmp_path, spec):
    # overlapping globs ran the same spec and seed twice; two boxes of one name were summed as one
    renamed = tmp_path / "other.json"
    renamed.write_text(paper_family("test")[1].to_json().replace('"paper-test-1"', '"paper-test-0"'))
    for second, says in ((spec, "the same box, 'paper-test-0'"), (renamed, "two different boxes of one name")):
        line = one_line_exit_2(capsys, "trial", "--specs", spec, second, *TRIAL, "--agent", "dual", "--out",
                               tmp_path / "o")  # fmt: skip
        assert says in line
    assert not (tmp_path / "o").exists()


def test_a_recording_that_cannot_be_written_is_refused_before_any_run(capsys, tmp_path, spec):
    # (every run failed at its end with a PermissionError, and left an --out that a plain rerun refused)
    line = one_line_exit_2(capsys, "trial", "--specs", spec, "--sim", "twin", "--runs", "1", "--seed", "0",
                           "--max-actions", "2", "--agent", "oracle", "--record", READ_ONLY.parent / "x.rrd",
                           "--out", tmp_path / "o")  # fmt: skip
    assert "cannot be written" in line and not (tmp_path / "o").exists()


def test_train_resume_with_no_run_of_the_command_is_refused_naming_what_differs(capsys, tmp_path, spec):
    """``--resume`` continues the latest run of the same command; with none, it began a new run in silence (a
    changed ``--episodes`` trained the memory twice over). Now one line names the flags the latest run differs in,
    and the memory is unchanged."""
    from puzzlebox.learning.memory import MemoryStore
    from puzzlebox.scripts import train

    memory = tmp_path / "m.sqlite"
    common = ["--specs", spec, "--memory", memory, "--seed", 0]
    line = one_line_exit_2(capsys, "train", *common, "--episodes", 2, "--resume")
    assert "does not exist, so holds no run to continue; leave out --resume" in line and not memory.exists()
    MemoryStore(memory).close()
    line = one_line_exit_2(capsys, "train", *common, "--episodes", 2, "--resume")
    assert "--resume: the memory holds no training run; leave out --resume" in line
    assert train.main(list(map(str, [*common, "--episodes", 2]))) == 0
    before = memory.read_bytes()
    line = one_line_exit_2(capsys, "train", *common, "--episodes", 3, "--resume")
    assert "none of the memory's 1 training run(s) was made by this command" in line
    assert "--episodes 2 (this: 3)" in line and memory.read_bytes() == before
    assert train.main(list(map(str, [*common, "--episodes", 2, "--resume"]))) == 0  # the same command resumes


def test_a_belief_too_large_to_decide_in_is_refused_before_any_run(capsys, tmp_path):
    """62 parts at --max-lockers 3 would hold 38 million probabilities (~8 min a decision) and ran 300 s without a
    word; the belief's size is checked for every spec before anything runs, naming the largest k that fits. The
    learning layer refuses it alike where the table would be built."""
    from puzzlebox.learning import ConfigError
    from puzzlebox.learning.locker_sets import MAX_BELIEF_ENTRIES, locker_sets, set_count
    from puzzlebox.models.generator import generate_chain

    path = tmp_path / "chain24.json"
    path.write_text(generate_chain(["slide", "door"] * 12, seed=0).to_json())
    line = one_line_exit_2(capsys, "trial", "--specs", path, "--sim", "symbolic", "--agent", "dual", "--max-lockers",
                           3, "--runs", 1, "--seed", 0, "--max-actions", 5, "--out", tmp_path / "o")  # fmt: skip
    assert "--max-lockers 3 on" in line and "832,560 probabilities" in line and "use max_lockers 2 or fewer" in line
    assert not (tmp_path / "o").exists()
    assert 24 * 2 * set_count(24, 2) <= MAX_BELIEF_ENTRIES < 24 * 2 * set_count(24, 3)
    with pytest.raises(ConfigError, match="62 parts holds 38,470,876 probabilities"):
        locker_sets(62, 3)


def test_a_sweep_over_two_boxes_of_one_name_or_one_box_twice_is_refused(capsys, tmp_path):
    """Cells are named by their box: two different boxes named ``random-n5-s0`` (generated with ``--kinds paper`` and
    ``--kinds all``) were reported as one cell of both, and overlapping globs ran one box twice."""
    from puzzlebox.models.generator import RandomGraphConfig, generate_random
    from puzzlebox.models.kinds import family_named

    for folder, family in (("paper", "paper"), ("all", "all")):
        (tmp_path / folder).mkdir()
        spec = generate_random(RandomGraphConfig(num_components=5, family=family_named(family)), seed=0)
        (tmp_path / folder / "box.json").write_text(spec.to_json())
    sweep = tmp_path / "grid.json"
    for globs, message in ((["paper/*.json", "all/*.json"], "two different boxes of one name"),
                           (["paper/*.json", "paper/box*.json"], "the same box")):  # fmt: skip
        sweep.write_text(json.dumps({"sim": "symbolic", "specs": globs, "agents": ["oracle"], "max_actions": 5}))
        line = one_line_exit_2(capsys, "sweep", sweep, "--out", tmp_path / "out")
        assert f"'specs' match {message}" in line and not (tmp_path / "out").exists()


def test_calibrate_on_a_full_disk_keeps_the_calibration_and_says_where(capsys, tmp_path, monkeypatch):
    """The procedure ran to its end, then the write failed with a traceback and the calibration was lost; now one line
    (exit 1) names where it is kept, a file in the temporary folder that loads as the calibration made."""
    from puzzlebox.models.calibration import CellCalibration
    from puzzlebox.scripts import calibrate

    save, target = CellCalibration.save, tmp_path / "cal.json"

    def full_at_the_target(self, path):
        if Path(path) == target:
            raise OSError(errno.ENOSPC, "No space left on device")
        return save(self, path)

    monkeypatch.setattr(CellCalibration, "save", full_at_the_target)
    monkeypatch.setenv("TMPDIR", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", None)  # (re-read TMPDIR)
    capsys.readouterr()
    with pytest.raises(SystemExit) as stopped:
        calibrate.main(["--out", str(target), "--overview-views", "6", "--wrist-views", "6"])
    err = capsys.readouterr().err.strip()
    assert stopped.value.code == 1 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert "cannot write" in err and "No space left on device" in err and "the calibration is kept in" in err
    kept = Path(err.split("kept in ")[1].split(":")[0])
    assert kept.parent == tmp_path / "tmp" and set(CellCalibration.load(kept).cameras) == {
        "overview", "xarm7/gripper/wrist_camera"}  # fmt: skip
    assert not target.exists()


def test_paths_with_bytes_that_are_not_utf8_are_written_and_resumed(tmp_path, spec):
    """A byte of a non-UTF-8 path reaches Python as a lone surrogate (``\\udcff``); every file that names the path
    (a trial's config, its report) ended in a ``UnicodeEncodeError`` traceback. It is written as its JSON escape, which
    reads back to the same path: the trial runs, resumes and reports."""
    from puzzlebox.scripts import report, trial

    out, box = tmp_path / "r\udcffsults", tmp_path / "b\udcfex.json"
    box.write_bytes(spec.read_bytes())
    common = ["--specs", str(box), "--sim", "symbolic", "--agent", "dual", "--runs", "1", "--seed", "0",
              "--max-actions", "5", "--out", str(out)]  # fmt: skip
    assert trial.main(common) == 0 and (out / "results.json").is_file()
    assert json.loads((out / "config.json").read_text())["specs"] == [str(box)]
    assert trial.main([*common, "--resume"]) == 0  # the configuration read back equals this one
    assert report.main([str(out)]) == 0 and (out / "report.html").is_file()


def test_a_box_out_of_reach_is_refused_before_any_run(capsys, tmp_path, spec):
    """A box pose out of the arm's reach, or a profile whose placement range holds no reachable pose, failed every
    run at its start and left an ``--out`` that a plain rerun refused; now one line before anything is written."""
    data = json.loads(spec.read_text())
    data["box"]["pose"] = [1.6, 0.0, 0.0]
    far = tmp_path / "far.json"
    far.write_text(json.dumps(data))
    twin = ["--sim", "twin", "--agent", "oracle", "--runs", 1, "--seed", 0, "--max-actions", 3, "--out", tmp_path / "o"]
    line = one_line_exit_2(capsys, "trial", "--specs", far, *twin)
    assert "box pose [1.6, 0.0, 0.0] puts handles outside the arm's reach" in line
    profile = tmp_path / "range.json"
    profile.write_text(json.dumps({"name": "far-range", "placement": {"x": [1.5, 1.6]}}))
    line = one_line_exit_2(capsys, "trial", "--specs", spec, *twin, "--reality", profile)
    assert "placement holds no reachable pose" in line and not (tmp_path / "o").exists()
