"""Inspect a memory file: how many episodes it holds, where they come from, and what it knows.

    python scripts/memory.py MEM.sqlite [--json] [--migrate]

Prints the episodes by provenance — the symbolic simulator, or end to end in the twin (with the simulated
robot hours and the reality profiles they were experienced under) — the training runs in the file, and
the entries per kind pair, the key scales and the file's schema. ``--json`` prints the same as one JSON
object. The file is only read, unless ``--migrate``: a file of an older schema (compact planar or Euler keys,
schemas 1-3) is brought to the current one in place — keys rewritten as SE(3) keys, in one transaction, so a
crash leaves the old file whole. Reading and training an old file need no migration (training migrates it).
"""

from __future__ import annotations

import argparse
import json
import sys

from puzzlebox.lab.cli import OneLineParser, fail, run_script
from puzzlebox.learning.errors import MemoryFileError
from puzzlebox.learning.memory import MemoryStore


def main(argv: list[str] | None = None) -> int:
    parser = OneLineParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("memory", help="SQLite memory file (from scripts/train.py)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--migrate", action="store_true", help="bring an older file to the current schema in place")
    args = parser.parse_args(argv)
    try:
        store = MemoryStore.open_existing(args.memory)
    except MemoryFileError as err:
        fail(str(err))
    try:
        if args.migrate:
            before = store.schema
            store.migrate()
            if before != store.schema:
                print(f"{args.memory}: migrated from schema {before} to {store.schema}", file=sys.stderr)
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
    print(
        f"  schema {report['schema']}; keys: SE(3), {report['position_scale']} m and {report['rotation_weight']} per "
        "unit of rotation chord weigh one key unit"
    )
    for bucket, count in report["pair_buckets"].items():
        print(f"  pairs {bucket}: {count}")
    return 0


if __name__ == "__main__":
    run_script(main)
