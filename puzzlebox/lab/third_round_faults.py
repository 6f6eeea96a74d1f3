"""The fault suite's third round (``experiment.py faults``; issue 56), each case in a real process as a user runs it:
an agent that misbehaves, inputs that are not regular files, a reader that closes stdout early, the environment
and odd paths, a memory whose contents are bad, boxes given twice, absurd profile values. Each case is one
:class:`Case`: what it runs and what it must end with (the exit code, a phrase of its one line, no traceback, and
whether anything must have been written)."""

from __future__ import annotations

import json
import os
import shutil
import sqlite3
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from puzzlebox.lab.cli import scripts_folder
from puzzlebox.models.generator import paper_family

SCRIPTS = scripts_folder()

AGENTS = """
class OffTheBox:
    name = "off-the-box"
    def begin_episode(self, observation, rng): pass
    def choose(self, observation): return -1
    def record(self, index, result, observation): pass
    def end_episode(self, solved): pass

class Quitter(OffTheBox):
    name = "quitter"
    def choose(self, observation): raise SystemExit(0)
"""
"""A user's module of agents that misbehave (``--agent misbehaving:OffTheBox``)."""


@dataclass(frozen=True)
class Case:
    """One case: the command's arguments (``scripts/<script>.py`` first), the exit code it must end with and a
    phrase its stderr must hold; ``check`` (optional) what must hold of the files afterwards."""

    fault: str
    args: tuple[Any, ...]
    exit_code: int
    says: str
    check: Callable[[], bool] | None = None
    env: dict[str, str] | None = None


def _run(case: Case, cwd: Path) -> tuple[bool, bool]:
    """(detected: the exit code and the phrase, and ``check``; survived: no traceback, no hang)."""
    env = {**os.environ, **(case.env or {})}
    try:
        result = subprocess.run([sys.executable, *map(str, case.args)], capture_output=True, text=True, timeout=300,
                                cwd=cwd, env=env)  # fmt: skip
    except subprocess.TimeoutExpired:
        return False, False
    detected = result.returncode == case.exit_code and case.says in result.stderr + result.stdout
    if case.check is not None:
        detected = detected and case.check()
    return detected, "Traceback" not in result.stderr


def _cases(out: Path, spec: Path) -> list[Case]:
    """Every case of the round, its inputs made in ``out``."""
    (out / "misbehaving.py").write_text(AGENTS)
    fifo = out / "a-fifo.json"
    if not fifo.exists():
        os.mkfifo(fifo)
    memory = out / "bad-kind.sqlite"
    _memory_of_an_unknown_kind(out, spec, memory)
    before = memory.read_bytes()
    renamed = out / "renamed.json"
    renamed.write_text(paper_family("test")[1].to_json().replace('"paper-test-1"', '"paper-test-0"'))
    profile = out / "absurd-profile.json"
    profile.write_text(json.dumps({"camera": {"occluder_count": 1_000_000}}))
    lens = out / "absurd-lens.json"
    lens.write_text(json.dumps(_calibration_with_distortion(spec, 1000.0)))
    loop = out / "loop-a"
    if not loop.is_symlink():
        loop.symlink_to(out / "loop-b")
        (out / "loop-b").symlink_to(loop)
    trial = [SCRIPTS / "trial.py", "--sim", "symbolic", "--runs", 1, "--seed", 0, "--max-actions", 5]
    twin = (SCRIPTS / "trial.py", "--specs", spec, "--sim", "twin", "--runs", 1, "--seed", 0, "--max-actions", 2,
            "--agent", "oracle")  # fmt: skip
    twelve = out / "closed-pipe"
    return [
        Case(
            "an agent that misbehaves",
            (*trial, "--specs", spec, "--agent", "misbehaving:OffTheBox", "--out", out / "o-agent1"),
            1,
            "agent 'off-the-box' chose -1",
        ),  # fmt: skip
        Case(
            "an agent that misbehaves",
            (*trial, "--specs", spec, "--agent", "misbehaving:Quitter", "--out", out / "o-agent2"),
            1,
            "agent 'quitter' raised SystemExit",
        ),  # fmt: skip
        Case(
            "inputs that are not regular files",
            (SCRIPTS / "generate.py", "validate", "/dev/zero"),
            1,
            "not a regular file",
        ),
        Case(
            "inputs that are not regular files",
            (*trial, "--specs", "/dev/urandom", "--agent", "dual", "--out", out / "o-dev"),
            2,
            "not a regular file",
        ),  # fmt: skip
        Case(
            "inputs that are not regular files",
            (*trial, "--specs", fifo, "--agent", "dual", "--out", out / "o-fifo"),
            2,
            "not a regular file",
        ),  # fmt: skip
        Case(
            "a reader that closes stdout early",
            (SCRIPTS / "generate.py", "paper", "--split", "all", "--out", twelve),
            0,
            "",
            check=lambda: len(list(twelve.glob("*.json"))) == 12,
        ),
        Case(
            "the environment and odd paths",
            (*trial, "--specs", spec, "--agent", "dual", "--out", out / "o-gl"),
            2,
            "MUJOCO_GL='eglx' is not a value MuJoCo knows",
            env={"MUJOCO_GL": "eglx"},
        ),
        Case(
            "the environment and odd paths",
            (*trial, "--specs", spec, "--agent", "dual", "--out", loop),
            2,
            "a loop of symbolic links",
        ),
        Case(
            "the environment and odd paths",
            (*trial, "--specs", spec, "--agent", "dual", "--out", ""),
            2,
            "--out is empty",
        ),
        Case(
            "a memory whose contents are bad",
            (*trial, "--specs", spec, "--agent", "memory", "--memory", memory, "--out", out / "o-mem"),
            2,
            "unknown kind",
            check=lambda: memory.read_bytes() == before,
        ),  # fmt: skip
        Case(
            "a memory whose contents are bad",
            (SCRIPTS / "memory.py", memory),
            2,
            "unknown kind",
            check=lambda: memory.read_bytes() == before,
        ),
        Case(
            "boxes given twice",
            (*trial, "--specs", spec, spec, "--agent", "dual", "--out", out / "o-twice"),
            2,
            "the same box",
        ),
        Case(
            "boxes given twice",
            (*trial, "--specs", spec, renamed, "--agent", "dual", "--out", out / "o-names"),
            2,
            "two different boxes of one name",
        ),
        Case("absurd values", (*twin, "--reality", profile, "--out", out / "o-prof"), 2, "occluder_count"),
        Case("absurd values", (*twin, "--calibration", lens, "--out", out / "o-lens"), 2, "radial terms k1 = 1000"),
        Case(
            "absurd values",
            (
                SCRIPTS / "train.py",
                "--specs",
                spec,
                "--episodes",
                2,
                "--memory",
                out / "no-such-memory.sqlite",
                "--resume",
            ),
            2,
            "holds no run to continue",
        ),  # fmt: skip
    ]


def _calibration_with_distortion(spec: Path, k1: float) -> dict[str, Any]:
    """A calibration of ``spec``'s ideal cell whose overview lens has radial distortion ``k1`` (only its form
    matters: it is refused before use)."""
    from puzzlebox.lab.input_faults import ideal_cell_calibration

    data = ideal_cell_calibration(spec)
    data["cameras"]["overview"]["dist"] = [k1, 0.0, 0.0, 0.0, 0.0]
    return data


def _memory_of_an_unknown_kind(out: Path, spec: Path, memory: Path) -> None:
    """A trained memory whose first pair entry names a kind no family knows."""
    if memory.exists():
        return
    trained = out / "trained.sqlite"
    subprocess.run([sys.executable, SCRIPTS / "train.py", "--specs", spec, "--episodes", "1", "--memory", trained],
                   check=True, capture_output=True, timeout=300)  # fmt: skip
    shutil.copy(trained, memory)
    conn = sqlite3.connect(memory)
    with conn:
        conn.execute("UPDATE pair_entries SET kind_i = 'trapdoor' WHERE rowid = (SELECT MIN(rowid) FROM pair_entries)")
    conn.close()


def third_round(out: Path, spec: Path) -> dict[str, dict[str, Any]]:
    """Each class: its cases, how many were detected (the right exit and line) and survived (no traceback, no
    hang), and the cases that were not."""
    out.mkdir(parents=True, exist_ok=True)
    classes: dict[str, dict[str, Any]] = {}
    for case in _cases(out, spec):
        if case.fault == "a reader that closes stdout early":
            detected, survived = _closed_pipe(case, out)
        else:
            detected, survived = _run(case, out)
        row = classes.setdefault(case.fault, {"cases": 0, "detected": 0, "survived": 0, "missed": [], "checked": 0})
        row["cases"] += 1
        row["checked"] += case.check is not None
        row["detected"] += detected
        row["survived"] += survived
        if not (detected and survived):
            row["missed"].append(" ".join(str(a) for a in case.args[1:])[:80])
    return classes


def _closed_pipe(case: Case, cwd: Path) -> tuple[bool, bool]:
    """``case`` run with its stdout's reader gone before it prints anything."""
    process = subprocess.Popen([sys.executable, *map(str, case.args)], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, cwd=cwd)  # fmt: skip
    assert process.stdout is not None
    process.stdout.close()
    try:
        _, err = process.communicate(timeout=300)
    except subprocess.TimeoutExpired:
        process.kill()
        return False, False
    detected = process.returncode == case.exit_code and (case.check is None or case.check())
    return detected, "Traceback" not in err and "Broken pipe" not in err


__all__ = ["Case", "third_round"]
