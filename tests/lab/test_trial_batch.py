"""What a batch of trials says of itself (``puzzlebox.lab.trial_batch``): its ``results.json`` and its last lines."""

from pathlib import Path

from puzzlebox.lab.trial_batch import TrialBatch, batch_results, summary_lines
from puzzlebox.models.generator import paper_family


def test_a_twin_batch_stopped_before_any_run_ended_says_no_run_finished_not_a_rate():
    # (a SIGTERM before the first run ended left "success_rate 0.0, mean_actions 30.0" and twin figures of nothing)
    batch = TrialBatch(specs=tuple(paper_family("test")), runs=2, seed=0, sim="twin", agent="oracle", max_actions=30)
    results = batch_results([], batch, planned=6)
    assert results["success_rate"] is None and results["mean_actions"] is None and results["ended"] == "no run finished"
    assert (results["runs_done"], results["runs_planned"]) == (0, 6) and "outcome_agreement" not in results
    assert summary_lines(results, batch, Path("out")) == [
        "oracle on 3 spec(s) x 2 run(s): no run finished -> out/results.json"
    ]
