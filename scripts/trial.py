"""Run seeded trials of an agent on puzzle specs and write ``DIR/results.json``.

    python scripts/trial.py --specs FILE... --sim symbolic --runs K --seed S --max-actions M \
                            --out DIR [--agent NAME]

Run ``r`` on every spec uses seed ``S + r`` for the world (component order, faults) and the agent.
``DIR/config.json`` records the resolved arguments and package versions, so the result can be re-run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from _cli import fail, versions, write_json
from tqdm import tqdm

from learning import AGENT_NAMES, LearningError, SymbolicWorld, make_agent, run_episode, summarise
from learning.memory import MemoryStore
from models import SpecError, load_spec

SIMS = ("symbolic", "twin")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--specs", nargs="+", required=True, help="puzzle spec files")
    parser.add_argument("--memory", default=None, help="memory file from train.py (memory agent; read only)")
    parser.add_argument("--sim", choices=SIMS, required=True)
    parser.add_argument("--runs", type=int, required=True, help="runs per spec")
    parser.add_argument("--seed", type=int, required=True, help="seed of run 0; run r uses seed + r")
    parser.add_argument("--max-actions", type=int, required=True, help="action budget per run")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--agent", default="memory", help=f"one of {list(AGENT_NAMES)} (default: memory)")
    parser.add_argument("--video", action="store_true", help="record rollout videos (twin only)")
    args = parser.parse_args(argv)
    # The memory is read, never written, during trials: evaluation does not change what was learned.

    if args.runs < 1 or args.max_actions < 1:
        fail("--runs and --max-actions must be >= 1")
    if args.agent not in AGENT_NAMES:
        fail(f"unknown agent {args.agent!r}. Available agents: {sorted(AGENT_NAMES)}")
    if args.sim != "symbolic":
        fail(f"--sim {args.sim} is not available yet; available: ['symbolic']")
    if (args.agent == "memory") != (args.memory is not None):
        fail("--memory goes with --agent memory (and only with it): train one with scripts/train.py")
    if args.video:
        fail("--video needs --sim twin")
    try:
        specs = [load_spec(path) for path in args.specs]
    except SpecError as err:
        fail(str(err))

    try:
        memory = MemoryStore.open_existing(args.memory) if args.memory else None
    except LearningError as err:
        fail(str(err))

    out = Path(args.out)
    write_json(out / "config.json", {"command": "trial", **vars(args), "versions": versions()})
    runs = []
    jobs = [(spec, args.seed + r) for spec in specs for r in range(args.runs)]
    for spec, seed in tqdm(jobs, desc=f"{args.agent} trials", unit="run", disable=None):
        try:
            agent = make_agent(args.agent, spec, memory)
            world = SymbolicWorld(spec, seed)
            runs.append(run_episode(agent, world, spec.name, seed, args.max_actions))
        except LearningError as err:
            fail(f"{spec.name} seed {seed}: {err}")
    results = summarise(runs, args.max_actions)
    write_json(out / "results.json", results)
    print(
        f"{args.agent} on {len(specs)} spec(s) x {args.runs} run(s): success {results['success_rate']:.1%}, "
        f"mean actions {results['mean_actions']:.2f} -> {out / 'results.json'}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
