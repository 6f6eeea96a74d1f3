"""The deep agents' protocol jobs on the task runner: a job file is reused only with the same settings, and the
records written before the runner moved to the composition layer keep their hash."""

import json

from puzzlebox.lab.deep_protocols_run import cached_record, job_task
from puzzlebox.lab.runner import RecordStore
from puzzlebox.learning.experiments import ProtocolConfig
from puzzlebox.learning.experiments.deep_protocols import DeepSchedule, job_settings, jobs_for

CONFIG = ProtocolConfig(runs_per_variant=2, training_seeds=2)
SCHEDULE = DeepSchedule(checkpoints=(0, 5, 10), converged_episodes=10, variant_counts=(0, 1, 9))


def test_a_cached_job_is_reused_only_with_identical_settings(tmp_path):
    job = jobs_for("episodes", ["dqn"], CONFIG, SCHEDULE)[0]
    record = {"settings": json.loads(json.dumps(job_settings(job, CONFIG))), "evaluations": []}
    RecordStore(tmp_path / "jobs").put(job_task(job, CONFIG, tmp_path), record)
    assert cached_record(job, CONFIG, tmp_path) is not None
    assert cached_record(job, ProtocolConfig(runs_per_variant=3, training_seeds=2), tmp_path) is None
    (tmp_path / "jobs" / f"{job.key}.json").write_text("{truncated")
    assert cached_record(job, CONFIG, tmp_path) is None


def test_a_job_keeps_the_hash_its_files_were_written_with(tmp_path):
    # the hash names the task's function: moving run_job_task out of the learning layer would make every
    # finished job file stale (recomputed, hours of training)
    task = job_task(jobs_for("episodes", ["dqn"], CONFIG, SCHEDULE)[0], CONFIG, tmp_path)
    assert task.key == "dqn-v9-s0" and task.context == {"out_dir": str(tmp_path)}
    assert task.settings_hash == "0528067785123cf605f62766cc8cdee74dc25c8f3693827b9e29f3ae5ef5c6dc"
