"""A twin trial's record does not depend on what ran before it in the process: with the renderer, the compiled
scene and the IK model kept from earlier trials (another spec's in between), a trial gives the record it gives
in a fresh process — the same fingerprint of everything sensed, the same actions — apart from wall times."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")


from puzzlebox.lab import TrialConfig, run_trial  # noqa: E402
from puzzlebox.lab.trial_task import without_timing  # noqa: E402
from puzzlebox.models.generator import paper_family  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
MAX_ACTIONS = 1
"""One try after the survey: every cached object (renderer, scene, IK) is used, in a few seconds."""


def _record(spec_index: int, seed: int, reality: str) -> dict:
    spec = paper_family("test")[spec_index]
    config = TrialConfig(agent="oracle", seed=seed, max_actions=MAX_ACTIONS, reality=reality)
    return without_timing(run_trial(spec, config).to_dict())


def test_a_trial_after_others_in_the_process_gives_the_record_of_a_fresh_process():
    first = _record(0, 1, "realistic")
    _record(1, 0, "ideal")  # another spec in between: other cached scene and renderer resources
    again = _record(0, 1, "realistic")
    assert again == first
    code = (
        "import json; from puzzlebox.models.generator import paper_family; "
        "from puzzlebox.lab import TrialConfig, run_trial; from puzzlebox.lab.trial_task import without_timing; "
        f"config = TrialConfig(agent='oracle', seed=1, max_actions={MAX_ACTIONS}, reality='realistic'); "
        "print(json.dumps(without_timing(run_trial(paper_family('test')[0], config).to_dict())))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True, timeout=600,
        env={**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")},
    )  # fmt: skip
    fresh = json.loads(out.stdout.strip().splitlines()[-1])
    assert fresh == json.loads(json.dumps(first))
    assert first["sensed_sha256"] and first["num_actions"] == MAX_ACTIONS
