"""Where tasks run: in this process, in a local pool of worker processes, or on a Ray cluster.

Each executor is a context manager whose :meth:`run` yields a :class:`Completion` per task as tasks end
(not in submission order), submitting no more than it has workers for, so that a stop request is honoured
after the tasks in flight. Workers live as long as the executor: what a task function caches per process
(an EGL context, a compiled model, an opened memory) serves every later task of that worker.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from puzzlebox.lab.runner.errors import RunnerError
from puzzlebox.lab.runner.task import Task, execute

MAX_BARREN_RESTARTS = 5
"""Pool restarts in a row with no task finished after which the pool gives up (workers that cannot start)."""

ONE_THREAD = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
"""Thread-count variables set to 1 for workers: one worker per core, no BLAS threads fighting over them."""


@dataclass(frozen=True)
class Completion:
    """A task that ended: ``ok`` with its record as ``payload``, or not, with the error's text."""

    task: Task
    ok: bool
    payload: Any


class Executor(Protocol):
    name: str
    workers: int

    def __enter__(self) -> Executor: ...
    def __exit__(self, *exc: object) -> None: ...
    def run(self, tasks: Iterable[Task], stop: Callable[[], bool]) -> Iterator[Completion]: ...


class InlineExecutor:
    """Every task in this process, one after another (what a debugger and the smallest tasks want)."""

    name = "in-process"
    workers = 1

    def __enter__(self) -> InlineExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        pass

    def run(self, tasks: Iterable[Task], stop: Callable[[], bool]) -> Iterator[Completion]:
        for task in tasks:
            if stop():
                return
            ok, payload = execute(task.function, task.settings, task.context)
            yield Completion(task, ok, payload)


@contextlib.contextmanager
def _sigint_blocked() -> Iterator[None]:
    """SIGINT held back in this thread for the duration (delivered after, not lost). A worker spawned meanwhile
    inherits the blocked signal through fork and exec, so a Ctrl-C to the process group never interrupts its
    start-up (its imports can take seconds): the driver alone decides what Ctrl-C does."""
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def _worker_init(parent: int) -> None:
    """Leave Ctrl-C to the driver (it stops after the tasks in flight) and exit if the driver dies
    (a SIGKILLed driver must not leave workers computing records nobody will write)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # and it stays blocked (see _sigint_blocked)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


class PoolExecutor:
    """``workers`` processes (spawned: torch, EGL and fork do not mix), each running tasks one at a time.

    A worker that dies (killed, out of memory, a crash in C) breaks the pool: the executor starts a new
    one and reruns the tasks that were in flight, one at a time, to learn which one kills its worker; a task
    whose worker died alone ``max_attempts`` times is reported as failed (``WorkerDied``), not retried
    forever, and the others go on.
    """

    name = "pool"

    def __init__(self, workers: int | None = None, max_attempts: int = 3) -> None:
        self.workers = workers or os.cpu_count() or 1
        if self.workers < 1:
            raise RunnerError(f"workers must be >= 1, got {self.workers}")
        self.max_attempts = max_attempts
        self._pool: ProcessPoolExecutor | None = None
        self.restarts = 0
        """How many times a dead worker made the pool start over."""

    def _start(self) -> ProcessPoolExecutor:
        import multiprocessing

        for var in ONE_THREAD:
            os.environ.setdefault(var, "1")  # inherited by the spawned workers
        return ProcessPoolExecutor(
            self.workers, multiprocessing.get_context("spawn"), initializer=_worker_init, initargs=(os.getpid(),)
        )

    def __enter__(self) -> PoolExecutor:
        self._pool = self._start()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._pool is not None:
            self._shutdown(cancel=exc[0] is not None)
            self._pool = None

    def _shutdown(self, cancel: bool) -> None:
        pool = self._pool
        if pool is None:
            return
        if cancel:  # interrupted: do not wait for tasks in flight
            for process in list(getattr(pool, "_processes", {}).values()):
                process.terminate()
        pool.shutdown(wait=True, cancel_futures=True)

    def run(self, tasks: Iterable[Task], stop: Callable[[], bool]) -> Iterator[Completion]:
        if self._pool is None:
            raise RunnerError("PoolExecutor.run outside its with-block")
        pending: deque[Task] = deque(tasks)
        suspects: deque[Task] = deque()  # in flight when a worker died: rerun alone, to learn which one kills
        deaths: dict[str, int] = {}
        in_flight: dict[Future, Task] = {}
        restarts_at_last_completion = self.restarts
        try:
            while pending or suspects or in_flight:
                broken = False
                try:
                    if suspects:
                        if not in_flight and not stop():
                            self._submit(suspects, in_flight)
                    else:
                        while pending and len(in_flight) < self.workers and not stop():
                            self._submit(pending, in_flight)
                except BrokenProcessPool:  # a worker died since the last look: its task is still in flight
                    broken = True
                if not in_flight and not broken:
                    return
                dead = []
                if not broken:
                    done, _ = wait(in_flight, timeout=0.5, return_when=FIRST_COMPLETED)
                    for future in done:
                        task = in_flight.pop(future)
                        try:
                            ok, payload = future.result()
                        except BrokenProcessPool:
                            dead.append(task)
                            continue
                        restarts_at_last_completion = self.restarts
                        yield Completion(task, ok, payload)
                    if not dead:
                        continue
                for future, task in list(in_flight.items()):  # the rest died with the pool, or just finished
                    try:
                        ok, payload = future.result()
                    except BrokenProcessPool:
                        dead.append(task)
                        continue
                    yield Completion(task, ok, payload)
                in_flight.clear()
                if len(dead) == 1:  # the only task lost with the pool: count it against this task
                    task = dead[0]
                    deaths[task.key] = deaths.get(task.key, 0) + 1
                    if deaths[task.key] >= self.max_attempts:
                        message = f"WorkerDied: its worker died on each of {deaths[task.key]} attempts"
                        yield Completion(task, False, message)
                    else:
                        suspects.appendleft(task)
                else:
                    suspects.extend(dead)
                if self.restarts - restarts_at_last_completion >= MAX_BARREN_RESTARTS:
                    raise RunnerError(
                        f"the pool's workers died {MAX_BARREN_RESTARTS} times in a row without finishing a task: "
                        "they cannot start or every task kills them (run with one worker to see the error)"
                    )
                self._restart(len(pending) + len(suspects))
        except BaseException:
            self._shutdown(cancel=True)
            self._pool = None
            raise

    def _submit(self, queue: deque[Task], in_flight: dict[Future, Task]) -> None:
        """Hand the next task of ``queue`` to the pool (left in ``queue`` if the pool is broken)."""
        assert self._pool is not None
        task = queue[0]
        with _sigint_blocked():  # a submit may spawn a worker (the pool starts them on demand)
            future = self._pool.submit(execute, task.function, dict(task.settings), task.context)
        in_flight[future] = queue.popleft()

    def _restart(self, to_go: int) -> None:
        self._shutdown(cancel=True)
        self.restarts += 1
        print(f"a worker died: starting the pool again ({to_go} task(s) to go)", file=sys.stderr, flush=True)
        self._pool = self._start()


class RayExecutor:
    """Tasks on a Ray cluster: ``address="auto"`` starts a local one (``num_cpus`` cores, default all of
    this machine's), any other address joins that cluster. Each task reserves its ``cpus``. Ray retries a
    task whose worker died (its default, 3 times); a task that still fails is reported with Ray's error."""

    name = "ray"

    def __init__(self, address: str = "auto", num_cpus: int | None = None) -> None:
        if address != "auto":
            _check_reachable(address)  # ray.init retries an unreachable address for minutes, silently
        self.address, self.num_cpus = address, num_cpus
        self.workers = 0
        self._started = False

    def __enter__(self) -> RayExecutor:
        try:
            import ray
        except ImportError:
            raise RunnerError("--ray needs the ray package: pip install -e '.[cluster]'") from None
        # Workers import task functions by module name: give them this process's source directories.
        paths = [p for p in sys.path if p and "-packages" not in p and Path(p).is_dir()]
        runtime_env = {"env_vars": {"PYTHONPATH": os.pathsep.join(paths), **{v: "1" for v in ONE_THREAD}}}
        try:
            if self.address == "auto":
                os.environ.setdefault("RAY_AUTH_MODE", "disabled")  # a private local cluster
                ray.init(num_cpus=self.num_cpus or os.cpu_count(), include_dashboard=False,
                         runtime_env=runtime_env, log_to_driver=False, configure_logging=False)  # fmt: skip
            else:
                ray.init(address=self.address, runtime_env=runtime_env, log_to_driver=False, configure_logging=False)
        except (ConnectionError, RuntimeError, ValueError) as err:
            raise RunnerError(f"cannot start or join the Ray cluster at {self.address!r}: {err}") from None
        self._started = True
        self.workers = int(ray.cluster_resources().get("CPU", 1))
        self._remote = ray.remote(execute)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._started:
            import ray

            ray.shutdown()
            self._started = False

    def run(self, tasks: Iterable[Task], stop: Callable[[], bool]) -> Iterator[Completion]:
        import ray
        import ray.exceptions

        pending: deque[Task] = deque(tasks)
        in_flight: dict[Any, Task] = {}
        window = max(1, 2 * self.workers)  # a little queued on each node, not the whole list
        try:
            while pending or in_flight:
                while pending and len(in_flight) < window and not stop():
                    task = pending.popleft()
                    # (ray's overloads of remote() took execute for its first two parameters: the third has a default)
                    ref = self._remote.options(num_cpus=task.cpus).remote(
                        task.function,
                        dict(task.settings),
                        task.context,  # pyright: ignore[reportCallIssue]
                    )
                    in_flight[ref] = task
                if not in_flight:
                    return
                ready, _ = ray.wait(list(in_flight), num_returns=1, timeout=0.5)
                for ref in ready:
                    task = in_flight.pop(ref)
                    try:
                        ok, payload = ray.get(ref)
                    except ray.exceptions.RayError as err:
                        ok, payload = False, f"{type(err).__name__}: {err}"
                    yield Completion(task, ok, payload)
        except BaseException:
            for ref in in_flight:
                ray.cancel(ref, force=True)
            raise


def _check_reachable(address: str, timeout_s: float = 5.0) -> None:
    """Raise :class:`RunnerError` unless a TCP connection to ``[ray://]HOST:PORT`` opens within ``timeout_s``."""
    import socket

    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        raise RunnerError(f"--ray {address!r}: give auto (a local cluster) or HOST:PORT of a running cluster's head")
    try:
        socket.create_connection((host, int(port)), timeout=timeout_s).close()
    except OSError as err:
        raise RunnerError(f"--ray {address}: no Ray cluster answers there ({err.strerror or err})") from None


def make_executor(workers: int | None = None, ray: str | None = None) -> InlineExecutor | PoolExecutor | RayExecutor:
    """The executor a command line asks for: ``ray`` (``auto`` or an address) wins; else ``workers`` = 1 runs
    in-process and more (default: one per core) in a local pool."""
    if ray is not None:
        return RayExecutor(ray)
    workers = workers or os.cpu_count() or 1
    if workers < 1:
        raise RunnerError(f"--workers must be >= 1, got {workers}")
    return InlineExecutor() if workers == 1 else PoolExecutor(workers)
