"""trial.py writes results.json in the contract's form and refuses what it cannot do, clearly."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

from puzzlebox.lab.trial_task import without_timing  # noqa: E402  (a results object less its wall-clock fields)


def run(*args):
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=300)


def test_symbolic_oracle_trial_writes_contract_results(tmp_path):
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    files = sorted(specs.glob("*.json"))
    out = tmp_path / "out"
    result = run(
        ROOT / "scripts/trial.py",
        "--specs",
        *files,
        "--sim",
        "symbolic",
        "--runs",
        2,
        "--seed",
        7,
        "--max-actions",
        15,
        "--out",
        out,
        "--agent",
        "oracle",
    )
    assert result.returncode == 0, result.stderr
    results = json.loads((out / "results.json").read_text())
    assert results["success_rate"] == 1.0 and results["mean_actions"] == 5.0
    assert len(results["runs"]) == 6
    run0 = results["runs"][0]
    assert set(run0) >= {"spec", "seed", "solved", "num_actions", "wall_time_s", "actions"}
    assert run0["spec"] == "paper-test-0" and run0["seed"] == 7 and results["runs"][1]["seed"] == 8
    action = run0["actions"][0]  # the contract's keys, plus the sensed outcome and its reason
    assert {k: action[k] for k in ("component", "moved")} == {"component": "door-0", "moved": True}
    assert action["outcome"] == "moved" and action["reason"] == ""
    config = json.loads((out / "config.json").read_text())
    assert config["agent"] == "oracle" and "versions" in config


def test_trial_refuses_bad_requests_without_traceback(tmp_path):
    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    spec = specs / "paper-test-0.json"
    common = ["--specs", spec, "--runs", 1, "--seed", 0, "--max-actions", 5, "--out", tmp_path / "o"]
    bad_agent = run(ROOT / "scripts/trial.py", *common, "--sim", "symbolic", "--agent", "genius")
    assert bad_agent.returncode == 2 and "Available agents" in bad_agent.stderr
    video = run(ROOT / "scripts/trial.py", *common, "--sim", "symbolic", "--agent", "dual", "--video")
    assert video.returncode == 2 and "Traceback" not in video.stderr and "--sim twin" in video.stderr
    no_memory = run(ROOT / "scripts/trial.py", *common, "--sim", "twin", "--agent", "memory")
    assert no_memory.returncode == 2 and "Traceback" not in no_memory.stderr and "--memory" in no_memory.stderr
    wrong_kind = run(ROOT / "scripts/trial.py", *common, "--sim", "symbolic", "--agent", "dual", "--wrong-kind")
    assert wrong_kind.returncode == 2 and "Traceback" not in wrong_kind.stderr and "--sim twin" in wrong_kind.stderr
    broken = tmp_path / "broken.json"
    broken.write_text("{")
    bad_spec = run(ROOT / "scripts/trial.py", *common[:1], broken, *common[2:], "--sim", "symbolic", "--agent", "dual")
    assert bad_spec.returncode == 2 and "not valid JSON" in bad_spec.stderr


def test_train_then_memory_trial_beats_dual_on_unseen_boxes(tmp_path):
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "all", "--out", specs).returncode == 0
    memory = tmp_path / "memory.sqlite"
    trained = run(
        ROOT / "scripts/train.py",
        "--specs",
        *sorted(specs.glob("paper-train-*.json")),
        "--episodes",
        9,
        "--memory",
        memory,
    )
    assert trained.returncode == 0, trained.stderr
    (logged,) = json.loads((tmp_path / "memory.sqlite.train.json").read_text())["runs"]
    assert logged["config"]["episodes"] == 9 and logged["episodes"][8]["spec"] == "paper-train-8"
    tests = sorted(specs.glob("paper-test-*.json"))
    means = {}
    for agent, extra in (("memory", ["--memory", memory]), ("dual", [])):
        out = tmp_path / agent
        result = run(
            ROOT / "scripts/trial.py",
            "--specs",
            *tests,
            "--sim",
            "symbolic",
            "--runs",
            3,
            "--seed",
            0,
            "--max-actions",
            30,
            "--out",
            out,
            "--agent",
            agent,
            *extra,
        )
        assert result.returncode == 0, result.stderr
        means[agent] = json.loads((out / "results.json").read_text())["mean_actions"]
    assert means["memory"] < means["dual"]


def test_memory_trial_refuses_a_missing_or_foreign_memory(tmp_path):
    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    common = [
        "--specs",
        specs / "paper-test-0.json",
        "--sim",
        "symbolic",
        "--runs",
        1,
        "--seed",
        0,
        "--max-actions",
        5,
        "--out",
        tmp_path / "o",
        "--agent",
        "memory",
    ]
    missing = run(ROOT / "scripts/trial.py", *common, "--memory", tmp_path / "none.sqlite")
    assert missing.returncode == 2 and "no memory file" in missing.stderr
    foreign = tmp_path / "foreign.sqlite"
    foreign.write_bytes(b"this is not a database at all" * 100)
    bad = run(ROOT / "scripts/trial.py", *common, "--memory", foreign)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr and "memory" in bad.stderr


def test_twin_trial_refuses_a_calibration_made_for_another_cell(tmp_path):
    # another profile or box height is refused; another cell seed of the same profile is the cell the file names,
    # and the trial runs in it (tests/lab/test_cells.py)
    import numpy as np

    from puzzlebox.models.calibration import CameraCalibration, CellCalibration

    specs = tmp_path / "specs"
    run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs)
    spec = specs / "paper-test-0.json"
    box_height = json.loads(spec.read_text())["box"]["size"][2]
    K = np.array([[600.0, 0, 319.5], [0, 600.0, 239.5], [0, 0, 1]])
    camera = CameraCalibration(K, np.zeros(5), (640, 480), T_base_camera=np.eye(4))
    common = ["--specs", spec, "--sim", "twin", "--agent", "dual", "--runs", 1, "--seed", 0, "--max-actions", 5]
    for cell, reality, what in (
        ({"profile": "realistic", "cell_seed": 0, "box_height": box_height}, "ideal", "profile 'realistic'"),
        ({"profile": "ideal", "cell_seed": 0, "box_height": box_height + 0.05}, "ideal", "box height"),
    ):
        calibration = CellCalibration({"overview": camera}, cell=cell).save(tmp_path / "cal.json")
        out = tmp_path / "out"
        result = run(
            ROOT / "scripts/trial.py", *common, "--out", out, "--reality", reality, "--calibration", calibration
        )
        assert result.returncode == 2, result.stderr
        assert what in result.stderr and "scripts/calibrate.py --reality" in result.stderr
        assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
        assert not (out / "results.json").exists()


# -- nothing lost: records written as runs end, resume, interrupts ---------------------------------------


def _symbolic_trial(specs, out, runs, *extra):
    return [
        sys.executable, ROOT / "scripts/trial.py", "--specs", *sorted(specs.glob("*.json")), "--sim", "symbolic",
        "--agent", "dual", "--runs", runs, "--seed", 3, "--max-actions", 30, "--out", out, *extra,
    ]  # fmt: skip


def _wait_for_records(out: Path, at_least: int, proc: subprocess.Popen) -> None:
    import time

    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if (out / "runs").is_dir() and len(list((out / "runs").glob("*.json"))) >= at_least:
            return
        time.sleep(0.02)
    raise AssertionError(f"the trial ended or stalled before writing {at_least} records")


def test_a_killed_trial_resumes_with_no_run_lost_or_duplicated(tmp_path):
    import signal

    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    whole = tmp_path / "whole"
    assert subprocess.run(list(map(str, _symbolic_trial(specs, whole, 60))), capture_output=True).returncode == 0
    for k, at in enumerate((1, 47, 133)):  # SIGKILL at three moments: nothing is flushed on the way out
        out = tmp_path / f"killed{k}"
        proc = subprocess.Popen(list(map(str, _symbolic_trial(specs, out, 60))), stderr=subprocess.DEVNULL)
        _wait_for_records(out, at, proc)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        kept = len(list((out / "runs").glob("*.json")))
        assert kept >= at, "every record written before the kill is kept"
        (out / "runs" / ".000-x.json.abc.tmp").write_text("{")  # what a kill in mid-write leaves
        refused = subprocess.run(list(map(str, _symbolic_trial(specs, out, 60))), capture_output=True, text=True)
        assert refused.returncode == 2 and "--resume" in refused.stderr and "Traceback" not in refused.stderr
        resumed = subprocess.run(list(map(str, _symbolic_trial(specs, out, 60, "--resume"))), capture_output=True)
        assert resumed.returncode == 0
        got, want = (json.loads((d / "results.json").read_text()) for d in (out, whole))
        assert len(got["runs"]) == 180 and got["runs_done"] == got["runs_planned"] == 180
        assert without_timing(got) == without_timing(want)
        assert not list(out.rglob("*.tmp")), "the resumed run removed the killed run's half-written file"


def test_sigterm_stops_after_the_current_run_and_says_how_to_resume(tmp_path):
    import signal

    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    out = tmp_path / "out"
    proc = subprocess.Popen(list(map(str, _symbolic_trial(specs, out, 200))), stderr=subprocess.PIPE, text=True)
    _wait_for_records(out, 5, proc)
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "--resume" in stderr and "Traceback" not in stderr
    results = json.loads((out / "results.json").read_text())
    kept = sorted((out / "runs").glob("*.json"))
    assert 5 <= results["runs_done"] == len(results["runs"]) == len(kept) < results["runs_planned"] == 600


def test_an_output_directory_of_another_configuration_is_refused_unless_forced(tmp_path):
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    out = tmp_path / "out"
    assert subprocess.run(list(map(str, _symbolic_trial(specs, out, 2))), capture_output=True).returncode == 0
    other = subprocess.run(list(map(str, _symbolic_trial(specs, out, 3, "--resume"))), capture_output=True, text=True)
    assert other.returncode == 2 and "differs in runs" in other.stderr
    forced = subprocess.run(list(map(str, _symbolic_trial(specs, out, 3, "--force"))), capture_output=True, text=True)
    assert forced.returncode == 0
    assert json.loads((out / "config.json").read_text())["runs"] == 3
    assert len(list((out / "runs").glob("*.json"))) == 9
    a_file = tmp_path / "a-file"
    a_file.write_text("")
    on_file = subprocess.run(list(map(str, _symbolic_trial(specs, a_file, 1))), capture_output=True, text=True)
    assert on_file.returncode == 2 and "is a file" in on_file.stderr and "Traceback" not in on_file.stderr
    negative = subprocess.run(list(map(str, _symbolic_trial(specs, tmp_path / "n", 1, "--seed", -1))),
                              capture_output=True, text=True)  # fmt: skip
    assert negative.returncode == 2 and "error: --seed must be >= 0, got -1" in negative.stderr


def test_train_refuses_an_output_it_cannot_write_before_any_work(tmp_path):
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    spec = specs / "paper-test-0.json"
    blocked = tmp_path / "a-file"
    blocked.write_text("")  # a file where a directory should be: nothing can be created under it
    for flags in (["--memory", blocked / "m.sqlite"], ["--agent", "dqn", "--checkpoint", blocked / "x.pt"]):
        result = run(ROOT / "scripts/train.py", "--specs", spec, "--episodes", 1, *flags)
        assert result.returncode == 2 and "cannot create its directory" in result.stderr, result.stderr
        assert "Traceback" not in result.stderr
    memory = tmp_path / "m.sqlite"
    negative = run(ROOT / "scripts/train.py", "--specs", spec, "--episodes", 1, "--memory", memory, "--seed", -3)
    assert negative.returncode == 2 and "--seed must be >= 0" in negative.stderr


# -- executors: in-process, a local pool, Ray ------------------------------------------------------------


def test_a_twin_trial_gives_the_same_records_in_process_in_the_pool_on_ray_and_resumed_elsewhere(tmp_path):
    """Under the realistic profile (noise, placements, jams drawn from the seed), so the seed matters."""
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    common = [ROOT / "scripts/trial.py", "--specs", specs / "paper-test-1.json", "--sim", "twin", "--agent",
              "oracle", "--runs", 2, "--seed", 11, "--max-actions", 6, "--reality", "realistic"]  # fmt: skip
    results = {}
    for name, flags in {"inline": ["--workers", 1], "pool": ["--workers", 2], "ray": ["--ray", "auto"]}.items():
        result = run(*common, "--out", tmp_path / name, *flags)
        assert result.returncode == 0, result.stderr
        results[name] = json.loads((tmp_path / name / "results.json").read_text())
    runs = results["inline"]["runs"]
    assert runs[0]["sensed_sha256"] != runs[1]["sensed_sha256"], "two seeds sensed two different worlds"
    assert without_timing(results["inline"]) == without_timing(results["pool"]) == without_timing(results["ray"])
    # Resuming on another executor reuses every record: nothing is recomputed (the wall times stay the same).
    again = run(*common, "--out", tmp_path / "pool", "--resume", "--workers", 1)
    assert again.returncode == 0, again.stderr
    assert json.loads((tmp_path / "pool" / "results.json").read_text()) == results["pool"]


def test_executor_mistakes_are_one_line(tmp_path):
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    for flags, message in (
        (["--workers", 0], "--workers must be >= 1"),
        (["--workers", 2, "--ray", "auto"], "give --workers or --ray"),
        (["--ray", "127.0.0.1:1"], "no Ray cluster answers there"),
        (["--ray", "nonsense"], "give auto"),
    ):
        out = tmp_path / "out"
        result = run(*_symbolic_trial(specs, out, 2, *flags)[1:])
        assert result.returncode == 2 and message in result.stderr and "Traceback" not in result.stderr, flags
        assert len(result.stderr.strip().splitlines()) == 1 and not out.exists(), "refused before writing anything"


def test_a_misreported_kind_is_drawn_from_the_seed_and_is_never_the_true_kind():
    from puzzlebox.lab.twin_trial import wrong_kind
    from puzzlebox.models.generator import paper_family

    spec = paper_family("test")[0]
    kinds = {c.name: c.kind for c in spec.components}
    draws = [wrong_kind(spec, seed) for seed in range(60)]
    assert all(len(d) == 1 and kinds[n] != k for d in draws for n, k in d.items())
    assert {n for d in draws for n in d} == set(kinds)  # every component can be the one misreported
    assert draws == [wrong_kind(spec, seed) for seed in range(60)]


def test_a_twin_trial_told_a_wrong_kind_finds_it_within_the_force_margin(tmp_path):
    """The oracle toggles every part on the solution; one of them is told as another kind (seed 3: slide-3 told a
    door): as a door its handle is not where the fingers close, so it is tried as the kinds whose handle stands
    elsewhere, found a slide and moved; the record names the kind found, and the true wrist force stays within the
    45 N margin (the limit is 60 N)."""
    specs = tmp_path / "specs"
    assert run(ROOT / "scripts/generate.py", "paper", "--split", "test", "--out", specs).returncode == 0
    out = tmp_path / "out"
    result = run(ROOT / "scripts/trial.py", "--specs", specs / "paper-test-0.json", "--sim", "twin", "--agent",
                 "oracle", "--runs", 1, "--seed", 3, "--max-actions", 8, "--out", out, "--wrong-kind")  # fmt: skip
    assert result.returncode == 0, result.stderr
    entry = json.loads((out / "results.json").read_text())["runs"][0]
    assert entry["told_kinds"] == {"slide-3": "door"} and entry["found_kinds"] == {"slide-3": "slide"}
    assert entry["solved"] and entry["num_actions"] == 5
    (tried,) = [a for a in entry["timeline"] if a["component"] == "slide-3"]
    assert tried["tried_kinds"] == ["slide"] and tried["moved"] and tried["true_moved"]
    assert entry["peak_true_wrist_force_n"] <= 45.0


def test_state_log_writes_each_twin_run_s_states_beside_its_record(tmp_path):
    from puzzlebox.lab.state_log import load_state_log
    from puzzlebox.models import save_spec
    from puzzlebox.models.generator import generate_chain

    spec = save_spec(generate_chain(["slide", "wheel"], seed=1), tmp_path / "chain.json")
    common = ["--specs", spec, "--runs", 2, "--seed", 0, "--max-actions", 1, "--agent", "oracle"]
    symbolic = run(ROOT / "scripts/trial.py", *common, "--sim", "symbolic", "--out", tmp_path / "s", "--state-log")
    assert symbolic.returncode == 2 and "--state-log needs --sim twin" in symbolic.stderr
    out = tmp_path / "t"
    twin = run(ROOT / "scripts/trial.py", *common, "--sim", "twin", "--out", out, "--state-log", "--workers", 1)
    assert twin.returncode == 0, twin.stderr
    runs = sorted(p.stem for p in (out / "runs").glob("*.json"))
    assert sorted(p.stem for p in (out / "states").glob("*.npz")) == runs and len(runs) == 2
    log, meta = load_state_log(out / "states" / f"{runs[1]}.npz")
    assert meta["seed"] == 1 and log["action"][-1] == 0 and len(log["time"]) > 100
