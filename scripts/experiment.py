"""Run the paper's symbolic protocols and compare with the paper's numbers.

    python scripts/experiment.py {variants,episodes,noise} --agents memory,dual,random,oracle --out DIR [--quick]

Writes ``DIR/<protocol>.json`` (every point, mean and std over training seeds, the settings),
``DIR/<protocol>.png`` (success and mean actions, like the paper's Fig. 3 panels) and
``DIR/<protocol>.md`` (our numbers beside the paper's), and prints the tables.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

from _cli import fail, versions, write_json

from learning.errors import LearningError
from learning.experiments import PROTOCOLS, SYMBOLIC_AGENTS, ProtocolConfig, comparison_table, plot, results_table

PLANNED = ("disassembly",)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("protocol", choices=(*PROTOCOLS, *PLANNED))
    parser.add_argument("--agents", required=True, help=f"comma-separated, from {list(SYMBOLIC_AGENTS)}")
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--quick", action="store_true", help="CI size: few runs, one training seed, 3 points")
    parser.add_argument("--runs", type=int, default=None, help="runs per unseen variant (default 50)")
    parser.add_argument("--seeds", type=int, default=None, help="training seeds (default 3)")
    args = parser.parse_args(argv)

    if args.protocol in PLANNED:
        fail(f"protocol {args.protocol!r} is not available yet; available: {sorted(PROTOCOLS)}")
    agents = [a.strip() for a in args.agents.split(",") if a.strip()]
    unknown = [a for a in agents if a not in SYMBOLIC_AGENTS]
    if not agents or unknown:
        fail(f"unknown agents {unknown or agents}; available: {list(SYMBOLIC_AGENTS)}")
    config = ProtocolConfig()
    if args.quick:
        config = config.quick()
    if args.runs is not None:
        config = replace(config, runs_per_variant=args.runs)
    if args.seeds is not None:
        config = replace(config, training_seeds=args.seeds)
    if config.runs_per_variant < 1 or config.training_seeds < 1:
        fail("--runs and --seeds must be >= 1")

    out = Path(args.out)
    write_json(out / f"{args.protocol}.config.json", {"command": "experiment", **vars(args), "versions": versions()})
    start = time.perf_counter()
    try:
        result = PROTOCOLS[args.protocol](agents, config, quick=args.quick)
    except LearningError as err:
        fail(str(err))
    result["wall_time_s"] = time.perf_counter() - start
    write_json(out / f"{args.protocol}.json", result)
    plot(result, out / f"{args.protocol}.png")
    tables = f"## {args.protocol}: all points (success / mean actions)\n\n{results_table(result)}\n\n"
    tables += f"## {args.protocol}: ours beside the paper\n\n{comparison_table(result)}\n"
    (out / f"{args.protocol}.md").write_text(tables)
    print(tables)
    print(f"{args.protocol}: {result['wall_time_s']:.0f} s -> {out}/{args.protocol}.{{json,png,md}}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
