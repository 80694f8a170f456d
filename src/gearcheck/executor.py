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

from gearcheck.interrupts import DeferredSignals

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


class WorkerError(RuntimeError):
    """A worker process died (killed, out of memory) or could not load its task: the map ends
    at once with this one line instead of waiting for a result that will never come."""


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


def _init_worker(setup_ref: tuple[str, str] | None, shared_file: str | None) -> None:
    global _worker_state  # noqa: PLW0603 - one state per worker process, made once
    _quiet_worker()
    shared = None
    if shared_file is not None:
        try:
            with open(shared_file, "rb") as fh:
                shared = pickle.load(fh)
        except (OSError, EOFError, pickle.UnpicklingError):
            # the parent wrote it before starting the pool and removes it only as the run ends
            # (finished or interrupted): a worker starting that late has nothing to do
            os._exit(0)
    setup = _resolve(setup_ref) if setup_ref is not None else None
    _worker_state = setup(shared) if setup is not None else shared


def _reference(fn: Callable[..., Any]) -> tuple[str, str]:
    """A module-level function by name, (module, qualified name): resolved in the worker by
    :func:`_resolve`, which says in one line why when it cannot be."""
    return getattr(fn, "__module__", None) or "?", getattr(fn, "__qualname__", None) or repr(fn)


def _resolve(ref: tuple[str, str]) -> Callable[..., Any]:
    import importlib

    module, name = ref
    try:
        found: Any = importlib.import_module("__mp_main__" if module == "__main__" else module)
        for part in name.split("."):
            found = getattr(found, part)
    except Exception as exc:  # noqa: BLE001 - any failure to find it is the same one line
        where = "the script or notebook being run" if module == "__main__" else f"module {module}"
        raise WorkerError(f"a worker process cannot load {name} from {where} ({type(exc).__name__}): define "
                          "it (and the mechanism) in an importable module, or run with jobs=1") from None
    return found


def _names_main(*objects: Any) -> str | None:
    """The first name the pickles of ``objects`` look up in ``__main__`` (a function or class
    defined in a notebook, ``python -c`` or a script), None when they look up none."""
    import pickletools

    for obj in objects:
        if obj is None:
            continue
        try:
            data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # noqa: BLE001 - what cannot pickle fails where the map sends it, with its own message
            return None
        if b"__main__" not in data:
            continue
        strings: list[str] = []
        for op, arg, _ in pickletools.genops(data):
            if isinstance(arg, str):
                if op.name in ("GLOBAL", "INST") and arg.startswith("__main__ "):
                    return arg.split(" ", 1)[1]
                strings.append(arg)
            elif op.name == "STACK_GLOBAL" and len(strings) >= 2 and strings[-2] == "__main__":
                return strings[-1]
    return None


def check_main_importable(fn: Any = None, setup: Any = None, task: Any = None) -> None:
    """A spawned worker first runs the script its parent was started from (as ``__mp_main__``);
    a script read from standard input (``python - < script.py``) or any other file that is not
    there has nothing to run, and every worker would die starting. A notebook, ``python -c`` or an
    interactive session has no script at all: what the task defines in ``__main__`` (a mechanism's
    sweep function, its parameters' class) cannot reach a worker. Each said in one line, with the
    cure, before any worker starts."""
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if getattr(getattr(main, "__spec__", None), "name", None) is not None:
        return  # a module run with -m: importable by name
    if path is None:  # a notebook, python -c, an interactive session
        refs = [f"{m}.{n}" for m, n in (_reference(f) for f in (fn, setup) if f is not None) if m == "__main__"]
        name = refs[0] if refs else _names_main(task)
        if name is not None:
            name = name if name.startswith("__main__.") else f"__main__.{name}"
            raise WorkerError(f"worker processes cannot load {name}: it is defined in this session (a notebook, "
                              "python -c or an interactive shell), which they cannot import; define the mechanism "
                              "in an importable module, or run with jobs=1")
        return
    if not os.path.isfile(path):
        raise WorkerError(f"worker processes cannot start from a script that is not a file ({path}: a script read "
                          "from standard input?): save it to a file and run that, or run with jobs=1")


def _run_chunk(fn_ref: tuple[str, str], chunk: list[tuple]) -> list:
    fn = _resolve(fn_ref)
    return [fn(_worker_state, *args) for args in chunk]


@contextlib.contextmanager
def _shared_file(shared: Any) -> Iterator[str | None]:
    """``shared`` pickled once into a file the spawned workers read as they start. Passed in the
    workers' start-up arguments instead, tens of megabytes of meshes would go down a pipe the
    calling process must wait on until each worker has started and read it (about 0.2 s idle,
    before it can do any work of its own).

    On Linux the file has no name: an anonymous memory file (``memfd``) the workers open through
    ``/proc/PID/fd/N`` while this process lives, so nothing is left behind whatever kills the
    run (a SIGKILL included). Elsewhere, a temporary file removed on leaving."""
    if shared is None:
        yield None
        return
    fd = _anonymous_file()
    if fd is not None:
        try:
            with os.fdopen(os.dup(fd), "wb") as fh:
                pickle.dump(shared, fh, protocol=pickle.HIGHEST_PROTOCOL)
            yield f"/proc/{os.getpid()}/fd/{fd}"
        finally:
            os.close(fd)
        return
    fd, path = tempfile.mkstemp(prefix="gearcheck-shared-", suffix=".pickle")
    try:
        with os.fdopen(fd, "wb") as fh:
            pickle.dump(shared, fh, protocol=pickle.HIGHEST_PROTOCOL)
        yield path
    finally:
        with contextlib.suppress(OSError):
            os.unlink(path)


def _anonymous_file() -> int | None:
    """A memory file with no name that workers can open by ``/proc/PID/fd/N``, or None."""
    if not hasattr(os, "memfd_create") or not os.path.isdir(f"/proc/{os.getpid()}/fd"):
        return None
    try:
        return os.memfd_create("gearcheck-shared", os.MFD_CLOEXEC)  # workers open it by path, not inherit it
    except OSError:
        return None


class _Spawning(DeferredSignals):
    """While workers are spawned: SIGINT blocked in this thread, so the children inherit it
    blocked (a Ctrl-C in the terminal — sent to the whole process group — reaches only the
    parent, which stops the pool); and SIGINT / SIGTERM that reach the process meanwhile (other
    threads, e.g. the CAD kernel's, do not block them) are only recorded, then raised again
    once the pool exists and can be stopped cleanly (:meth:`deliver`). No-op outside the main
    thread of the main process (signals are not ours to change there)."""

    def __init__(self) -> None:
        super().__init__()
        self._mask: Any = None

    def __enter__(self) -> _Spawning:
        if self.active:
            # multiprocessing's resource tracker warns about "leaked semaphores" when a killed
            # parent could not close its pool: nothing leaks that the kernel does not reclaim
            quiet = "ignore::UserWarning:multiprocessing.resource_tracker"
            if quiet not in sys.warnoptions:
                sys.warnoptions.append(quiet)
            super().__enter__()
            self._mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        return self

    def __exit__(self, *exc: object) -> None:  # the signals are delivered later, once the pool can stop
        if self.active:
            self.restore()
            signal.pthread_sigmask(signal.SIG_SETMASK, self._mask)


def _stop(pool: Any) -> None:
    """Stop a process pool now: its workers killed (their tasks are abandoned), nothing waited
    for that may never come."""
    processes = list(getattr(pool, "_processes", {}).values())
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            process.kill()
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:  # gone, with the locks and files they held, before the caller cleans up
        with contextlib.suppress(OSError, ValueError, AttributeError, AssertionError):
            process.join(5)


def _broken(processes: list[Any]) -> WorkerError:
    """The one line for a pool whose worker died, with how it died where that can be read (the
    pool stops the other workers with SIGTERM once one has died)."""
    codes = []
    for process in processes:
        with contextlib.suppress(OSError, ValueError, AttributeError, AssertionError):
            process.join(1.0)
            if process.exitcode not in (None, 0):
                codes.append(process.exitcode)
    how = ""
    if -signal.SIGKILL in codes:
        how = " (killed by SIGKILL: out of memory?)"
    elif codes:
        code = next((c for c in codes if c != -signal.SIGTERM), codes[0])
        with contextlib.suppress(ValueError):
            how = f" (killed by {signal.Signals(-code).name})" if code < 0 else f" (exit code {code})"
    return WorkerError(f"a worker process died{how}: the run is stopped; run again with fewer --jobs, a coarser "
                       "--tol, or --jobs 1 to run in this process")


class ProcessExecutor:
    """``jobs`` processes (default: every core this process may use, and never more): this one
    and ``jobs − 1`` spawned workers, all taking tasks from one queue (:class:`_Chunks`).

    This process works too: it would only wait otherwise, and it does its ``first`` work and its
    first tasks while the workers start, so two processes do close to twice the work of one — the
    spawned workers' start-up (interpreter, imports, their own state) is the only cost that does
    not shrink with more processes, and this process hides its share of it.

    A worker that dies (killed by a signal, out of memory) or cannot load its task ends the map
    at once with a :class:`WorkerError` (the pool is stopped; no result is waited for that
    cannot come)."""

    def __init__(self, jobs: int | None = None):
        self.jobs = capped_jobs(jobs)

    def map(self, fn, tasks, *, setup=None, shared=None, progress=None, weights=None, first=None) -> list:
        from concurrent.futures import ProcessPoolExecutor

        tasks = list(tasks)
        workers = min(self.jobs, len(tasks))
        if workers <= 1:
            return SerialExecutor().map(fn, tasks, setup=setup, shared=shared, progress=progress, weights=weights,
                                        first=first)
        log.debug("running %d tasks on %d processes (this one and %d spawned)", len(tasks), workers, workers - 1)
        check_main_importable(fn, setup, tasks[0])
        ctx = mp.get_context("spawn")
        fn_ref = _reference(fn)
        with _shared_file(shared) as shared_file:
            with _Spawning() as spawning:
                pool = ProcessPoolExecutor(workers - 1, mp_context=ctx, initializer=_init_worker,
                                           initargs=(_reference(setup) if setup is not None else None, shared_file))
                run = _Run(pool, fn, fn_ref, tasks, workers, progress, weights)
                run.feed_first()  # the workers are spawned as their first chunks are sent
            try:
                spawning.deliver()
                out = run.finish(setup, shared, first)
            except BaseException:
                _stop(pool)
                raise
            pool.shutdown(wait=True)
            return out

    @staticmethod
    def _run(pool: Any, fn, tasks: list, workers: int, setup, shared, progress, weights, first) -> list:
        """The map on ``pool`` (an executor of ``workers − 1`` processes, with ``submit``) and this
        process."""
        run = _Run(pool, fn, _reference(fn), tasks, workers, progress, weights)
        run.feed_first()
        return run.finish(setup, shared, first)


class _Run:
    """One map on a pool and this process. A worker's next chunk is sent as soon as one of its
    chunks ends, from the pool's result thread, not only when this process is between two tasks
    of its own: a task here may be long (a whole template's check, side by side with the
    others), and a worker must not wait for it."""

    def __init__(self, pool: Any, fn: Callable[..., Any], fn_ref: tuple[str, str], tasks: list, workers: int,
                 progress: Progress | None, weights: Sequence[int] | None):
        self.pool, self.fn, self.fn_ref, self.tasks, self.workers = pool, fn, fn_ref, tasks, workers
        self.progress, self.weights = progress, weights
        self.queue = _Chunks(len(tasks), workers, weights)
        self.out: list[Any] = [None] * len(tasks)
        self.inflight: dict[int, Any] = {}  # chunk start → its future, until collected here
        self.running: set[int] = set()  # chunk starts not yet ended
        self.lock = threading.Lock()  # all of the above: this thread and the pool's result thread
        self.stopped = False  # the map has ended (a result, an error): nothing more is sent
        self.failed: list[BaseException] = []  # raised while sending from the result thread, raised here
        self.processes: list[Any] = []  # the pool's worker processes

    def _collect(self, start: int, results: list) -> None:
        for i, result in enumerate(results, start):
            self.out[i] = result
            _advance(self.progress, self.weights, i)

    def _feed(self) -> None:  # under the lock; two chunks running per worker, one when few tasks are left
        queue, workers = self.queue, self.workers
        while queue and len(self.running) < (2 if len(queue) > workers else 1) * (workers - 1):
            start, end = queue.take_first()
            self.running.add(start)
            future = self.pool.submit(_run_chunk, self.fn_ref, self.tasks[start:end])
            self.inflight[start] = future
            future.add_done_callback(functools.partial(self._ended, start))

    def _ended(self, start: int, _future: Any) -> None:  # in the pool's result thread: must not raise
        with self.lock:
            self.running.discard(start)
            if not self.stopped and not self.failed:
                try:
                    self._feed()
                except BaseException as error:  # noqa: BLE001 - handed to the calling thread
                    self.failed.append(error)

    def feed_first(self) -> None:
        """The first chunks sent: the pool spawns its workers as they are (one per chunk)."""
        with self.lock:
            self._feed()
        self.processes = list(getattr(self.pool, "_processes", {}).values())  # to say how one died

    def finish(self, setup: Callable[[Any], Any] | None, shared: Any, first: Callable[[], Any] | None) -> list:
        from concurrent.futures import FIRST_COMPLETED, wait
        from concurrent.futures.process import BrokenProcessPool

        try:
            if first is not None:
                first()  # while the workers start
            state = setup(shared) if setup is not None else shared
            while True:
                with self.lock:
                    if self.failed:
                        raise self.failed[0]
                    for start in [k for k, f in self.inflight.items() if f.done()]:
                        self._collect(start, self.inflight.pop(start).result())
                    self._feed()
                    # this process takes the last task in line, the workers the first chunks
                    mine = self.queue.take_last() if self.queue else None
                    pending = list(self.inflight.values())
                if mine is not None:
                    result = self.fn(state, *self.tasks[mine])
                    with self.lock:
                        self._collect(mine, [result])
                elif pending:
                    wait(pending, timeout=0.05, return_when=FIRST_COMPLETED)
                else:
                    return self.out
        except BrokenProcessPool:
            raise _broken(self.processes) from None
        finally:
            with self.lock:  # before the pool is stopped: a chunk ending now sends nothing to it
                self.stopped = True


_CAPPED_SAID: set[tuple[int, int]] = set()  # (asked, cores) already said in this process


def capped_jobs(jobs: int | None) -> int:
    """``--jobs``: at least 1, and at most the cores this process may use (more processes than
    cores only add start-up time and memory: a larger value is lowered, with a note said once per
    process however often the value is capped). The process pool and a local Dask cluster alike."""
    cores = available_cores()
    if jobs is None:
        return cores
    if int(jobs) < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    if int(jobs) > cores:
        if (int(jobs), cores) not in _CAPPED_SAID:
            _CAPPED_SAID.add((int(jobs), cores))
            log.warning("--jobs %d: more than the %d core%s this process may use; running %d", jobs, cores,
                        "" if cores == 1 else "s", cores)
        return cores
    return int(jobs)


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
    started here is shut down on leaving.

    Quiet: the log records of distributed (and of tornado and bokeh, which it runs on) reach no
    handler while the executor is open unless gearcheck's own diagnostics are on (``-v``). A
    cluster started here has no dashboard: its scheduler's HTTP server, which it always starts
    (on port 8787 by default), listens on a random loopback port and serves nothing. An
    interrupt while it starts takes effect once it can be shut down (no half-started cluster
    left to exit handlers). ``timeout``: seconds an existing scheduler may take to answer
    (OSError then)."""

    LOGGERS = ("distributed", "tornado", "bokeh")

    def __init__(self, scheduler: str, jobs: int | None = None, timeout: float = 20.0):
        from distributed import Client, LocalCluster

        self._cluster: Any = None
        self.client: Any = None
        self._levels = self._quiet_logs()
        starting = _Spawning()
        try:
            if scheduler == "local-cluster":
                with starting:
                    self._cluster = self._local_cluster(LocalCluster, jobs)
                    self.client = Client(self._cluster)
                starting.deliver()
            else:  # an interrupt while connecting acts at once (the wait may be long)
                self.client = Client(scheduler, timeout=f"{timeout}s")
            workers = self.client.scheduler_info()["workers"].values()
            self.jobs = max(1, sum(w.get("nthreads", 1) for w in workers))
        except BaseException:
            self.close()
            starting.deliver()  # an interrupt that came meanwhile (and may have failed the start) wins
            raise

    @staticmethod
    def _local_cluster(cluster_class: Any, jobs: int | None) -> Any:
        import dask

        n = capped_jobs(jobs)  # a worker process per core at most, as the process pool
        # worker processes: their own log handlers, at this level
        quiet = logging.WARNING if log.isEnabledFor(logging.INFO) else logging.CRITICAL + 1
        # the workers take the configuration as it is now (no HTTP routes: nothing to serve)
        with dask.config.set({"distributed.scheduler.http.routes": [], "distributed.worker.http.routes": []}):
            return cluster_class(n_workers=n, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0",
                                 scheduler_kwargs={"dashboard": False}, silence_logs=quiet)

    @classmethod
    def _quiet_logs(cls) -> dict[str, int]:
        """Without -v: every logger of :attr:`LOGGERS` (and below) above CRITICAL; their levels
        before, to restore (nothing changed with -v)."""
        if log.isEnabledFor(logging.INFO):
            return {}
        names = [n for n in list(logging.root.manager.loggerDict)
                 if any(n == top or n.startswith(f"{top}.") for top in cls.LOGGERS)]
        levels = {n: logging.getLogger(n).level for n in {*cls.LOGGERS, *names}}
        for n in levels:
            logging.getLogger(n).setLevel(logging.CRITICAL + 1)
        return levels

    def __enter__(self) -> DaskExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        try:
            if self.client is not None:
                self.client.close()
            if self._cluster is not None:
                self._cluster.close()
        finally:
            self.client = self._cluster = None
            levels, self._levels = self._levels, {}
            for n, level in levels.items():
                logging.getLogger(n).setLevel(level)

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
    """``--jobs N``: serial in this process at 1, a local process pool above (None: every core;
    never more processes than cores)."""
    jobs = capped_jobs(jobs)
    if jobs == 1:
        return SerialExecutor()
    return ProcessExecutor(jobs)
