"""experiment.py stops cleanly on SIGTERM and on SIGINT whatever it inherited (here: SIGINT ignored, as a shell's
``&`` or ``nohup`` leaves it): one line, exit 130, every job saved before kept, and the same command reuses them."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _jobs(out: Path) -> list[str]:
    """The jobs whose records are saved (``KEY.json``; ``KEY.pt`` and ``KEY.pt.json`` are their checkpoints)."""
    return sorted(p.name for p in (out / "jobs").glob("*.json") if not p.name.endswith(".pt.json"))


def test_sigterm_and_an_inherited_ignored_sigint_stop_experiment_py_keeping_its_jobs(tmp_path):
    out = tmp_path / "out"
    command = [sys.executable, str(ROOT / "scripts/experiment.py"), "variants", "--agents", "dqn", "--quick",
               "--workers", "1", "--seeds", "2", "--out", str(out)]  # fmt: skip
    for sig in (signal.SIGTERM, signal.SIGINT):
        before = _jobs(out)
        proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))  # fmt: skip
        deadline = time.monotonic() + 600
        while time.monotonic() < deadline and proc.poll() is None and len(_jobs(out)) <= len(before):
            time.sleep(0.1)
        assert proc.poll() is None, "the experiment ended before a job was saved"
        proc.send_signal(sig)
        _, stderr = proc.communicate(timeout=120)
        assert proc.returncode == 130, (sig.name, stderr)
        lines = [line for line in stderr.splitlines() if line.strip()]
        assert "Traceback" not in stderr and lines[-1].startswith(f"{sig.name}: stopped"), stderr
        assert str(out) in lines[-1] and "resumes" in lines[-1]
        kept = _jobs(out)
        assert len(kept) > len(before) and set(before) <= set(kept), "every saved job is kept"
        assert not (out / ".lock").exists(), "the output is released"
    done = subprocess.run(command, capture_output=True, text=True, timeout=1200)
    assert done.returncode == 0, done.stderr
    reused = len(kept)
    assert f"{reused} reused" in done.stdout, done.stdout
