"""One study, end to end: draw the variants, evaluate them level by level, re-check the worst on
real geometry, and write results.parquet, summary.json and report.html as one transaction."""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import tempfile
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gearcheck.params import ParamError
from gearcheck.pipeline import ProgressFactory, no_progress
from gearcheck.studies import stats
from gearcheck.studies.run import Base, run_level
from gearcheck.studies.sampling import draw, field_values, integer_fields, nominal_values
from gearcheck.studies.spec import (FIGURE_LEVELS, StudySpec, check_fields, check_outputs, check_scheduler, load_spec,
                                    template_path, with_flags)

log = logging.getLogger("gearcheck")

REJECTIONS_LISTED = 200  # in summary.json (every one is in results.parquet)
FILES = ("results.parquet", "summary.json", "report.html")
# How long a Dask scheduler given by address may take to answer (seconds; the environment
# variable overrides it, e.g. for a scheduler on a slow network).
SCHEDULER_TIMEOUT_S = 20.0
SCHEDULER_TIMEOUT_ENV = "GEARCHECK_SCHEDULER_TIMEOUT"


@dataclass
class StudyResult:
    """A finished study: the table (pyarrow), summary.json's data, the folder written (if any)."""

    spec: StudySpec
    table: Any  # pyarrow.Table
    summary: dict
    folder: Path | None = None
    timings: dict = field(default_factory=dict)

    def to_pandas(self):
        return self.table.to_pandas()

    def __repr__(self) -> str:
        from gearcheck.notebook import study_repr

        return study_repr(self)

    def _repr_html_(self) -> str:
        from gearcheck.notebook import study_html

        return study_html(self)


def scheduler_timeout() -> float:
    """Seconds a Dask scheduler given by address may take to answer (:data:`SCHEDULER_TIMEOUT_S`,
    or ``$GEARCHECK_SCHEDULER_TIMEOUT``)."""
    text = os.environ.get(SCHEDULER_TIMEOUT_ENV)
    if text is None:
        return SCHEDULER_TIMEOUT_S
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 < value <= 3600:
        raise ParamError(SCHEDULER_TIMEOUT_ENV, text, "allowed a number of seconds > 0 to 3600")
    return value


@contextlib.contextmanager
def _executor(jobs: int | None, scheduler: str | None, timeout: float = SCHEDULER_TIMEOUT_S) -> Iterator[Any]:
    from gearcheck.executor import DaskExecutor, make_executor

    if not scheduler:
        yield make_executor(jobs)
        return
    try:
        executor = DaskExecutor(scheduler, jobs, timeout=timeout)
    except OSError:  # refused, unreachable, or no answer in time: distributed retries until the timeout
        if scheduler == "local-cluster":
            raise
        raise ParamError("--scheduler", scheduler, f"no Dask scheduler answered within {timeout:g} s (start one "
                         "with `dask scheduler`, or run on --scheduler local-cluster)") from None
    except (TypeError, ValueError) as exc:  # e.g. tls:// without Dask's TLS configuration
        if scheduler == "local-cluster":
            raise
        raise ParamError("--scheduler", scheduler, f"could not connect: {exc}") from None
    with executor:
        yield executor


def study_figures(spec: StudySpec, base: Base) -> list[str]:
    """The figures (``LEVEL.KEY``) the template's own values give at each level the study names
    an output of (the analytical level always): the names its outputs may take."""
    from gearcheck import mechanism as registry
    from gearcheck.design import from_data

    named = {spec.rank_by, *(f.output for f in spec.failures), *(p.output for p in spec.paper)}
    levels = [lv for lv in FIGURE_LEVELS if lv == "analytical" or any(n.startswith(f"{lv}.") for n in named)]
    impl = registry.get(base.mechanism)
    params = from_data(base.data).params
    return [f"{lv}.{k}" for lv in levels for k in impl.study_row(params, lv)]


def _prefixed(level: str, cols: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {f"{level}.{k}": v for k, v in cols.items()}


def _scatter(n: int, indices: np.ndarray, cols: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    out = {}
    for k, v in cols.items():
        full = np.full(n, math.nan)
        full[indices] = v
        out[k] = full
    return out


def shown(path: Path) -> str:
    """A path as a reader can follow it: a shipped file by where it sits in the package, another
    relative to the working folder when inside it, else as it is."""
    from gearcheck.design import packaged_templates

    p = Path(path).absolute()
    with contextlib.suppress(ValueError):
        return f"gearcheck/templates/{p.relative_to(packaged_templates().absolute())} (shipped)"
    with contextlib.suppress(ValueError):
        return str(p.relative_to(Path.cwd()))
    return str(path)


def evaluate(spec: StudySpec, base: Base, inputs: dict[str, np.ndarray], executor: Any,
             progress: ProgressFactory = no_progress, exact: int | None = None,
             figures: Iterable[str] = ()) -> dict[str, Any]:
    """Levels 1 and 2 over the variants (``inputs``: the template fields each sets): validity,
    rejection reasons and figure columns (each of ``figures`` among them, NaN where no variant
    gave it: all rejected, or a level not run)."""
    n = len(next(iter(inputs.values())))
    all_idx = np.arange(n)
    t0 = time.perf_counter()
    with progress("study: analytical model", n, "variant") as bar:
        first = run_level(base, "analytical", inputs, all_idx, executor, bar.update)
    valid = np.array([isinstance(r, dict) for r in first.rows])
    rejection = [r if isinstance(r, str) else "" for r in first.rows]
    cols = _prefixed("analytical", first.columns)
    t1 = time.perf_counter()
    wanted = spec.exact if exact is None else exact
    exact_idx = all_idx[valid] if wanted < 0 else all_idx[valid][:wanted]
    with progress("study: exact model", len(exact_idx), "variant") as bar:
        second = run_level(base, "exact", inputs, exact_idx, executor, bar.update)
    cols |= _prefixed("exact", _scatter(n, exact_idx, second.columns))
    t2 = time.perf_counter()
    if any(k.startswith("contact.") for k in figures):  # tooth contact analysis: only when a study names it
        with progress("study: tooth contact analysis", len(exact_idx), "variant") as bar:
            third = run_level(base, "contact", inputs, exact_idx, executor, bar.update)
        cols |= _prefixed("contact", _scatter(n, exact_idx, third.columns))
    cols |= {k: np.full(n, math.nan) for k in figures if k not in cols}
    t3 = time.perf_counter()
    return {"valid": valid, "rejection": rejection, "figures": cols, "exact_rows": exact_idx,
            "timings": {"analytical_s": t1 - t0, "exact_s": t2 - t1, "contact_s": t3 - t2,
                        "analytical_variants": n, "exact_variants": int(len(exact_idx))}}


def worst_variants(spec: StudySpec, figures: dict[str, np.ndarray], valid: np.ndarray, k: int) -> list[int]:
    """The K valid variants with the lowest ``rank_by`` (finite values only)."""
    if k <= 0:
        return []
    key = spec.rank_by
    if key not in figures:
        raise ParamError("rank_by", key, f"allowed one of the study's figures: {', '.join(sorted(figures))}")
    v = np.where(valid & np.isfinite(figures[key]), figures[key], np.inf)
    order = np.argsort(v, kind="stable")
    return [int(i) for i in order[:k] if np.isfinite(v[i])]


def run_checks(base: Base, inputs: dict[str, np.ndarray], picks: list[int], folder: Path | None, jobs: int | None,
               progress: ProgressFactory = no_progress) -> list[dict]:
    """Level 3: the full check of each picked variant, in ``folder/checks/variant_NNNNN``.

    A check is a run folder of its own (locked, staged, swapped in): it runs in a temporary
    folder (inside ``folder``: same file system) and only its finished folder is moved in, so
    the study's folder holds the checks' files and none of their transactions' (a lock file)."""
    from gearcheck import pipeline
    from gearcheck.design import from_data
    from gearcheck.studies.run import variant_data

    out = []
    for i in picks:
        design = from_data(variant_data(base, {f: float(inputs[f][i]) for f in inputs}))
        name = f"variant_{i:05d}"
        target = (folder / "checks" / name) if folder is not None else None
        with tempfile.TemporaryDirectory(prefix=".check-", dir=folder) as tmp:
            run = pipeline.check(design, Path(tmp) / name, jobs=jobs, progress=progress)
            if target is not None:
                target.parent.mkdir(exist_ok=True)
                os.rename(Path(tmp) / name, target)
        result = run.result
        out.append({"variant": i, "folder": f"checks/{name}" if target is not None else "",
                    "level": result.level, "passed": bool(result.passed),
                    "verdicts": {v.name: v.level for v in result.verdicts},
                    "failed": [f"{v.label}: {v.measured}" for v in result.verdicts if v.level == "fail"]})
    return out


def summarise(spec: StudySpec, template: str, inputs: dict[str, np.ndarray], ev: dict, checks: list[dict],
              samples: int, seed: int) -> dict:
    """summary.json: distributions, failure probabilities (Wilson 95 %), sensitivity, checks."""
    figures, valid = ev["figures"], ev["valid"]
    n = len(valid)
    outputs = {k: stats.describe(v[valid]) for k, v in sorted(figures.items())}
    failures = {}
    for f in spec.failures:
        if f.output not in figures:
            raise ParamError(f"failures[{f.name}].output", f.output,
                             f"allowed one of the study's figures: {', '.join(sorted(figures))}")
        v = figures[f.output]
        seen = valid & np.isfinite(v)
        failed = seen & np.array([f.failed(x) if math.isfinite(x) else False for x in v])
        p, lo, hi = stats.wilson(int(failed.sum()), int(seen.sum()))
        # over every variant drawn where the output was asked for: those the template rejects (out
        # of spec) counted as failures of their own kind
        out_of_spec = int((~valid).sum()) if seen.any() else 0
        drawn, failed_or_rejected = int(seen.sum()) + out_of_spec, int(failed.sum()) + out_of_spec
        pd, lod, hid = stats.wilson(failed_or_rejected, drawn)
        failures[f.name] = {"label": f.label, "output": f.output, "limit": f.below if f.below is not None else f.above,
                            "side": "below" if f.below is not None else "above", "variants": int(seen.sum()),
                            "failures": int(failed.sum()), "probability": p, "ci95_low": lo, "ci95_high": hi,
                            "interval": "Wilson score, 95 %", "over": "valid variants",
                            "over_drawn": {"variants": drawn, "failures": failed_or_rejected, "rejected": out_of_spec,
                                           "probability": pd, "ci95_low": lod, "ci95_high": hid}}
    targets = sorted({spec.rank_by, *(f.output for f in spec.failures)} & set(figures))
    sensitivity = {}
    for t in targets:
        rows = valid & np.isfinite(figures[t])
        x = {k: np.asarray(v)[rows] for k, v in inputs.items()}
        coef, r2 = stats.src(x, figures[t][rows])
        rcoef, rr2 = stats.src(x, figures[t][rows], ranked=True)
        ranking = sorted(coef, key=lambda k: -abs(rcoef[k]))
        sensitivity[t] = {"src": coef, "r2": r2, "srrc": rcoef, "r2_rank": rr2, "ranking": ranking,
                          "variants": int(rows.sum())}
    rejected = [{"variant": int(i), "reason": ev["rejection"][i]} for i in np.flatnonzero(~valid)]
    return {
        "study": spec.title, "template": template, "samples": samples, "seed": seed, "sampler": spec.sampler,
        "inputs": {i.key: {"field": i.field, "mode": i.mode, "distribution": i.distribution, "unit": i.unit,
                           "reason": i.reason,
                           **{k: getattr(i, k) for k in ("mean", "sd", "low", "high") if getattr(i, k) is not None},
                           "sampled": stats.describe(inputs[i.key])} for i in spec.inputs},
        "valid": int(valid.sum()), "rejected": int(n - valid.sum()),
        "rejections": rejected[:REJECTIONS_LISTED], "exact_variants": int(len(ev["exact_rows"])),
        "outputs": outputs, "failures": failures, "sensitivity": sensitivity, "checks": checks,
        "paper": [p.model_dump() for p in spec.paper],
    }


def table(inputs: dict[str, np.ndarray], fields: dict[str, np.ndarray], ev: dict, checks: list[dict]):
    """results.parquet's table: one row per variant (inputs, figures per level, validity, the
    rejection reason, the check's level where it ran)."""
    import pyarrow as pa

    n = len(ev["valid"])
    level = [""] * n
    folder = [""] * n
    for c in checks:
        level[c["variant"]] = c["level"]
        folder[c["variant"]] = c["folder"]
    cols: dict[str, Any] = {"variant": pa.array(np.arange(n), pa.int64()), "valid": pa.array(ev["valid"]),
                            "rejection": pa.array(ev["rejection"], pa.string())}
    # a figure a variant has no value for (rejected, or not evaluated at that level) is null
    cols |= {f"in.{k}": pa.array(v, pa.float64()) for k, v in inputs.items()}
    # the template fields as set, where an offset makes them differ from an input's draw
    cols |= {f"field.{k}": pa.array(v, pa.float64()) for k, v in fields.items()
             if k not in inputs or not np.array_equal(v, inputs[k])}
    cols |= {k: pa.array(v, pa.float64(), from_pandas=True) for k, v in ev["figures"].items()}
    cols |= {"check.level": pa.array(level, pa.string()), "check.folder": pa.array(folder, pa.string())}
    return pa.table(cols)


def _json(data: dict) -> str:
    def clean(x):
        if isinstance(x, dict):
            return {str(k): clean(v) for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v) for v in x]
        if isinstance(x, (np.floating, float)):
            return float(x) if math.isfinite(float(x)) else None
        if isinstance(x, (np.integer,)):
            return int(x)
        if isinstance(x, np.bool_):
            return bool(x)
        return x

    return json.dumps(clean(data), indent=2, sort_keys=True, allow_nan=False) + "\n"


def study(path: str | Path, *, samples: int | None = None, seed: int | None = None, jobs: int | None = None,
          scheduler: str | None = None, out: str | Path | None = None, exact: int | None = None,
          check_worst: int | None = None, progress: ProgressFactory = no_progress) -> StudyResult:
    """Run a study file. ``out``: the folder to write (one transaction), or None for no files
    (level 3 then runs in temporary folders). ``scheduler``: None (local processes, ``jobs``
    of them; 1 runs in this process), ``"local-cluster"`` (a Dask LocalCluster of ``jobs``
    workers) or ``"tcp://HOST:PORT"`` / ``"tls://HOST:PORT"`` (an existing Dask cluster, which
    must answer within 20 s, or ``$GEARCHECK_SCHEDULER_TIMEOUT`` seconds). ``samples``,
    ``seed``, ``exact`` and ``check_worst`` override the study file's, within its limits.

    Everything is checked before any variant is drawn (one-line :class:`ParamError`): the
    study file, the overrides, the scheduler's address, and that ``rank_by`` and every
    failure's output name a figure of the mechanism. A study whose every variant the template
    rejects is an error too (the first rejection's reason), and writes nothing."""
    from gearcheck.design import load
    from gearcheck.output import RunFolder, atomic_write_bytes, atomic_write_text

    path = Path(path)
    check_scheduler(scheduler)
    timeout = scheduler_timeout() if scheduler not in (None, "local-cluster") else SCHEDULER_TIMEOUT_S
    spec = with_flags(load_spec(path), samples=samples, seed=seed, exact=exact, check_worst=check_worst)
    tpl = template_path(spec, path)
    design = load(tpl)
    check_fields(spec, type(design.params), str(path))
    n, s, k = spec.samples, spec.seed, spec.check_worst
    nominal = nominal_values(design.data, [i.field for i in spec.inputs])
    base = Base(design.mechanism, design.data, integer_fields(spec, nominal))
    figures = study_figures(spec, base)
    check_outputs(spec, set(figures), str(path))
    inputs = draw(spec, nominal, n, s)
    fields = field_values(spec, nominal, inputs)
    t0 = time.perf_counter()
    with _executor(jobs, scheduler, timeout) as executor:
        ev = evaluate(spec, base, fields, executor, progress, figures=figures)
    if not ev["valid"].any():
        first = next(i for i, r in enumerate(ev["rejection"]) if r)
        raise ParamError("", None, f"every one of the {n} variants was rejected by the template's checks, nothing "
                         f"to report; the first, variant {first}: {ev['rejection'][first]}", str(path))
    picks = worst_variants(spec, ev["figures"], ev["valid"], k)

    def finish(folder: Path | None) -> StudyResult:
        t1 = time.perf_counter()
        checks = run_checks(base, fields, picks, folder, jobs if not scheduler else None, progress)
        timings = {**ev["timings"], "check_s": time.perf_counter() - t1, "total_s": time.perf_counter() - t0,
                   "workers": getattr(executor, "jobs", 1)}
        summary = summarise(spec, shown(tpl), inputs, ev, checks, n, s)
        tab = table(inputs, fields, ev, checks)
        result = StudyResult(spec, tab, summary, folder, timings)
        if folder is not None:
            import pyarrow as pa
            import pyarrow.parquet as pq

            from gearcheck import __version__
            from gearcheck.design import from_data
            from gearcheck.studies.report import render

            sink = pa.BufferOutputStream()
            pq.write_table(tab, sink, compression="zstd")
            atomic_write_bytes(folder / "results.parquet", sink.getvalue().to_pybytes())
            atomic_write_text(folder / "summary.json", _json(summary))
            labels = {f.key: f.label for f in from_data(base.data).calc().figures}
            atomic_write_text(folder / "report.html", render(spec, summary, tab, study_file=shown(path),
                                                             labels=labels))
            from gearcheck.pipeline import seal

            seal(folder, {"gearcheck_version": __version__, "kind": "study", "study": shown(path),
                                "template": shown(tpl), "samples": n, "seed": s}, Path(out))  # type: ignore[arg-type]
        return result

    if out is None:
        return finish(None)
    with RunFolder(Path(out)) as txn:
        result = finish(txn.staging)
        result.folder = txn.commit()
    return result
