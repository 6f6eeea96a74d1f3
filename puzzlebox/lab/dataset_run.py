"""Making a dataset of specs (``generate.py random|chain ... --count N --out DIR``): the specs of seeds
S..S+N-1 generated in parallel as runner tasks (``puzzlebox.lab.dataset``), each written the moment it is made
(with its top view if asked), and the manifest written once every spec is there. A stop request (Ctrl-C,
SIGTERM) ends the run after the current spec, without a manifest. The directory is owned by one run at a time
(``DIR/.lock``: another run into it is refused, naming it), and holds one dataset: a directory holding anything
else (another dataset's manifest or specs) is refused before anything is written; the same command again, or after
a stop (``DIR/.dataset-started.json`` names the run under way), writes the same files."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tqdm import tqdm

from puzzlebox.lab.dataset import MANIFEST, spec_task, write_manifest, write_spec
from puzzlebox.lab.errors import DatasetError
from puzzlebox.lab.inputs import MAX_COUNT, check_count, check_seed
from puzzlebox.lab.interrupt import StopRequests
from puzzlebox.lab.out_lock import LOCK_NAME, OutputLock
from puzzlebox.lab.runner import RunnerError, make_executor
from puzzlebox.models import load_spec
from puzzlebox.models.atomic import write_text_atomically


@dataclass(frozen=True)
class DatasetRun:
    """What a dataset run wrote: ``written`` of ``count`` specs in ``out``; ``manifest`` None if it stopped."""

    out: Path
    written: int
    count: int
    manifest: Path | None


def make_dataset(
    out: str | Path,
    generator: dict[str, Any],
    *,
    seed: int,
    count: int,
    name: str | None,
    anywhere: bool,
    plot: bool,
    workers: int | None,
    ray: str | None,
) -> DatasetRun:
    """``count`` specs of ``generator`` (its name and arguments) with seeds ``seed``.. in the directory ``out`` and
    ``manifest.json``, on ``workers`` processes (default: one for fewer than 64 specs, else one per core) or on
    Ray (``ray``). :class:`DatasetError` for a count below 1, an output that is a file, a spec that fails or a
    runner that cannot run."""
    if count < 1:
        raise DatasetError(f"--count must be >= 1, got {count}")
    check_count(count, "--count", MAX_COUNT)
    check_seed(seed, "--seed", count)  # spec i from seed S + i
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise DatasetError(f"--out {out} is a file; with --count it names a directory")
    lock = OutputLock(out)  # one dataset run writes a directory at a time
    generator = {**generator, "name": name, "anywhere": anywhere, "seed": seed}
    try:
        _check_one_dataset(out, {**generator, "count": count})
    except DatasetError:
        lock.release()
        raise
    write_text_atomically(out / STARTED, json.dumps({"generator": {**generator, "count": count}}, indent=1) + "\n")
    tasks = [spec_task(f"s{seed + i}", {**generator, "seed": seed + i}) for i in range(count)]
    entries = []
    try:
        executor = make_executor(workers or (1 if count < 64 else None), ray)
        with StopRequests("spec") as stop, executor:
            bar = tqdm(total=len(tasks), desc=f"{generator['generator']} specs", unit="spec", disable=None)
            for done in executor.run(tasks, lambda: stop.requested):
                if not done.ok:
                    raise DatasetError(f"seed {done.task.settings['seed']}: {str(done.payload).splitlines()[0]}")
                path = write_spec(out, done.payload)
                if plot:
                    from puzzlebox.lab.spec_plot import plot_spec  # matplotlib only when asked

                    plot_spec(load_spec(path), path.with_suffix(".png"))
                entries.append(done.payload["entry"])
                bar.update()
            bar.close()
    except RunnerError as err:
        raise DatasetError(str(err)) from err
    if len(entries) < len(tasks):
        lock.release()
        return DatasetRun(out, len(entries), len(tasks), None)
    manifest = write_manifest(out, {**generator, "seed": seed, "count": count}, entries)
    (out / STARTED).unlink(missing_ok=True)  # the manifest says it now
    lock.release()
    return DatasetRun(out, len(entries), len(tasks), manifest)


STARTED = ".dataset-started.json"
"""The generator of a dataset run under way (or stopped) in its directory, written before its first spec."""


def _check_one_dataset(out: Path, generator: dict[str, Any]) -> None:
    """A dataset directory holds one dataset: :class:`DatasetError` if ``out`` holds anything but this run's own
    (its manifest, or the marker of a run of this ``generator`` that stopped, and what they list) and the lock.
    Generated into a folder of another dataset, the old specs stayed beside the new ones under a replaced
    ``manifest.json``."""
    if not out.is_dir():
        return
    found = sorted(p.name for p in out.iterdir() if p.name != LOCK_NAME)
    if not found:
        return
    for record in (out / MANIFEST, out / STARTED):
        if record.is_file():
            try:
                theirs = json.loads(record.read_text()).get("generator")
            except (OSError, ValueError, AttributeError):
                theirs = None
            if theirs == json.loads(json.dumps(generator)):
                return  # this dataset again, or the rest of a stopped run of it
            raise DatasetError(f"--out {out} holds another dataset ({record.name}: {_shown(theirs)}); give a new or "
                               "empty directory")  # fmt: skip
    raise DatasetError(f"--out {out} holds {len(found)} file(s) of no dataset ({', '.join(found[:3])}"
                       f"{', ...' if len(found) > 3 else ''}); give a new or empty directory")  # fmt: skip


def _shown(value: object) -> str:
    text = json.dumps(value)
    return text if len(text) <= 100 else text[:97] + "..."
