"""experiment.py kinds: boxes of every registered kind, symbolic and in the twin, from the project's own commands."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

from puzzlebox.lab.kinds_experiment import KindsConfig, five_kind_chains, make_specs  # noqa: E402
from puzzlebox.models import LockTable, load_spec  # noqa: E402
from puzzlebox.models.kinds import registry_family  # noqa: E402


def experiment(*args):
    return subprocess.run(
        [sys.executable, str(ROOT / "scripts/experiment.py"), "kinds", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=900,
    )


def test_every_chain_of_the_registry_kinds_is_an_allowed_order_once():
    family = registry_family()
    chains = five_kind_chains()
    assert len(chains) == len(set(chains)) > 0
    for order in chains:
        assert sorted(order) == sorted(family.kinds)
        assert all(family.may_neighbour(a, b) for a, b in zip(order, order[1:], strict=False))


def test_the_test_chains_are_held_out_of_training_and_every_spec_is_solvable(tmp_path):
    sets = make_specs(tmp_path, KindsConfig(random_boxes=4))
    assert len(sets["test"]) == 3 and len(sets["train"]) == len(five_kind_chains()) - 3
    assert not {p.name for p in sets["test"]} & {p.name for p in sets["train"]}
    assert make_specs(tmp_path / "again", KindsConfig(random_boxes=4))["test"][0].name == sets["test"][0].name
    for path in [*sets["test"], *sets["random"]]:
        assert LockTable.from_spec(load_spec(path)).shortest_solution() is not None


def test_quick_run_solves_the_boxes_symbolically_and_in_the_twin_and_resumes(tmp_path):
    result = experiment("--out", tmp_path, "--quick", "--workers", "1")
    assert result.returncode == 0, result.stderr[-2000:]
    summary = json.loads((tmp_path / "kinds.json").read_text())
    assert set(summary["sets"]) == {"symbolic-chains", "symbolic-random", "twin-ideal", "twin-random-ideal"}
    assert summary["sets"]["symbolic-chains"]["success_rate"] == 1.0
    assert summary["sets"]["twin-ideal"]["outcome_agreement"] == 1.0
    assert summary["sets"]["twin-ideal"]["runs"] == 3  # the 3 held-out chains, one seed each
    assert (tmp_path / "kinds.png").read_bytes().startswith(b"\x89PNG")
    assert "| twin-ideal | 3 |" in (tmp_path / "kinds.md").read_text()
    again = experiment("--out", tmp_path, "--quick", "--workers", "1")  # every step resumes: nothing run again
    assert again.returncode == 0, again.stderr[-2000:]
    assert json.loads((tmp_path / "kinds.json").read_text())["sets"] == summary["sets"]


def test_options_of_other_protocols_are_one_line_mistakes(tmp_path):
    result = experiment("--out", tmp_path, "--agents", "memory")
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and "--agents" in result.stderr
