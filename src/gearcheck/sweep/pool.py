"""Parallel pose evaluation without the CAD kernel: worker processes get plain mesh arrays.

Workers are started with the "spawn" method and import only numpy and python-fcl (through
:mod:`gearcheck.sweep.engine`), never CadQuery (~2 s and ~420 MB each). FCL objects do not
pickle, so each worker builds its own :class:`Scene` once, in its initializer, and then
evaluates tasks against it.
"""

from __future__ import annotations

import multiprocessing as mp
import os
from typing import Callable, Iterable

from gearcheck.sweep.engine import MeshData, Scene

_scene: Scene | None = None


def _init(meshes: list[MeshData]) -> None:
    global _scene
    _scene = Scene(meshes)


def _call(job):
    fn, args = job
    return fn(_scene, *args)


def default_workers() -> int:
    return max(1, min(2, os.cpu_count() or 1))


def map_scene(fn: Callable, meshes: list[MeshData], arg_tuples: Iterable[tuple], workers: int | None = None,
              progress: Callable[[int], None] | None = None) -> list:
    """``[fn(scene, *args) for args in arg_tuples]`` with the scene built once per worker.

    ``fn`` must be a module-level function (it is pickled by name). Order is preserved.
    With one worker everything runs in this process (no start-up cost)."""
    jobs = [(fn, tuple(a)) for a in arg_tuples]
    workers = default_workers() if workers is None else workers
    if workers <= 1 or len(jobs) < 2:
        scene = Scene(meshes)
        out = []
        for fn_, args in jobs:
            out.append(fn_(scene, *args))
            if progress:
                progress(1)
        return out
    ctx = mp.get_context("spawn")
    with ctx.Pool(workers, initializer=_init, initargs=(meshes,)) as pool:
        out = []
        for result in pool.imap(_call, jobs, chunksize=max(1, len(jobs) // (8 * workers))):
            out.append(result)
            if progress:
                progress(1)
        return out
