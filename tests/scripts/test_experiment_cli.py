"""experiment.py --quick runs every symbolic protocol end to end and writes JSON, PNG and tables."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def experiment(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts/experiment.py"), *map(str, args)],
        capture_output=True,
        text=True,
        timeout=600,
    )


@pytest.mark.parametrize("protocol", ["variants", "episodes", "noise"])
def test_quick_protocol_writes_results_plot_and_paper_table(tmp_path, protocol):
    result = experiment(protocol, "--agents", "memory,dual,oracle", "--out", tmp_path, "--quick")
    assert result.returncode == 0, result.stderr
    data = json.loads((tmp_path / f"{protocol}.json").read_text())
    assert (tmp_path / f"{protocol}.png").read_bytes().startswith(b"\x89PNG")
    assert "| figure | agent | ours | paper |" in (tmp_path / f"{protocol}.md").read_text()
    for point in data["points"]:
        assert point["oracle"]["success_rate"] == 1.0 and point["oracle"]["mean_actions"] == 5.0
        assert 0.0 <= point["memory"]["success_rate"] <= 1.0


def test_memory_after_nine_variants_beats_no_memory_in_the_variants_protocol(tmp_path):
    assert experiment("variants", "--agents", "memory", "--out", tmp_path, "--quick").returncode == 0
    points = {
        p["training_variants"]: p["memory"] for p in json.loads((tmp_path / "variants.json").read_text())["points"]
    }
    assert points[9]["mean_actions"] < points[0]["mean_actions"]


def test_unknown_agent_and_unbuilt_protocol_are_clear_errors(tmp_path):
    bad = experiment("variants", "--agents", "memory,genius", "--out", tmp_path, "--quick")
    assert bad.returncode == 2 and "genius" in bad.stderr and "Traceback" not in bad.stderr
    later = experiment("disassembly", "--agents", "memory", "--out", tmp_path)
    assert later.returncode == 2 and "not available yet" in later.stderr
