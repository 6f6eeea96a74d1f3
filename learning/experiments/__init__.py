"""The paper's experiments: protocols, the paper's numbers, figures and tables."""

from puzzlebox.learning.experiments.protocol import SYMBOLIC_AGENTS, ProtocolConfig, Score, evaluate, train_memory
from puzzlebox.learning.experiments.report import comparison_table, plot, results_table
from puzzlebox.learning.experiments.symbolic_protocols import (
    NOISE_CONDITIONS,
    PROTOCOLS,
    run_episodes,
    run_noise,
    run_variants,
)

__all__ = [
    "NOISE_CONDITIONS",
    "PROTOCOLS",
    "SYMBOLIC_AGENTS",
    "ProtocolConfig",
    "Score",
    "comparison_table",
    "evaluate",
    "plot",
    "results_table",
    "run_episodes",
    "run_noise",
    "run_variants",
    "train_memory",
]
