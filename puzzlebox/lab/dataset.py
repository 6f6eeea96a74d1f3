"""Datasets of puzzle specs for ``generate.py random|chain ... --count N --out DIR``: spec ``i`` is made
with seed ``S + i`` as a runner task (in parallel), written as ``DIR/<name>.json``, and listed in
``DIR/manifest.json`` (name, seed, file, SHA-256, size, shortest solution). Every byte is a pure function of
the arguments: the same command writes the same files with any number of workers."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from puzzlebox.lab.runner import Task
from puzzlebox.models import LockTable
from puzzlebox.models.atomic import write_text_atomically
from puzzlebox.models.generator import BoxConfig, RandomGraphConfig, generate_chain, generate_random
from puzzlebox.models.kinds import family_named
from puzzlebox.models.lock_table import ReachabilityUndecided
from puzzlebox.models.names import name_slug

MANIFEST = "manifest.json"


def spec_task(key: str, settings: dict[str, Any]) -> Task:
    """The task making one spec (``settings``: generator, its arguments and the seed)."""
    return Task(key, make_spec, settings)


def make_spec(settings: Mapping[str, Any]) -> dict[str, Any]:
    """One spec as its file text, with its manifest entry."""
    box = BoxConfig(fit_reach=not settings["anywhere"])
    name = f"{settings['name']}-s{settings['seed']}" if settings["name"] else None
    if settings["generator"] == "random":
        config = RandomGraphConfig(
            num_components=settings["components"],
            multi_locker=settings["multi_locker"],
            family=family_named(settings.get("kinds", "paper")),
        )
        spec = generate_random(config, seed=settings["seed"], name=name, box=box)
    else:
        spec = generate_chain(settings["kinds"], seed=settings["seed"], name=name, box=box)
    text = spec.to_json()
    try:
        plan = LockTable.from_spec(spec).shortest_solution()
        shortest = [spec.components[i].name for i in plan] if plan is not None else None
    except ReachabilityUndecided:
        shortest = "undecided (search too large)"
    entry = {
        "name": spec.name, "seed": settings["seed"], "file": f"{name_slug(spec.name)}.json",
        "sha256": hashlib.sha256(text.encode()).hexdigest(), "components": len(spec.components),
        "shortest_solution": shortest,
    }  # fmt: skip
    return {"entry": entry, "text": text}


def write_spec(out: Path, record: Mapping[str, Any]) -> Path:
    return write_text_atomically(out / record["entry"]["file"], record["text"])


def write_manifest(out: Path, generator: dict[str, Any], entries: list[dict[str, Any]]) -> Path:
    """``DIR/manifest.json``: the generator's arguments and one entry per spec, in seed order."""
    entries = sorted(entries, key=lambda e: e["seed"])
    text = json.dumps({"generator": generator, "count": len(entries), "specs": entries}, indent=1) + "\n"
    return write_text_atomically(out / MANIFEST, text)
