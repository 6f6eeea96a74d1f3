"""Inspect a memory file: how many episodes it holds, where they come from, and what it knows.

    python scripts/memory.py MEM.sqlite [--json]

Prints the episodes by provenance — the symbolic simulator, or end to end in the twin (with the simulated
robot hours and the reality profiles they were experienced under) — the training runs in the file, and
the entries per kind pair. ``--json`` prints the same as one JSON object. The file is only read.
"""

from __future__ import annotations

import argparse
import json
import sys

from _cli import fail

from learning.errors import MemoryFileError
from learning.memory import MemoryStore


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("memory", help="SQLite memory file (from scripts/train.py)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    args = parser.parse_args(argv)
    try:
        store = MemoryStore.open_existing(args.memory)
    except MemoryFileError as err:
        fail(str(err))
    try:
        report = {
            "memory": args.memory,
            **store.summary(),
            "training_runs": [
                {"id": run["id"], "episodes": len(run["episodes"]), "config": run["config"]}  # type: ignore[arg-type]
                for run in store.training_log()
            ],
        }
    finally:
        store.close()
    if args.json:
        json.dump(report, sys.stdout, indent=1, sort_keys=True)
        print()
        return 0
    provenance = report["provenance"]
    twin = provenance["twin"]
    print(f"{args.memory}: {report['episodes']} episode(s)")
    print(f"  symbolic simulator: {provenance['symbolic']['episodes']} episode(s)")
    profiles = ", ".join(f"{name} {count}" for name, count in sorted(twin["profiles"].items())) or "-"
    print(f"  twin: {twin['episodes']} episode(s), {twin['robot_hours']:.2f} simulated robot hour(s) ({profiles})")
    print(f"  training runs: {len(report['training_runs'])}")
    for bucket, count in report["pair_buckets"].items():
        print(f"  pairs {bucket}: {count}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
