"""Study benchmarks (`make bench`, section "study"): the analytical level vectorised over 10⁶
variants on one core, the exact level's variants per second per core for each mechanism, and
the same study on local processes against a 2-worker Dask LocalCluster (rows identical, the
throughput ratio)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

STUDIES = Path(__file__).resolve().parents[1] / "src" / "gearcheck" / "templates" / "studies"
BATCH_VARIANTS = 1_000_000
EXACT_VARIANTS = {"track": 12, "differential": 8, "steering": 4}
# The exact level on every core of this machine (local processes), this many variants, and the
# time 10⁴ variants would then take; the differential's must be minutes on 2 cores (the bench
# holds it to a quarter of an hour).
PARALLEL_VARIANTS = 96
TARGET_1E4_S = {"differential": 900.0}


def _spec_and_base(path: Path):
    from gearcheck.design import load
    from gearcheck.studies.run import Base
    from gearcheck.studies.sampling import draw, field_values, nominal_values
    from gearcheck.studies.spec import load_spec, template_path

    spec = load_spec(path)
    design = load(template_path(spec, path))
    nominal = nominal_values(design.data, [i.field for i in spec.inputs])
    return spec, design, Base(design.mechanism, design.data), nominal, draw, field_values


def analytical_batch(path: Path) -> dict[str, Any] | None:
    """10⁶ variants through the mechanism's vectorised analytical model, one core."""
    spec, design, _base, nominal, draw, field_values = _spec_and_base(path)
    inputs = draw(spec, nominal, BATCH_VARIANTS, spec.seed)
    fields = field_values(spec, nominal, inputs)
    t0 = time.perf_counter()
    out = design.impl.study_batch(design.params, fields)
    if out is None:
        return None
    dt = time.perf_counter() - t0
    return {"variants": BATCH_VARIANTS, "seconds": dt, "variants_per_s": BATCH_VARIANTS / dt,
            "target_s": 10.0, "meets_target": dt <= 10.0, "outputs": len(out)}


def exact_rate(path: Path) -> dict[str, Any]:
    """The exact level in this process (validation included): variants per second on one core.
    A mechanism whose exact figures are its model's (steering: the exact contact intervals are in
    calc) is measured at the analytical level, and says so."""
    from gearcheck.executor import SerialExecutor
    from gearcheck.studies.run import run_level

    spec, design, base, nominal, draw, field_values = _spec_and_base(path)
    n = EXACT_VARIANTS.get(design.mechanism, 4)
    fields = field_values(spec, nominal, draw(spec, nominal, n, spec.seed))
    level = "exact" if design.impl.study_row(design.params, "exact") else "analytical"
    t0 = time.perf_counter()
    res = run_level(base, level, fields, np.arange(n), SerialExecutor())
    dt = time.perf_counter() - t0
    valid = sum(isinstance(r, dict) for r in res.rows)
    out = {"level": level, "variants": n, "valid": valid, "seconds": dt, "variants_per_s_per_core": n / dt}
    if level == "exact":
        from gearcheck.executor import ProcessExecutor, available_cores

        jobs = available_cores()
        m = PARALLEL_VARIANTS
        fields = field_values(spec, nominal, draw(spec, nominal, m, spec.seed))
        t0 = time.perf_counter()  # the processes' start-up included, as a study pays it
        run_level(base, level, fields, np.arange(m), ProcessExecutor(jobs))
        wall = time.perf_counter() - t0
        out.update({"cores": jobs, "parallel_variants": m, "parallel_seconds": wall,
                    "parallel_variants_per_s": m / wall, "projected_1e4_variants_s": 1e4 * wall / m})
        target = TARGET_1E4_S.get(design.mechanism)
        if target is not None:
            out.update({"target_1e4_s": target, "meets_target": 1e4 * wall / m <= target})
    return out


def dask_vs_local(path: Path, samples: int = 64, workers: int = 2) -> dict[str, Any]:
    """The same study on `workers` local processes and on a `workers`-worker LocalCluster."""
    import gearcheck

    t0 = time.perf_counter()
    local = gearcheck.study(path, samples=samples, jobs=workers, check_worst=0)
    t1 = time.perf_counter()
    dask = gearcheck.study(path, samples=samples, jobs=workers, scheduler="local-cluster", check_worst=0)
    t2 = time.perf_counter()
    return {"study": path.stem, "samples": samples, "workers": workers, "local_s": t1 - t0, "dask_s": t2 - t1,
            "dask_over_local_throughput": (t1 - t0) / (t2 - t1), "rows_identical": bool(local.table.equals(dask.table))}


def bench_study() -> dict[str, Any]:
    out: dict[str, Any] = {"analytical_batch": {}, "exact_level": {}}
    for path in sorted(STUDIES.glob("*.toml")):
        batch = analytical_batch(path)
        if batch is not None:
            out["analytical_batch"][path.stem] = batch
        out["exact_level"][path.stem] = exact_rate(path)
    out["dask_vs_local"] = dask_vs_local(STUDIES / "track_wear.toml")
    return out
