"""Where independent tasks run: in this process, in a pool of local processes, or (later) on a
cluster. One seam, so a check gives the same results, in the same order, on any of them.

A task is ``fn(state, *args)``: ``fn`` a module-level function (pickled by name), ``state`` made
once per worker by ``setup(shared)`` (a sweep builds its FCL scene from plain mesh arrays there,
because FCL objects do not pickle). Results come back in task order, whatever the number of
workers, so any reduction over them is the same for ``--jobs 1`` and ``--jobs 8``.

Local processes are started with "spawn": a worker imports only what its tasks need (numpy and
python-fcl for a sweep), never CadQuery (~2 s and ~420 MB each).
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import os
from collections.abc import Callable, Sequence
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
    """Runs ``fn(state, *args)`` for every ``args`` in ``tasks``; results in task order."""

    jobs: int

    def map(self, fn: Callable[..., Any], tasks: Sequence[tuple], *, setup: Callable[[Any], Any] | None = None,
            shared: Any = None, progress: Progress | None = None,
            weights: Sequence[int] | None = None) -> list: ...


def _advance(progress: Progress | None, weights: Sequence[int] | None, i: int) -> None:
    if progress is not None:
        progress(int(weights[i]) if weights is not None else 1)


class SerialExecutor:
    """Every task in this process, one after the other (``--jobs 1``): no start-up cost."""

    jobs = 1

    def map(self, fn, tasks, *, setup=None, shared=None, progress=None, weights=None) -> list:
        state = setup(shared) if setup is not None else shared
        out = []
        for i, args in enumerate(tasks):
            out.append(fn(state, *args))
            _advance(progress, weights, i)
        return out


_worker_state: Any = None


def _init_worker(setup, shared) -> None:
    global _worker_state  # noqa: PLW0603 - one state per worker process, made once
    _worker_state = setup(shared) if setup is not None else shared


def _run(job: tuple) -> Any:
    fn, args = job
    return fn(_worker_state, *args)


class ProcessExecutor:
    """A pool of ``jobs`` spawned local processes (default: every core this process may use)."""

    def __init__(self, jobs: int | None = None):
        self.jobs = available_cores() if jobs is None else int(jobs)
        if self.jobs < 1:
            raise ValueError(f"jobs must be at least 1, got {self.jobs}")

    def map(self, fn, tasks, *, setup=None, shared=None, progress=None, weights=None) -> list:
        tasks = list(tasks)
        workers = min(self.jobs, len(tasks))
        if workers <= 1:
            return SerialExecutor().map(fn, tasks, setup=setup, shared=shared, progress=progress, weights=weights)
        log.debug("running %d tasks on %d processes", len(tasks), workers)
        ctx = mp.get_context("spawn")
        chunk = max(1, len(tasks) // (8 * workers))
        with ctx.Pool(workers, initializer=_init_worker, initargs=(setup, shared)) as pool:
            out = []
            for i, result in enumerate(pool.imap(_run, [(fn, tuple(a)) for a in tasks], chunksize=chunk)):
                out.append(result)
                _advance(progress, weights, i)
            return out


def make_executor(jobs: int | None = None) -> Executor:
    """``--jobs N``: serial in this process at 1, a local process pool above (None: every core)."""
    if jobs is not None and jobs < 1:
        raise ValueError(f"jobs must be at least 1, got {jobs}")
    if jobs == 1:
        return SerialExecutor()
    return ProcessExecutor(jobs)
