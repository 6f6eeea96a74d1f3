"""An output is owned by one process at a time: a second writer is refused in one line naming the holder (its pid
and command), exit 2, and writes nothing; the lock is the kernel's, so a killed holder leaves nothing held."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from puzzlebox.lab.errors import OutputInUse, OutputNotADirectory, OutputNotWritable, RunStoreError
from puzzlebox.lab.out_lock import OutputLock, lock_path
from puzzlebox.lab.run_store import RunStore

ROOT = Path(__file__).resolve().parents[2]

HOLDER = """
import sys
from pathlib import Path
from puzzlebox.lab.run_store import RunStore
store = RunStore(Path(sys.argv[1]), {"command": "holder"})
print("held", flush=True)
sys.stdin.readline()  # hold until told
"""


@pytest.fixture
def held(tmp_path):
    """A real process holding ``tmp_path / "out"`` as a trial's run store would; yields (out, its pid)."""
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(out)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True)  # fmt: skip
    assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
    yield out, proc.pid
    proc.communicate("\n", timeout=60)
    assert proc.returncode == 0


def _symbolic_spec(tmp_path: Path) -> Path:
    from puzzlebox.models.generator import paper_family

    path = tmp_path / "spec.json"
    path.write_text(paper_family("test")[0].to_json())
    return path


def _run(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True, timeout=600)


def _refused(result: subprocess.CompletedProcess, pid: int) -> None:
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert "in use by another process" in result.stderr and f"pid {pid}" in result.stderr, result.stderr


def test_a_second_trial_is_refused_naming_the_holder_and_writes_nothing(held, tmp_path):
    out, pid = held
    before = sorted(p.name for p in out.iterdir())
    spec = _symbolic_spec(tmp_path)
    result = _run(ROOT / "scripts/trial.py", "--specs", spec, "--sim", "symbolic", "--agent", "dual", "--runs", 2,
                  "--seed", 0, "--max-actions", 20, "--out", out, "--force")  # fmt: skip
    _refused(result, pid)
    assert "-c" in result.stderr or "holder" in result.stderr or "python" in result.stderr  # the holder's command
    assert sorted(p.name for p in out.iterdir()) == before, "nothing written, nothing removed (not even by --force)"
    assert json.loads((out / "config.json").read_text())["command"] == "holder"


def test_a_second_sweep_is_refused_naming_the_holder(held, tmp_path):
    out, pid = held
    sweep = tmp_path / "sweep.json"
    sweep.write_text(json.dumps({"sim": "symbolic", "generate": {"generator": "random", "components": 4, "count": 1},
                                 "agents": ["oracle"], "max_actions": 20}))  # fmt: skip
    _refused(_run(ROOT / "scripts/sweep.py", sweep, "--out", out, "--resume"), pid)
    assert not (out / "results.json").exists()


def test_the_lock_file_names_the_holder_and_goes_with_it(tmp_path):
    out = tmp_path / "out"
    store = RunStore(out, {"command": "trial"})
    info = json.loads((out / ".lock").read_text())
    assert info["pid"] == os.getpid() and info["command"]
    again = RunStore(out, {"command": "trial"}, resume=True)  # the same process: re-entrant
    again.close()
    assert (out / ".lock").exists(), "still held by the first store"
    store.close()
    assert not (out / ".lock").exists(), "a released lock leaves no file"


def test_a_killed_holder_leaves_nothing_held(tmp_path):
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-c", HOLDER, str(out)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            text=True)  # fmt: skip
    assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
    with pytest.raises(OutputInUse, match=f"pid {proc.pid}"):
        OutputLock(out)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=60)
    assert (out / ".lock").exists(), "a SIGKILL leaves the file"
    with OutputLock(out):  # but not the lock: the kernel dropped it with the process
        assert json.loads((out / ".lock").read_text())["pid"] == os.getpid()


def test_file_outputs_are_locked_beside_them_and_a_directory_or_a_file_in_the_way_is_refused(tmp_path):
    target = tmp_path / "bench.json"
    with OutputLock(target, directory=False) as lock:
        assert lock.path == lock_path(target, directory=False) == tmp_path / ".bench.json.lock"
        assert lock.path.exists()
    assert not lock.path.exists()
    with pytest.raises(OutputNotADirectory, match="is a directory"):
        OutputLock(tmp_path, directory=False)
    (tmp_path / "a-file").write_text("x")
    with pytest.raises(OutputNotADirectory, match="is a file"):
        OutputLock(tmp_path / "a-file")
    with pytest.raises(OutputNotWritable, match="cannot create it"):
        OutputLock(tmp_path / "a-file" / "under")
    assert issubclass(OutputInUse, RunStoreError)


LOCK_HOLDER = """
import sys
from pathlib import Path
from puzzlebox.lab.out_lock import OutputLock
lock = OutputLock(Path(sys.argv[1]), directory=sys.argv[2] == "dir")
print("held", flush=True)
sys.stdin.readline()
"""


@pytest.mark.parametrize(
    ("command", "file_output"),
    [
        (["scripts/render.py", "SPEC", "--out", "OUT"], None),
        (["scripts/calibrate.py", "--out", "OUT/calibration.json"], "calibration.json"),
        (["scripts/bench.py", "--out", "OUT/bench.json", "--quick"], "bench.json"),
        (["scripts/experiment.py", "variants", "--agents", "dual", "--quick", "--out", "OUT"], None),
        (["scripts/generate.py", "random", "--components", "4", "--seed", "0", "--count", "2", "--out", "OUT"], None),
        (
            ["scripts/train.py", "--specs", "SPEC", "--episodes", "1", "--agent", "dqn", "--checkpoint", "OUT/dqn.pt"],
            "dqn.pt",
        ),
    ],
    ids=["render", "calibrate", "bench", "experiment", "generate", "train-checkpoint"],
)
def test_every_command_that_writes_an_output_refuses_a_second_writer(tmp_path, command, file_output):
    out = tmp_path / "out"
    out.mkdir()
    target = out / file_output if file_output else out
    holder = subprocess.Popen([sys.executable, "-c", LOCK_HOLDER, str(target), "file" if file_output else "dir"],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)  # fmt: skip
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        before = sorted(p.name for p in out.iterdir())
        spec = _symbolic_spec(tmp_path)
        words = [str(ROOT / w) if w.startswith("scripts/") else str(spec) if w == "SPEC" else w.replace("OUT", str(out))
                 for w in command]  # fmt: skip
        _refused(_run(*words), holder.pid)
        assert sorted(p.name for p in out.iterdir()) == before, "the refused command wrote nothing"
    finally:
        holder.communicate("\n", timeout=60)
