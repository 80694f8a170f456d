"""One benchmark measurement in a fresh process, one JSON line on stdout (used by bench/run.py).

    probe.py calc TEMPLATE [--repeat N]      the analytical model: first call, then N warm calls
    probe.py sweep TEMPLATE [--jobs 1,2]     build and mesh once (untimed), then the sweep on each
                                             number of workers in turn: wall time and its figures

The same script measures the baseline and the current code: ``bench/run.py`` runs it with
``PYTHONPATH`` set to one side's ``src`` and reports which ``gearcheck`` was imported
(``gearcheck_file``), so a measurement can never be credited to the wrong side. Two APIs are
known: the current one (``gearcheck.design`` and ``gearcheck.pipeline``: build, then
``pipeline.sweep``) and the earlier one (``gearcheck.mechanisms.load_template``, the mechanism's
``calc``, ``parts.build_parts``, ``cad.export.export_parts`` at the mechanism's mesh tolerance,
``check.run_check``). Each sweep measured is the whole mechanism check on the meshes: planning,
the pool of workers (started and stopped inside the timed span), and the reduction to verdicts.

Only figures both APIs give are read from the sweeps' timings; the counts behind them are
recovered from rates and times where a version does not keep them (steering: poses = poses/s x
elapsed s; track: sprocket poses = poses/s x sweep s).
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import resource
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any


def _api() -> str:
    try:
        import gearcheck.pipeline  # noqa: F401
        from gearcheck.design import load_template  # noqa: F401
    except ImportError:
        return "mechanisms"
    return "pipeline"


def _plain(value: Any) -> Any:
    """JSON-ready: numbers as float/int (NaN as None), containers recursed, the rest as text."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    try:
        number = float(value)
    except (TypeError, ValueError):
        return str(value)
    if not math.isfinite(number):
        return None
    return int(number) if isinstance(value, int) or (hasattr(value, "dtype") and "int" in str(value.dtype)) \
        else number


def calc_fn(api: str, template: Path) -> Callable[[], Any]:
    if api == "pipeline":
        from gearcheck.design import load_template

        design = load_template(template)
        return design.calc
    loaded = importlib.import_module("gearcheck.mechanisms").load_template(template)
    module, params = loaded.module, loaded.params
    return lambda: module.calc(params)


def probe_calc(api: str, template: Path, repeat: int) -> dict:
    fn = calc_fn(api, template)
    t0 = time.perf_counter()
    fn()
    first = time.perf_counter() - t0
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t0)
    return {"first_s": first, "warm_median_s": statistics.median(runs), "warm_runs_s": runs}


def sweep_fn(api: str, template: Path, tmp: Path) -> tuple[str, Callable[[int], Any]]:
    """Build and mesh the template (untimed); a function running the sweep on ``jobs`` workers."""
    if api == "pipeline":
        from gearcheck import pipeline
        from gearcheck.design import load_template

        design = load_template(template)
        run = pipeline.build(design, tmp / "run")
        return design.mechanism, lambda jobs: pipeline.sweep(design, run.assembly, run.bodies, jobs=jobs)
    export = importlib.import_module("gearcheck.cad.export")  # the earlier API, by name (absent now)
    loaded = importlib.import_module("gearcheck.mechanisms").load_template(template)
    parts = loaded.parts_module.build_parts(loaded.params)
    _, exported = export.export_parts(parts, tmp, name=loaded.name, mechanism=loaded.mechanism,
                               params_data=loaded.resolved_data, tol_mm=loaded.module.MESH_TOL_MM)
    bodies = export.sweep_bodies(exported)
    check = loaded.check_module
    return loaded.mechanism, lambda jobs: check.run_check(loaded.params, bodies, workers=jobs)


def default_jobs(api: str) -> int | None:
    """The number of workers the sweep uses when none is asked for (the pool's default)."""
    try:
        if api == "pipeline":
            return int(importlib.import_module("gearcheck.executor").make_executor(None).jobs)
        return int(importlib.import_module("gearcheck.sweep.pool").default_workers())
    except Exception:  # a figure the harness reports, never a reason to stop
        return None


def _cpu_s() -> float:
    """CPU seconds of this process and of its waited-for children (the pool's workers)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def work_count(mechanism: str, timings: dict) -> dict:
    """What the sweep evaluated, from its timings: differential collide calls, steering poses,
    track sprocket poses (None when the timings do not tell)."""
    try:
        if mechanism == "differential":
            if "fcl_queries" in timings:  # the current code: collisions and distance queries
                return {"unit": "FCL queries", "count": int(timings["fcl_queries"])}
            return {"unit": "collide calls", "count": int(timings["collide_calls"])}
        if mechanism == "steering":
            return {"unit": "poses", "count": int(round(timings["poses_per_s"] * timings["elapsed_s"]))}
        if mechanism == "track":
            return {"unit": "sprocket poses", "count": int(round(timings["poses_per_s"] * timings["sweep_s"]))}
    except (KeyError, TypeError, ValueError):
        pass
    return {"unit": None, "count": None}


def probe_sweep(api: str, template: Path, jobs_list: list[int]) -> dict:
    with tempfile.TemporaryDirectory(prefix="gearcheck-probe-") as tmp:
        t0 = time.perf_counter()
        mechanism, run = sweep_fn(api, template, Path(tmp))
        build_s = time.perf_counter() - t0
        runs: dict[str, Any] = {}
        for jobs in jobs_list:
            cpu0, t0 = _cpu_s(), time.perf_counter()
            result = run(jobs)
            wall, cpu = time.perf_counter() - t0, _cpu_s() - cpu0
            timings = _plain(dict(result.timings))
            runs[f"jobs_{jobs}"] = {"jobs": jobs, "wall_s": wall, "cpu_s": cpu, "timings": timings,
                                    **work_count(mechanism, timings)}
    return {"mechanism": mechanism, "build_s": build_s, "default_jobs": default_jobs(api), "runs": runs}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("figure", choices=("calc", "sweep"))
    ap.add_argument("template", type=Path)
    ap.add_argument("--repeat", type=int, default=5, help="warm calls of calc")
    ap.add_argument("--jobs", default="1", help="comma-separated worker counts for sweep, run in this order")
    args = ap.parse_args(argv)
    import gearcheck

    api = _api()
    out: dict[str, Any] = {"figure": args.figure, "template": str(args.template), "api": api,
                           "gearcheck_file": str(Path(gearcheck.__file__).resolve()), "ok": True}
    try:
        if args.figure == "calc":
            out.update(probe_calc(api, args.template, args.repeat))
        else:
            out.update(probe_sweep(api, args.template, [int(j) for j in args.jobs.split(",")]))
    except Exception as exc:  # reported to run.py, which records it and carries on
        import traceback

        traceback.print_exc(file=sys.stderr)
        out.update(ok=False, error=f"{type(exc).__name__}: {exc}")
    sys.stdout.write(json.dumps(out, allow_nan=False) + "\n")
    return 0 if out["ok"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
