"""Training the memory agent into a SQLite memory, as ``train.py`` does: episode ``e`` on ``specs[e % len(specs)]``
with world seed ``S + e``, in the symbolic simulator or end to end in the twin; each episode stored in one
transaction with its training-log row, so an interrupted run keeps every finished episode. A run is logged
with its command; ``resume`` continues the latest run of the same command, skipping the episodes it stored.
Ctrl-C or SIGTERM stops after the current episode; the log's export (``MEM.sqlite.train.json``) is written
when training ends or stops."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from tqdm import tqdm

from puzzlebox.lab.cli import versions, write_json
from puzzlebox.lab.errors import TrainingError
from puzzlebox.lab.interrupt import StopRequests
from puzzlebox.learning import MemoryAgent, SymbolicWorld, run_episode
from puzzlebox.learning.dual_controller import DualControllerConfig
from puzzlebox.learning.errors import LearningError
from puzzlebox.learning.memory import MemoryStore
from puzzlebox.models import PuzzleSpec

if TYPE_CHECKING:
    from puzzlebox.lab.twin_training import TwinTraining


def training_command(flags: dict[str, Any]) -> dict[str, Any]:
    """The command a training run is logged with (and resumed by): the flags but ``resume``, and ``max_lockers``
    only when not the default (a command from before it existed stays resumable)."""
    command = {key: value for key, value in flags.items() if key != "resume"}
    if command.get("max_lockers") == 1:
        del command["max_lockers"]
    return command


def nothing_to_resume(store: MemoryStore, command: dict) -> str:
    """Why ``store`` holds no run of ``command`` to resume: no training run at all, or how the latest one's command
    differs (the flags whose values differ, as ``--flag theirs (this: ours)``)."""
    runs = store.training_log()
    if not runs:
        return "the memory holds no training run"
    config = dict(cast("dict[str, Any]", runs[-1]["config"]))
    ours = json.loads(json.dumps(command))
    keys = sorted((set(config) | set(ours)) - {"versions", "command"})
    differ = [f"--{key.replace('_', '-')} {config.get(key)!r} (this: {ours.get(key)!r})"
              for key in keys if config.get(key) != ours.get(key)]  # fmt: skip
    return (
        f"none of the memory's {len(runs)} training run(s) was made by this command; the latest differs in "
        f"{', '.join(differ[:4])}{' ...' if len(differ) > 4 else ''}"
    )


def resumed_run(store: MemoryStore, command: dict) -> tuple[int | None, set[int]]:
    """The latest training run in ``store`` made by the same ``command`` (versions aside) and the seeds of the
    episodes it stored; (None, empty) when there is none."""
    for run in reversed(store.training_log()):
        config = dict(cast("dict[str, Any]", run["config"]))  # a run's config: a JSON object
        config.pop("versions", None)
        config.pop("command", None)
        if config == json.loads(json.dumps(command)):
            return run["id"], {e["seed"] for e in run["episodes"]}  # type: ignore[union-attr]
    return None, set()


class MemoryTraining:
    """A training run into the memory file ``memory``, begun (or with ``resume`` continued) for ``command``."""

    def __init__(self, memory: str, command: dict[str, Any], resume: bool) -> None:
        self.memory = memory
        if resume and not Path(memory).exists():
            raise TrainingError(f"--resume: {memory} does not exist, so holds no run to continue; leave out --resume "
                                "to begin one")  # fmt: skip
        try:
            self.store = MemoryStore(memory)
            self.run_id, self.done_seeds = resumed_run(self.store, command) if resume else (None, set())
            if resume and self.run_id is None:
                raise TrainingError(f"--resume: {nothing_to_resume(self.store, command)}; leave out --resume to begin "
                                    "a new run")  # fmt: skip
            if self.run_id is None:
                self.run_id = self.store.begin_training_run({"command": "train", **command, "versions": versions()})
        except LearningError as err:
            raise TrainingError(str(err)) from err
        except sqlite3.OperationalError as err:  # e.g. a read-only directory for SQLite's journal
            raise TrainingError(f"--memory {Path(memory)}: cannot write ({err})") from err

    @property
    def resumed(self) -> int:
        """How many episodes the resumed run had already stored."""
        return len(self.done_seeds)

    def train(
        self,
        specs: list[PuzzleSpec],
        *,
        seed: int,
        episodes: int,
        max_actions: int,
        sim: str,
        controller: DualControllerConfig | None = None,
        twin: TwinTraining | None = None,
    ) -> tuple[int, int]:
        """Run the ``episodes`` episodes not stored yet (in the ``twin`` if given, else symbolically with
        ``controller``) until done or asked to stop: the episodes of the run done, and how many of them this
        call solved."""
        solved, done = 0, len(self.done_seeds)
        with StopRequests("episode") as stop:
            try:
                todo = [e for e in range(episodes) if seed + e not in self.done_seeds]
                for e in tqdm(todo, desc=f"training ({sim})", unit="episode", disable=None):
                    if stop.requested:
                        break
                    spec = specs[e % len(specs)]
                    agent = MemoryAgent(self.store, learn=True, config=controller if twin is None else twin.controller)
                    agent.episode_label, agent.episode_seed, agent.training_run = spec.name, seed + e, self.run_id
                    if twin is None:
                        result = run_episode(agent, SymbolicWorld(spec, seed + e), spec.name, seed + e, max_actions)
                    else:
                        result = twin.episode(agent, spec, seed + e, max_actions)
                    solved, done = solved + result.solved, done + 1
            except KeyboardInterrupt:
                pass
            except LearningError as err:  # the memory refused a write (e.g. its schema changed under the run)
                raise TrainingError(f"{err}; the {done} episode(s) stored before are kept") from err
            except (sqlite3.OperationalError, OSError) as err:  # a full disk, a file made read-only mid-run
                raise TrainingError(
                    f"--memory {self.memory}: cannot write the next episode ({err}); the {done} episode(s) of this "
                    "run stored before are kept in it: free space (or fix the file) and rerun the same command "
                    "with --resume"
                ) from err
        return done, solved

    def finish(self) -> int:
        """Write the export of the file's training log (``MEM.sqlite.train.json``) and close the memory: how
        many episodes it holds."""
        # the log is in the memory file, episode by episode; its export is written once, at the end (reading
        # the whole log after every episode made a long training quadratic)
        try:
            write_json(Path(self.memory + ".train.json"), {"memory": self.memory, "runs": self.store.training_log()})
        except OSError as err:  # the memory holds every episode; only its export is missing
            raise TrainingError(f"cannot write {self.memory}.train.json ({err.strerror or err}); every episode is "
                                f"kept in {self.memory} (scripts/memory.py shows it)") from err  # fmt: skip
        self.store.close()
        return self.store.num_episodes
