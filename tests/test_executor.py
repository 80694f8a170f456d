"""The executor seam and the typed motions (no CAD)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.executor import ProcessExecutor, SerialExecutor, _Chunks, available_cores, make_executor
from gearcheck.geometry.bisect import bisect
from gearcheck.sweep.motion import ChainLink, Rotation, Translation


def scaled(state: float, x: float, y: float) -> float:
    return state * (x + y)


def test_results_in_task_order_on_any_number_of_workers():
    tasks = [(float(i), 0.5 * i) for i in range(37)]
    expected = [3.0 * (x + y) for x, y in tasks]
    ticks: list[int] = []
    assert SerialExecutor().map(scaled, tasks, setup=float, shared=3.0, progress=ticks.append) == expected
    assert sum(ticks) == 37
    weighted: list[int] = []
    assert ProcessExecutor(2).map(scaled, tasks, setup=float, shared=3.0, progress=weighted.append,
                                  weights=[2] * 37) == expected
    assert sum(weighted) == 74


def test_make_executor_defaults_to_every_core_and_runs_serially_at_one():
    assert isinstance(make_executor(1), SerialExecutor)
    assert make_executor().jobs == available_cores() >= 1
    with pytest.raises(ValueError):
        make_executor(0)


def test_rotation_is_rigid_about_its_axis_through_its_origin():
    r = Rotation.about((0, 0, 2), (10.0, 0.0, 0.0))
    m = r.matrix(math.pi / 2)
    assert np.allclose(m @ [10.0, 0.0, 5.0, 1.0], [10.0, 0.0, 5.0, 1.0])  # points on the axis stay
    assert np.allclose(m @ [11.0, 0.0, 0.0, 1.0], [10.0, 1.0, 0.0, 1.0])  # a quarter turn, right-handed
    assert r.to_dict() == {"kind": "rotation", "axis": [0.0, 0.0, 1.0], "origin": [10.0, 0.0, 0.0]}
    t = Translation.along((3, 0, 0))
    assert np.allclose(t.matrix(2.0)[:3, 3], [2.0, 0.0, 0.0])
    assert ChainLink(4).to_dict() == {"kind": "chain_link", "index": 4}
    with pytest.raises(ValueError):
        Rotation.about((0, 0, 0))


def test_one_bisection_brackets_where_a_flag_changes():
    b = bisect(lambda x: x >= 0.3, 0.0, 1.0, tol=1e-9)
    assert b.free < 0.3 <= b.touching and b.width <= 1e-9
    b = bisect(lambda x: x <= -0.25, 0.0, -1.0, tol=1e-9)  # either direction
    assert b.touching <= -0.25 < b.free
    with pytest.raises(ValueError):
        bisect(lambda x: True, 0.0, 1.0)
    steps = bisect(lambda x: x >= 0.3, 0.0, 1.0, tol=None, max_iter=10, check_ends=False)
    assert steps.width == pytest.approx(2.0**-10)


def _pid_of(_state: None, _i: int) -> int:
    import os

    return os.getpid()


def test_the_calling_process_works_as_one_of_the_jobs():
    import os

    pids = ProcessExecutor(2).map(_pid_of, [(i,) for i in range(64)])
    assert len(pids) == 64
    assert os.getpid() in pids and len(set(pids)) == 2  # this process and one spawned worker


def _fails_at(_state: None, i: int) -> int:
    if i == 30:
        raise ArithmeticError(f"task {i}")
    return i


def test_a_failing_task_stops_the_map_wherever_it_ran():
    with pytest.raises(ArithmeticError, match="task 30"):
        ProcessExecutor(2).map(_fails_at, [(i,) for i in range(64)])


def test_chunks_cover_every_task_once_and_shrink_towards_the_end():
    for n, processes in ((1, 2), (7, 2), (200, 2), (1000, 4)):
        queue = _Chunks(n, processes)
        taken: list[int] = []
        sizes = []
        turn = 0
        while queue:
            assert len(queue) == n - len(taken)
            if turn % 3 == 2:  # the calling process: one task at a time, from the back
                taken.append(queue.take_last())
            else:
                start, end = queue.take_first()
                sizes.append(end - start)
                taken.extend(range(start, end))
            turn += 1
        assert sorted(taken) == list(range(n))
        assert all(a >= b for a, b in zip(sizes, sizes[1:], strict=False))  # guided: never larger later
        assert not sizes or (sizes[0] <= max(1, n // (8 * processes)) and sizes[-1] <= max(1, sizes[0]))
        if n >= 200:
            assert sizes[-1] <= 2 < sizes[0]


def test_weighted_chunks_even_out_the_work_where_heavy_tasks_follow_light_ones():
    """Many light tasks, then a run of heavy ones (a sweep's mesh contacts, then its exact range
    tasks): a chunk weighs no more than the guided share of the work, so a worker that reaches the
    heavy run takes a few of them, not a count's worth; every task once, in order within a chunk."""
    weights = [1.0] * 264 + [16.0] * 21 + [1.0] * 264
    n, processes = len(weights), 2
    queue = _Chunks(n, processes, weights)
    total = sum(weights)
    taken: list[int] = []
    chunk_weights = []
    while queue:
        start, end = queue.take_first()
        assert end > start
        taken.extend(range(start, end))
        w = sum(weights[start:end])
        assert end - start == 1 or w <= max(1.0, total // (8 * processes))  # never more than the cap
        chunk_weights.append(w)
    assert taken == list(range(n))
    # the heavy run is spread over several chunks, each within the cap (by count, one chunk of
    # up to n // 16 = 34 tasks could have held all 21 heavy ones: 336 of the 864 weight)
    assert max(chunk_weights) <= total // (8 * processes) < 16.0 * 21
    # unit weights: the same chunks as without weights
    a, b = _Chunks(200, 2), _Chunks(200, 2, [1] * 200)
    while a or b:
        assert a.take_first() == b.take_first()


def _handoff(_state: None, i: int, marker: str) -> tuple[int, bool]:
    """Task 2 (the calling process's: the last in line) waits for task 1 to have run elsewhere."""
    import os
    import time

    if i == 1:
        open(marker, "w").close()
    saw = False
    if i == 2:
        deadline = time.monotonic() + 20.0
        while not (saw := os.path.exists(marker)) and time.monotonic() < deadline:
            time.sleep(0.01)
    return os.getpid(), saw


def test_a_worker_gets_its_next_task_while_this_process_runs_a_long_one(tmp_path):
    """Templates side by side: this process checks the longest, the worker the others one after
    the other. The worker's next task is sent when its last one ends, not when this process is
    next between two tasks of its own (it once waited a whole differential check for it)."""
    import os

    marker = str(tmp_path / "task-1-ran")
    out = ProcessExecutor(2).map(_handoff, [(i, marker) for i in range(3)])
    (pid0, _), (pid1, _), (pid2, saw) = out
    assert pid2 == os.getpid() and pid0 != pid2 and pid1 == pid0
    assert saw  # task 1 ran in the worker while task 2 was still running here


def _slow_identity(_state: None, i: int) -> int:
    import time

    time.sleep(0.005)
    return i


def test_a_failure_to_send_from_the_result_thread_is_raised_here_not_lost():
    """The next chunk is sent from the pool's result thread; if sending fails there (the pool no
    longer running, say), the map raises it in the calling process instead of waiting forever."""
    import threading
    from concurrent.futures import Future

    class Pool:  # runs each chunk in a thread; refuses chunks sent from any thread but the main one
        def submit(self, fn, *args):
            if threading.current_thread() is not threading.main_thread():
                raise ValueError("Pool not running")
            future: Future = Future()

            def run():
                future.set_result(fn(*args))

            threading.Thread(target=run, daemon=True).start()
            return future

    tasks = [(i,) for i in range(400)]
    with pytest.raises(ValueError, match="Pool not running"):
        ProcessExecutor._run(Pool(), _slow_identity, tasks, 2, None, None, None, None, None)


def _marked(_state: None, i: int) -> tuple[int, bool]:
    import os

    return os.getpid(), bool(os.environ.get("GEARCHECK_TEST_FIRST"))


def test_first_runs_once_in_the_calling_process_before_its_tasks(monkeypatch):
    import os

    monkeypatch.delenv("GEARCHECK_TEST_FIRST", raising=False)
    calls: list[int] = []

    def first() -> None:
        calls.append(os.getpid())
        os.environ["GEARCHECK_TEST_FIRST"] = "1"  # this process's own tasks see it, spawned ones do not

    out = SerialExecutor().map(_marked, [(i,) for i in range(5)], first=first)
    assert calls == [os.getpid()] and all(flag for _, flag in out)
    monkeypatch.delenv("GEARCHECK_TEST_FIRST")
    calls.clear()
    out = ProcessExecutor(2).map(_marked, [(i,) for i in range(64)], first=first)
    assert calls == [os.getpid()]
    assert all(flag == (pid == os.getpid()) for pid, flag in out)


def _index_task(scene, i: int) -> tuple[int, list[str]]:
    return i, scene.built


def test_a_plan_runs_in_its_order_and_its_results_come_back_in_task_order():
    from gearcheck.mechanism import SweepPlan
    from gearcheck.sweep.bodies import MeshData
    from gearcheck.sweep.plan import run_plan

    tri = MeshData("t", np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    tasks = [(_index_task, (i,)) for i in range(40)]
    done: list[str] = []
    order = list(range(39, -1, -1))
    plan = SweepPlan([tri], tasks, reduce=lambda r: r, weights=[2] * 40, order=order,
                     first=lambda: done.append("first"))
    ticks: list[int] = []
    for executor in (SerialExecutor(), ProcessExecutor(2)):
        done.clear()
        out = run_plan(executor, plan, ticks.append)
        assert [i for i, _ in out] == list(range(40)) and done == ["first"]
        assert all(built == [] for _, built in out)  # no task used the mesh: no BVH built
    assert sum(ticks) == 2 * 2 * 40

    class Older:  # an executor from before ``first``: the plan's first work is done before its map
        jobs = 1

        def map(self, fn, tasks, *, setup=None, shared=None, progress=None, weights=None):
            assert done == ["first"]
            return SerialExecutor().map(fn, tasks, setup=setup, shared=shared, progress=progress, weights=weights)

    done.clear()
    assert [i for i, _ in run_plan(Older(), plan)] == list(range(40))
    with pytest.raises(ValueError, match="permutation"):
        SweepPlan([tri], tasks, reduce=lambda r: r, order=[0] * 40)


def test_the_shared_state_reaches_the_workers_through_a_file_removed_after_the_map():
    import glob
    import os
    import tempfile

    folders = ["/dev/shm", tempfile.gettempdir()]

    def left() -> set[str]:
        return {f for d in folders if os.path.isdir(d) for f in glob.glob(os.path.join(d, "gearcheck-shared-*"))}

    before = left()
    tasks = [(float(i), 1.0) for i in range(40)]
    shared = 2.5  # each worker's state is made from the file's copy, the calling process's from its own
    assert ProcessExecutor(2).map(scaled, tasks, setup=float, shared=shared) == [2.5 * (x + y) for x, y in tasks]
    assert left() == before
    with pytest.raises(ArithmeticError):
        ProcessExecutor(2).map(_fails_at, [(i,) for i in range(64)], shared=[1, 2, 3])
    assert left() == before


# ------------------------------------------------------------------------------------------
# Faults: a worker killed, a task no worker can load, more jobs than cores


def _kill_self_at(_state: None, i: int, victim: int) -> int:
    import os
    import signal
    import time

    if i == victim and os.getpid() != int(os.environ["GEARCHECK_TEST_PARENT"]):
        os.kill(os.getpid(), signal.SIGKILL)  # as the OOM killer does
    time.sleep(0.01)
    return i


def test_a_worker_killed_ends_the_map_within_seconds_with_one_line(monkeypatch):
    """Before: the pool replaced the killed worker and waited forever for its chunk's result
    (a check made no progress in 300 s). Now the map stops at once with WorkerError."""
    import os
    import time

    from gearcheck.executor import WorkerError

    monkeypatch.setenv("GEARCHECK_TEST_PARENT", str(os.getpid()))
    started = time.monotonic()
    with pytest.raises(WorkerError, match=r"a worker process died \(killed by SIGKILL: out of memory\?\)"):
        ProcessExecutor(2).map(_kill_self_at, [(i, 3) for i in range(200)])
    assert time.monotonic() - started < 20


def test_a_task_no_worker_can_load_fails_at_once_with_the_cure():
    """A function the workers cannot import (defined in a notebook, ``python -c`` or stdin) ends
    the map with one line naming it and the cure, instead of a pool waiting on dead workers."""
    import time

    from gearcheck.executor import WorkerError

    namespace: dict = {}
    exec("def local_task(state, i):\n    return i\n", namespace)  # noqa: S102 - a function no module holds
    fn = namespace["local_task"]
    fn.__module__ = "__main__"
    started = time.monotonic()
    with pytest.raises(WorkerError, match=r"cannot load local_task from the script or notebook.*jobs=1"):
        ProcessExecutor(2).map(fn, [(i,) for i in range(50)])
    assert time.monotonic() - started < 20


def test_jobs_beyond_the_cores_are_lowered_to_them(caplog):
    """Before: ``--jobs 100000`` started 144 processes (5.3 GB in 48 s)."""
    with caplog.at_level("WARNING", logger="gearcheck"):
        assert ProcessExecutor(100000).jobs == available_cores()
        assert make_executor(100000).jobs == available_cores()
    assert "--jobs 100000: more than the" in caplog.text
    with pytest.raises(ValueError):
        ProcessExecutor(0)


def test_the_shared_state_file_has_no_name_a_killed_run_could_leave():
    """Before: a SIGKILL during a sweep left gearcheck-shared-*.pickle (up to 15 MB) in /dev/shm
    for good. On Linux the workers now read an anonymous memory file through /proc."""
    import os

    from gearcheck.executor import _shared_file

    if not hasattr(os, "memfd_create"):
        pytest.skip("no anonymous memory files here")
    with _shared_file({"a": 1}) as path:
        assert path is not None and path.startswith(f"/proc/{os.getpid()}/fd/")
        import pickle

        with open(path, "rb") as fh:
            assert pickle.load(fh) == {"a": 1}
    assert not os.path.exists(path)


def test_a_script_read_from_stdin_is_one_line_naming_the_cause(tmp_path):
    """Before: ``python - < script.py`` with workers failed with ``OutputError: …/<stdin>:
    cannot write`` (a spawned worker cannot run ``<stdin>`` again), blaming the output folder."""
    import subprocess
    import sys

    script = ("from gearcheck.executor import ProcessExecutor, WorkerError\n"
              "import operator\n"
              "try:\n"
              "    ProcessExecutor(2).map(operator.add, [(i,) for i in range(8)], shared=1)\n"
              "except WorkerError as exc:\n"
              "    print(exc)\n")
    out = subprocess.run([sys.executable, "-"], input=script, capture_output=True, text=True, timeout=60,
                         cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "cannot start from a script that is not a file (<stdin>" in out.stdout and "jobs=1" in out.stdout


def test_a_mechanism_defined_in_a_session_fails_before_the_build_with_the_cure(tmp_path):
    """Before: a mechanism defined in a notebook (here ``python -c``) checked with the default jobs
    never returned: the workers died with ``Can't get attribute 'measure_play' on <module
    '__main__'>`` and the pool waited (killed by a timeout after 150 s). Now one line names what the
    workers cannot load and the cure, before anything is built; and the worker-side check names it
    too when only a task's data lives in ``__main__``."""
    import subprocess
    import sys
    import time
    from pathlib import Path

    spur = Path(__file__).with_name("spur_pair.py")
    script = (f"exec(open({str(spur)!r}).read())\n"
              "import gearcheck\nfrom gearcheck import mechanism\nfrom gearcheck.executor import WorkerError\n"
              "mechanism.register(SpurPair)\n"
              "try:\n"
              f"    gearcheck.load(TEMPLATE).check(out={str(tmp_path / 'run')!r}, jobs=2)\n"
              "except WorkerError as exc:\n"
              "    print(exc)\n")
    started = time.monotonic()
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert time.monotonic() - started < 10
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == ("worker processes cannot load __main__.SpurPair: it is defined in this session (a "
                                  "notebook, python -c or an interactive shell), which they cannot import; define the "
                                  "mechanism in an importable module, or run with jobs=1")
    assert not (tmp_path / "run").exists()


def test_names_in_main_are_found_in_a_tasks_pickle(monkeypatch):
    import sys

    from gearcheck.executor import _names_main

    namespace: dict = {"__name__": "__main__"}
    exec("class Local:\n    pass\n", namespace)  # noqa: S102 - a class no module holds
    local = namespace["Local"]
    monkeypatch.setattr(sys.modules["__main__"], "Local", local, raising=False)
    assert _names_main((1, local())) == "Local"
    assert _names_main((1, [2.0], {"a": "__main__"})) is None
