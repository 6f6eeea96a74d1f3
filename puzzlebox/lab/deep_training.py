"""Training a deep agent (dqn, model-based, mt-dqn, mt-model-based; torch) in the symbolic simulator, as
``train.py --agent DEEP --checkpoint FILE`` does: episode ``e`` on ``specs[e % len(specs)]`` with world seed
``S + e``; the checkpoint and its log (``FILE.train.json``: the command and every episode's outcome) are saved
every 50 episodes and at the end."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tqdm import tqdm

from puzzlebox.lab.cli import write_json
from puzzlebox.learning import SymbolicWorld, run_episode
from puzzlebox.models import PuzzleSpec


def train_deep(
    agent_name: str,
    specs: list[PuzzleSpec],
    *,
    seed: int,
    episodes: int,
    max_actions: int,
    checkpoint: str,
    command: dict[str, Any],
) -> int:
    """Train ``agent_name`` for ``episodes`` episodes into ``checkpoint``, its log headed by ``command``: how many
    episodes it solved."""
    from puzzlebox.learning.baselines import make_learner, save_checkpoint  # torch only when asked

    agent = make_learner(agent_name, seed)
    log = {**command, "runs": []}
    for e in tqdm(range(episodes), desc=f"training {agent_name}", unit="episode", disable=None):
        spec = specs[e % len(specs)]
        result = run_episode(agent, SymbolicWorld(spec, seed + e), spec.name, seed + e, max_actions)
        log["runs"].append({k: v for k, v in result.to_dict().items() if k != "actions"})
        if (e + 1) % 50 == 0 or e + 1 == episodes:  # nothing much lost on a crash
            save_checkpoint(agent, checkpoint)
            write_json(Path(checkpoint + ".train.json"), log)
    return sum(r["solved"] for r in log["runs"])
