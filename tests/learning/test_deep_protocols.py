"""The deep agents' protocol jobs: shared between protocols, reused only with the same settings, and
merged into the protocol results where the paper's figures expect them."""

import json

import pytest

from puzzlebox.learning.errors import ConfigError
from puzzlebox.learning.experiments import ProtocolConfig
from puzzlebox.learning.experiments.deep_protocols import DeepSchedule, job_settings, jobs_for, merge_deep_points
from puzzlebox.learning.experiments.report import episodes_to_solve

CONFIG = ProtocolConfig(runs_per_variant=2, training_seeds=2)
SCHEDULE = DeepSchedule(checkpoints=(0, 5, 10), converged_episodes=10, variant_counts=(0, 1, 9))


def test_the_nine_variant_job_is_shared_by_every_protocol():
    keys = {p: {j.key for j in jobs_for(p, ["dqn", "mt-dqn"], CONFIG, SCHEDULE)} for p in ("episodes", "noise")}
    assert keys["episodes"] == keys["noise"] == {"dqn-v9-s0", "dqn-v9-s1", "mt-dqn-v9-s0", "mt-dqn-v9-s1"}
    variants = {j.key for j in jobs_for("variants", ["dqn", "mt-dqn"], CONFIG, SCHEDULE)}
    assert variants == keys["episodes"] | {"dqn-v1-s0", "dqn-v1-s1"}  # no MT-OPT agents in Fig. 3 left


def test_schedules_that_cannot_work_are_config_errors():
    with pytest.raises(ConfigError, match="converged_episodes"):
        DeepSchedule(checkpoints=(0, 10), converged_episodes=20)
    with pytest.raises(ConfigError, match="increasing"):
        DeepSchedule(checkpoints=(10, 0), converged_episodes=10)
    with pytest.raises(ConfigError, match="variant counts"):
        DeepSchedule(variant_counts=(0, 12))


def _record(job, config, success):
    evaluations = [{"episodes": x, "condition": "none", "success_rate": success(x), "mean_actions": 5.0, "runs": 6}
                   for x in job.evaluate_at]  # fmt: skip
    if job.conditions_at is not None:
        evaluations += [{"episodes": job.conditions_at, "condition": c, "success_rate": 0.5, "mean_actions": 9.0,
                         "runs": 6} for c in ("wrong kind", "pose noise", "both", "moved box")]  # fmt: skip
    return {"settings": json.loads(json.dumps(job_settings(job, config))), "evaluations": evaluations}


def test_merged_points_take_each_protocol_value_from_the_right_job_and_count():
    jobs = jobs_for("variants", ["dqn"], CONFIG, SCHEDULE)
    success = {0: 0.0, 5: 1.0, 10: 1.0}
    records = {}
    for job in jobs:
        seed_success = (lambda x: success[x]) if job.seed == 0 else (lambda x: 1.0 if x == 10 else 0.0)
        records[job.key] = _record(job, CONFIG, seed_success)
    base = {"x": "training_episodes", "protocol": "episodes", "config": {}, "points": [{"training_episodes": 0}]}
    episodes = merge_deep_points(base, ["dqn"], records, CONFIG, SCHEDULE)
    by_x = {p["training_episodes"]: p["dqn"] for p in episodes["points"]}
    assert sorted(by_x) == [0, 5, 10] and by_x[5]["success_rate"] == 0.5 and by_x[5]["seeds"] == 2
    assert episodes_to_solve(episodes)["dqn"]["per_seed"] == [5, 10]
    variants = merge_deep_points({**base, "x": "training_variants", "protocol": "variants", "points": []},
                                 ["dqn"], records, CONFIG, SCHEDULE)  # fmt: skip
    by_k = {p["training_variants"]: p["dqn"] for p in variants["points"]}
    assert by_k[0]["success_rate"] == 0.0  # the untrained network: the 9-variant job at 0 episodes
    assert by_k[9]["success_rate"] == 1.0 and by_k[1]["seeds"] == 2
    noise = merge_deep_points({**base, "x": "condition", "protocol": "noise", "points": []},
                              ["dqn"], records, CONFIG, SCHEDULE)  # fmt: skip
    assert [p["condition"] for p in noise["points"]] == ["none", "wrong kind", "pose noise", "both", "moved box"]
    assert noise["points"][1]["dqn"]["success_rate"] == 0.5
