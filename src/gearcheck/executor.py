"""Where independent tasks run: in this process, in a pool of local processes, or on a Dask
cluster. One seam, so a check gives the same results, in the same order, on any of them.

A task is ``fn(state, *args)``: ``fn`` a module-level function (pickled by name), ``state`` made
once per worker by ``setup(shared)`` (a sweep builds its FCL scene from plain mesh arrays there,
because FCL objects do not pickle). Results come back in task order, whatever the number of
workers, so any reduction over them is the same for ``--jobs 1`` and ``--jobs 8``.

Local processes are started with "spawn": a worker imports only what its tasks need (numpy and
python-fcl for a sweep), never CadQuery (~2 s and ~420 MB each). The calling process works as one
of them.
"""

from __future__ import annotations

import bisect
import contextlib
import ctypes
import functools
import logging
import math
import multiprocessing as mp
import os
import pickle
import signal
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator, Sequence
from typing import Any, Protocol

log = logging.getLogger("gearcheck")

Progress = Callable[[int], None]


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity, else the machine's count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


class Executor(Protocol):
    """Runs ``fn(state, *args)`` for every ``args`` in ``tasks``; results in task order.
    ``first``: work of the calling process's own (its result is not kept), done while the
    workers start, before this process takes any task."""

    jobs: int

    def map(self, fn: Callable[..., Any], tasks: Sequence[tuple], *, setup: Callable[[Any], Any] | None = None,
            shared: Any = None, progress: Progress | None = None,
            weights: Sequence[int] | None = None, first: Callable[[], Any] | None = None) -> list: ...


def _advance(progress: Progress | None, weights: Sequence[int] | None, i: int) -> None:
    if progress is not None:
        progress(int(weights[i]) if weights is not None else 1)


class SerialExecutor:
    """Every task in this process, one after the other (``--jobs 1``): no start-up cost."""

    jobs = 1

    def map(self, fn, tasks, *, setup=None, shared=None, progress=None, weights=None, first=None) -> list:
        if first is not None:
            first()
        state = setup(shared) if setup is not None else shared
        out = []
        for i, args in enumerate(tasks):
            out.append(fn(state, *args))
            _advance(progress, weights, i)
        return out


_worker_state: Any = None


def _quiet_worker() -> None:
    """A worker leaves interrupts to its parent (which stops the pool) and dies with it: SIGINT
    ignored, SIGTERM the default (a silent exit), and on Linux a SIGKILL when the parent dies,
    so a killed run leaves no process and no traceback behind."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # blocked by the parent while spawning
    with contextlib.suppress(OSError, AttributeError):
        pr_set_pdeathsig = 1
        ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, int(signal.SIGKILL))
    if os.getppid() == 1:  # the parent died before we got here
        os._exit(0)


def _init_worker(setup, shared_file: str | None) -> None:
    global _worker_state  # noqa: PLW0603 - one state per worker process, made once
    _quiet_worker()
    shared = None
    if shared_file is not None:
        with open(shared_file, "rb") as fh:
            shared = pickle.load(fh)
    _worker_state = setup(shared) if setup is not None else shared


@contextlib.contextmanager
def _shared_file(shared: Any) -> Iterator[str | None]:
    """``shared`` pickled once into a file the spawned workers read as they start (removed on
    leaving). Passed in the workers' start-up arguments instead, tens of megabytes of meshes would
    go down a pipe the calling process must wait on until each worker has started and read it
    (about 0.2 s idle, before it can do any work of its own)."""
    if shared is None:
        yield None
        return
    folder = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None
    fd, path = tempfile.mkstemp(prefix="gearcheck-shared-", suffix=".pickle", dir=folder)
    try:
        with os.fdopen(fd, "wb") as fh:
            pickle.dump(shared, fh, protocol=pickle.HIGHEST_PROTOCOL)
        yield path
    finally:
        with contextlib.suppress(OSError):
            os.unlink(path)


class _Spawning:
    """While workers are spawned: SIGINT blocked in this thread, so the children inherit it
    blocked (a Ctrl-C in the terminal — sent to the whole process group — reaches only the
    parent, which stops the pool); and SIGINT / SIGTERM that reach the process meanwhile (other
    threads, e.g. the CAD kernel's, do not block them) are only recorded, then raised again
    once the pool exists and can be stopped cleanly. No-op outside the main thread of the main
    process (signals are not ours to change there)."""

    def __init__(self) -> None:
        self.active = mp.parent_process() is None and threading.current_thread() is threading.main_thread()
        self.pending: list[int] = []
        self._handlers: dict[int, Any] = {}
        self._mask: Any = None

    def _record(self, signum: int, _frame: object) -> None:
        self.pending.append(signum)

    def __enter__(self) -> _Spawning:
        if self.active:
            # multiprocessing's resource tracker warns about "leaked semaphores" when a killed
            # parent could not close its pool: nothing leaks that the kernel does not reclaim
            quiet = "ignore::UserWarning:multiprocessing.resource_tracker"
            if quiet not in sys.warnoptions:
                sys.warnoptions.append(quiet)
            self._handlers = {s: signal.signal(s, self._record) for s in (signal.SIGINT, signal.SIGTERM)}
            self._mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        return self

    def __exit__(self, *exc: object) -> None:
        if self.active:
            for s, handler in self._handlers.items():
                signal.signal(s, handler if handler is not None else signal.SIG_DFL)
            signal.pthread_sigmask(signal.SIG_SETMASK, self._mask)

    def deliver(self) -> None:
        """Raise the signals recorded while spawning (handled by the restored handlers)."""
        for s in dict.fromkeys(self.pending):
            signal.raise_signal(s)


def _run_chunk(fn: Callable[..., Any], chunk: list[tuple]) -> list:
    return [fn(_worker_state, *args) for args in chunk]


class ProcessExecutor:
    """``jobs`` processes (default: every core this process may use): this one and ``jobs − 1``
    spawned workers, all taking tasks from one queue (:class:`_Chunks`).

    This process works too: it would only wait otherwise, and it does its ``first`` work and its
    first tasks while the workers start, so two processes do close to twice the work of one — the
    spawned workers' start-up (interpreter, imports, their own state) is the only cost that does
    not shrink with more processes, and this process hides its share of it."""

    def __init__(self, jobs: int | None = None):
        self.jobs = available_cores() if jobs is None else int(jobs)
        if self.jobs < 1:
            raise ValueError(f"jobs must be at least 1, got {self.jobs}")

    def map(self, fn, tasks, *, setup=None, shared=None, progress=None, weights=None, first=None) -> list:
        tasks = list(tasks)
        workers = min(self.jobs, len(tasks))
        if workers <= 1:
            return SerialExecutor().map(fn, tasks, setup=setup, shared=shared, progress=progress, weights=weights,
                                        first=first)
        log.debug("running %d tasks on %d processes (this one and %d spawned)", len(tasks), workers, workers - 1)
        ctx = mp.get_context("spawn")
        with _shared_file(shared) as shared_file:
            with _Spawning() as spawning:
                pool = ctx.Pool(workers - 1, initializer=_init_worker, initargs=(setup, shared_file))
            with pool:  # leaving the block (an error, an interrupt) terminates the workers
                spawning.deliver()
                return self._run(pool, fn, tasks, workers, setup, shared, progress, weights, first)

    @staticmethod
    def _run(pool: Any, fn, tasks: list, workers: int, setup, shared, progress, weights, first) -> list:
        """The map on ``pool`` (``workers − 1`` spawned workers) and this process. A worker's next
        chunk is sent as soon as one of its chunks ends, from the pool's result thread, not only
        when this process is between two tasks of its own: a task here may be long (a whole
        template's check, side by side with the others), and a worker must not wait for it."""
        queue = _Chunks(len(tasks), workers, weights)
        out: list[Any] = [None] * len(tasks)
        inflight: dict[int, Any] = {}  # chunk start → its result, until collected here
        running: set[int] = set()  # chunk starts not yet ended
        lock = threading.Lock()  # queue, inflight, running: this thread and the pool's result thread

        def finish(start: int, results: list) -> None:
            for i, result in enumerate(results, start):
                out[i] = result
                _advance(progress, weights, i)

        def feed() -> None:  # under the lock; two chunks running per worker, one when few tasks are left
            while queue and len(running) < (2 if len(queue) > workers else 1) * (workers - 1):
                start, end = queue.take_first()
                running.add(start)
                done = functools.partial(ended, start)
                inflight[start] = pool.apply_async(_run_chunk, (fn, tasks[start:end]), callback=done,
                                                   error_callback=done)

        stopped: list[bool] = []  # the map has ended (a result, an error): nothing more is sent
        failed: list[BaseException] = []  # raised while sending from the result thread, raised here

        def ended(start: int, _result: Any) -> None:  # in the pool's result thread: must not raise
            with lock:
                running.discard(start)
                if not stopped and not failed:
                    try:
                        feed()
                    except BaseException as error:  # noqa: BLE001 - handed to the calling thread
                        failed.append(error)

        try:
            with lock:
                feed()
            if first is not None:
                first()  # while the workers start
            state = setup(shared) if setup is not None else shared
            while True:
                with lock:
                    if failed:
                        raise failed[0]
                    for start in [k for k, r in inflight.items() if r.ready()]:
                        finish(start, inflight.pop(start).get())
                    feed()
                    # this process takes the last task in line, the workers the first chunks
                    mine = queue.take_last() if queue else None
                    pending = next(iter(inflight.values()), None)
                if mine is not None:
                    result = fn(state, *tasks[mine])
                    with lock:
                        finish(mine, [result])
                elif pending is not None:
                    pending.wait(0.05)
                else:
                    return out
        finally:
            with lock:  # before the pool is stopped: a chunk ending now sends nothing to it
                stopped.append(True)


class _Chunks:
    """The tasks not yet taken, [lo, hi): the spawned workers take chunks from the front, this
    process one task at a time from the back (so each keeps to its own run of tasks and the
    meshes they use, and this process tops up the workers' queue after every task it runs).
    Guided sizes, in task weights (the plan's estimate of each task's work; 1 each without):
    a chunk weighs at most 1/(8·processes) of all the work (few round trips) and at most
    1/(3·processes) of what is left, so chunks shrink towards the end and no process waits long
    for another's last chunk, even where a few heavy tasks follow many light ones; a chunk holds
    at least one task. With no more tasks left than processes, a worker gets one only when it has
    none in flight (the last few go to whoever is free, this process included)."""

    def __init__(self, n: int, processes: int, weights: Sequence[float] | None = None):
        self.lo, self.hi, self.processes = 0, n, processes
        self._cum = [0.0]  # weight of the first i tasks
        for w in weights if weights is not None else [1.0] * n:
            self._cum.append(self._cum[-1] + max(float(w), 0.0))
        self.largest = max(1.0, float(math.floor(self._cum[-1] / (8 * processes))))

    def __bool__(self) -> bool:
        return self.hi > self.lo

    def __len__(self) -> int:
        return self.hi - self.lo

    def take_first(self) -> tuple[int, int]:
        """The next chunk from the front: (start, end)."""
        left = self._cum[self.hi] - self._cum[self.lo]
        most = min(self.largest, math.ceil(left / (3 * self.processes)))
        end = bisect.bisect_right(self._cum, self._cum[self.lo] + most, self.lo + 1, self.hi + 1) - 1
        start, self.lo = self.lo, max(self.lo + 1, end)
        return start, self.lo

    def take_last(self) -> int:
        """The last task."""
        self.hi -= 1
        return self.hi


_dask_states: dict[str, Any] = {}


def _dask_task(fn: Callable[..., Any], token: str, setup: Callable[[Any], Any] | None, shared: Any,
               args: tuple) -> Any:
    """One task on a Dask worker: the worker's state for this map (made once per worker and map,
    by ``setup(shared)``), then ``fn(state, *args)``."""
    if token not in _dask_states:
        _dask_states.clear()  # one map at a time per worker: drop the last one's state
        _dask_states[token] = setup(shared) if setup is not None else shared
    return fn(_dask_states[token], *args)


class DaskExecutor:
    """Tasks on a Dask distributed cluster: an existing scheduler (``tcp://HOST:PORT``), or a
    ``LocalCluster`` of ``jobs`` single-threaded worker processes started here
    (``"local-cluster"``). Workers import gearcheck from their own environment (it must be
    installed there, the same version); tasks travel as module-level functions and plain data.
    Results come back in task order, like every executor. Use as a context manager: a cluster
    started here is shut down on leaving."""

    def __init__(self, scheduler: str, jobs: int | None = None):
        from distributed import Client, LocalCluster

        self._cluster = None
        if scheduler == "local-cluster":
            n = available_cores() if jobs is None else int(jobs)
            if n < 1:
                raise ValueError(f"jobs must be at least 1, got {n}")
            self._cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                         dashboard_address=None, silence_logs=logging.ERROR)
            self.client = Client(self._cluster)
        else:
            self.client = Client(scheduler, timeout="20s")
        self.jobs = max(1, sum(w.get("nthreads", 1) for w in self.client.scheduler_info()["workers"].values()))

    def __enter__(self) -> DaskExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.client.close()
        if self._cluster is not None:
            self._cluster.close()

    def map(self, fn, tasks, *, setup=None, shared=None, progress=None, weights=None, first=None) -> list:
        import uuid

        from distributed import as_completed

        tasks = list(tasks)
        if not tasks:
            if first is not None:
                first()
            return []
        token = uuid.uuid4().hex
        shared_ref = self.client.scatter(shared, broadcast=True) if shared is not None else None
        futures = [self.client.submit(_dask_task, fn, token, setup, shared_ref, tuple(a), pure=False,
                                      key=f"gearcheck-{token}-{i}") for i, a in enumerate(tasks)]
        if first is not None:
            first()  # while the cluster works
        index = {f.key: i for i, f in enumerate(futures)}
        for done in as_completed(futures):
            _advance(progress, weights, index[done.key])
        return self.client.gather(futures)


def make_executor(jobs: int | None = None) -> Executor:
    """``--jobs N``: serial in this process at 1, a local process pool above (None: every core)."""
    if jobs is not None and jobs < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    if jobs == 1:
        return SerialExecutor()
    return ProcessExecutor(jobs)
