"""`make fuzz`: random parameter sets through validation, the analytical models and the CAD.

For each mechanism, seeded random sets around its shipped template (the sampler the property
tests use, gearcheck.mechanisms.sampling) go through the template model: a rejection must be one
ParamError line naming a field of the set and an allowed range; an accepted set must run the
paper's analytical model with finite figures (NaN only where documented). The first accepted sets
of each mechanism are then built (build_parts), every solid checked valid and meshed at 0.02 mm
(watertight, volume within the mesh's error bound) — and handed to :func:`sweep_sample`.

Each built set is then swept at its mechanism's default meshing tolerance (as `gearcheck check`
meshes: differential 0.003 mm, track 0.008, steering 0.01) with its mechanism's check (the
differential at 4 drive angles and its own shim), and the mesh-resolution rule applied: a set
whose smallest clearance checked is below 10× the mesh-error bound is *rejected after meshing*
(one --tol line, counted apart, not a failure). A failure is: a rejection message that is not one
line naming a field and a range, a calc/CAD/sweep exception, or a consistency verdict (mesh
sweep vs the independent exact model) that does not hold.

Prints tried / accepted / rejected / swept per mechanism and the rejection reasons, writes
out/fuzz.json (counts, histograms, timings and every failure with the set that caused it, to
reproduce), and exits 1 if anything failed. Defaults: 1200 sets per mechanism, 35 CAD builds and
sweeps per mechanism (105). --sets/--cad scale it; --only picks mechanisms. Measured full run
(2 cores): 3600 tried, 1100 accepted (all through calc), 105 built and swept, 10 of them rejected
after meshing, 0 failures, 1357 s (differential 726 s: its 0.003 mm meshes; steering calc 0.7 s
per set).
"""

from __future__ import annotations

import argparse
import collections
import copy
import json
import math
import platform
import re
import sys
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from gearcheck import __version__, pipeline  # noqa: E402
from gearcheck.design import Design, load_template  # noqa: E402
from gearcheck.mechanism import Mechanism, get, names  # noqa: E402
from gearcheck.mechanisms.sampling import RandomDraw  # noqa: E402
from gearcheck.output import atomic_write_text, ensure_out_dir  # noqa: E402
from gearcheck.params import ParamError, validate  # noqa: E402

TEMPLATE_DIR = ROOT / "templates"
MESH_TOL_MM = 0.02


def sweep_sample(design: Design) -> dict:
    """The FCL sweep of one fuzzed, built set through the pipeline: mesh at the check's default
    tolerance (as `gearcheck check` meshes), sweep with the mechanism's fuzz options (cheaper
    sampling where it has them), apply the mesh-resolution rule; return the verdicts as numbers.

    Raises when a consistency verdict fails (mesh sweep disagrees with the exact model): that is
    a defect of gearcheck, whatever the design. Design verdicts are recorded, not failures.
    ParamError: rejected after meshing."""
    import tempfile


    impl = design.impl
    with tempfile.TemporaryDirectory() as tmp:
        run = pipeline.build(design, Path(tmp))
    result = pipeline.sweep(design, run.assembly, run.bodies, options=impl.fuzz_options(design.params),
                            mesh_plan=run.mesh_plan)
    verdicts = {v.name: int(v.passed) for v in result.verdicts}
    broken = [k for k in impl.consistency_verdicts if verdicts.get(k) == 0]
    if broken:
        details = "; ".join(v.measured for v in result.verdicts if v.name in broken)
        raise AssertionError(f"mesh sweep disagrees with the exact model: {details}")
    return {"verdicts": verdicts, "verdict_pass": int(result.passed),
            "mesh_resolution": result.summary["mesh_resolution"]}


def _reason(exc: ParamError) -> str:
    """The rejection without its numbers: 'field: allowed # to #: pointed teeth, ...'."""
    text = re.sub(r"(?<![A-Za-z_])[-+]?\d+(\.\d+)?(e[-+]?\d+)?", "#", exc.allowed)
    return f"{exc.field}: {text[:90]}"


def _lookup(body: dict, field: str):
    node = body
    for name in field.split("."):
        node = node[int(name)] if isinstance(node, list) else node[name]
    return node


def check_rejection(body: dict, exc: ParamError, source: str = "fuzz") -> str | None:
    """What is wrong with a rejection message, or None: one line per broken rule (several rules
    named together carry ``errors``), each naming a field of the set and its allowed range."""
    errors = getattr(exc, "errors", None)
    if errors is not None:
        lines_ok = str(exc).splitlines() == [str(e) for e in errors]
        return next((p for e in errors if (p := check_rejection(body, e, source))), None) if lines_ok \
            else "a line per broken rule expected"
    text = str(exc)
    if "\n" in text:
        return "message is more than one line"
    if not exc.field or not text.startswith(f"{source}: {exc.field} = "):
        return "message does not name a field"
    if "allowed" not in exc.allowed:
        return "message gives no allowed range"
    try:
        _lookup(body, exc.field)
    except (KeyError, IndexError, ValueError, TypeError):
        return f"field {exc.field} is not in the set"
    return None


def check_figures(impl: Mechanism, figures) -> tuple[str | None, list[str]]:
    nan: list[str] = []
    for f in figures:
        if math.isinf(f.value):
            return f"figure {f.key} is infinite", nan
        if math.isnan(f.value):
            if f.key not in impl.nan_figures:
                return f"figure {f.key} is NaN (not documented as possible)", nan
            nan.append(f.key)
    return None, nan


def check_parts(parts) -> tuple[str | None, dict]:
    """Valid solids, watertight meshes whose volume is within area × error bound of the B-rep."""
    from gearcheck.cad.mesh import mesh_shape

    seen, worst_error, triangles = set(), 0.0, 0
    for part in parts:
        if id(part.solid) in seen:
            continue
        seen.add(id(part.solid))
        if not part.solid.isValid():
            return f"{part.name}: invalid solid", {}
        mesh = mesh_shape(part.solid, MESH_TOL_MM, error_samples=300)
        if not mesh.is_watertight():
            return f"{part.name}: mesh not watertight", {}
        volume = part.solid.Volume()
        if not abs(mesh.volume() - volume) <= mesh.area() * mesh.error_bound_mm + 1e-6:
            return f"{part.name}: mesh volume {mesh.volume():.3f} vs solid {volume:.3f} mm³", {}
        worst_error = max(worst_error, mesh.error_bound_mm)
        triangles += len(mesh.faces)
    return None, {"solids": len(seen), "parts": len(parts), "triangles": triangles,
                  "mesh_error_bound_mm": worst_error}


class _Run:
    """One mechanism's fuzz: counts, histograms, timings and failures, stage by stage."""

    def __init__(self, impl: Mechanism, log):
        self.impl, self.log = impl, log
        self.stats = {"tried": 0, "accepted": 0, "rejected": 0, "calc_ok": 0, "cad_built": 0, "cad_ok": 0,
                      "swept": 0, "rejected_after_meshing": 0}
        self.fields: collections.Counter = collections.Counter()
        self.reasons: collections.Counter = collections.Counter()
        self.nan_figures: collections.Counter = collections.Counter()
        self.failures: list[dict] = []
        self.swept_sets: list[dict] = []
        self.timing = {"validate_s": 0.0, "calc_s": 0.0, "cad_s": 0.0}

    def fail(self, stage: str, set_seed: int, data: dict, error: str) -> None:
        self.failures.append({"mechanism": self.impl.name, "seed": set_seed, "stage": stage, "error": error,
                              "set": data})
        self.log(f"  FAIL {self.impl.name} seed {set_seed} [{stage}]: {error.splitlines()[-1] if error else ''}")

    def validated(self, set_seed: int, data: dict):
        """The set's Params, or None (rejected: counted, its message checked)."""
        from gearcheck.design import RUN_KEYS

        body = {k: v for k, v in data.items() if k not in RUN_KEYS}  # mechanism, name, mesh_tol_mm: not Params
        self.stats["tried"] += 1
        t0 = time.perf_counter()
        try:
            return validate(self.impl.Params, body, "fuzz")
        except ParamError as exc:
            self.stats["rejected"] += 1
            self.fields[exc.field] += 1
            self.reasons[_reason(exc)] += 1
            problem = check_rejection(body, exc)
            if problem:
                self.fail("reject", set_seed, data, f"{problem}: {exc}")
        except Exception:
            self.fail("validate", set_seed, data, traceback.format_exc())
        finally:
            self.timing["validate_s"] += time.perf_counter() - t0
        return None

    def calc_ok(self, set_seed: int, data: dict, params) -> bool:
        t0 = time.perf_counter()
        try:
            problem, nan = check_figures(self.impl, self.impl.analyse(params))
        except Exception:
            problem, nan = traceback.format_exc(), []
        self.timing["calc_s"] += time.perf_counter() - t0
        self.nan_figures.update(nan)
        if problem:
            self.fail("calc", set_seed, data, problem)
            return False
        self.stats["calc_ok"] += 1
        return True

    def cad_and_sweep(self, set_seed: int, data: dict, params, cad: int) -> None:
        mech = self.impl.name
        self.stats["cad_built"] += 1
        t0 = time.perf_counter()
        design = Design(Path(f"fuzz/{mech}-{set_seed}.toml"), mech, params, data)
        try:
            _, parts = pipeline.build_parts(design)
            problem, built = check_parts(parts)
        except Exception:
            problem, built = traceback.format_exc(), {}
        self.timing["cad_s"] += time.perf_counter() - t0
        if problem:
            self.fail("cad", set_seed, data, problem)
            return
        self.stats["cad_ok"] += 1
        try:
            result = sweep_sample(design)
        except ParamError as exc:  # the mesh-resolution rule: a clear rejection, not a failure
            self.stats["rejected_after_meshing"] += 1
            problem = check_rejection({"--tol": 0}, exc, source="fuzz")
            if problem:
                self.fail("mesh-rule", set_seed, data, f"{problem}: {exc}")
            else:
                self.reasons[_reason(exc)] += 1
            return
        except Exception:
            self.fail("sweep", set_seed, data, traceback.format_exc())
            return
        self.stats["swept"] += 1
        self.swept_sets.append({"seed": set_seed, "build": built, "sweep": result})
        self.log(f"  {mech} CAD {self.stats['cad_built']}/{cad} seed {set_seed}: {built['parts']} parts, "
                 f"{built['triangles']} triangles ({time.perf_counter() - t0:.1f} s)")

    def summary(self) -> dict:
        return {
            **self.stats,
            "rejections_by_field": dict(self.fields.most_common()),
            "rejection_reasons": dict(self.reasons.most_common()),
            "documented_nan_figures": dict(self.nan_figures.most_common()),
            "swept_sets": self.swept_sets,
            "timing_s": {k: round(v, 2) for k, v in self.timing.items()},
            "failures": self.failures,
        }


def fuzz_mechanism(impl: Mechanism, sets: int, cad: int, seed: int, log) -> dict:
    """``sets`` random sets of one mechanism through validation and calc; the first ``cad``
    accepted ones through the CAD build, meshing and the sweep."""
    base = load_template(TEMPLATE_DIR / str(impl.template)).data
    run = _Run(impl, log)
    for i in range(sets):
        set_seed = seed + impl.fuzz_seed_base + i
        data = copy.deepcopy(base)
        impl.sample(data, RandomDraw(set_seed))
        params = run.validated(set_seed, data)
        if params is None:
            continue
        run.stats["accepted"] += 1
        if run.calc_ok(set_seed, data, params) and run.stats["cad_built"] < cad:
            run.cad_and_sweep(set_seed, data, params, cad)
    return run.summary()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=1200, help="random sets per mechanism (default 1200)")
    parser.add_argument("--cad", type=int, default=35, help="accepted sets built per mechanism (default 35)")
    parser.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "fuzz.json")
    parser.add_argument("--only", choices=names(), action="append", help="fuzz only these mechanisms")
    args = parser.parse_args(argv)

    def log(text: str) -> None:
        print(text, flush=True)

    t_start = time.perf_counter()
    results = {}
    for mech in names():
        impl = get(mech)
        if (args.only and mech not in args.only) or impl.template is None or type(impl).sample is Mechanism.sample:
            continue  # no template, or no sampler (an assembly's designs are the user's own files)
        log(f"{mech}: {args.sets} sets, CAD for the first {args.cad} accepted ...")
        t0 = time.perf_counter()
        results[mech] = fuzz_mechanism(impl, args.sets, args.cad, args.seed, log)
        results[mech]["elapsed_s"] = round(time.perf_counter() - t0, 1)
    elapsed = time.perf_counter() - t_start

    totals = {k: sum(r[k] for r in results.values())
              for k in ("tried", "accepted", "rejected", "calc_ok", "cad_built", "cad_ok", "swept",
                        "rejected_after_meshing")}
    failures = [f for r in results.values() for f in r["failures"]]
    print()
    print(f"{'mechanism':<14}{'tried':>7}{'accepted':>10}{'rejected':>10}{'calc ok':>9}{'CAD ok':>9}"
          f"{'swept':>7}{'mesh rej':>9}{'failed':>8}{'time s':>8}")
    for mech, r in [*results.items(), ("total", {**totals, "failures": failures, "elapsed_s": round(elapsed, 1)})]:
        print(f"{mech:<14}{r['tried']:>7}{r['accepted']:>10}{r['rejected']:>10}{r['calc_ok']:>9}"
              f"{r['cad_ok']:>5}/{r['cad_built']:<3}{r['swept']:>7}{r['rejected_after_meshing']:>9}"
              f"{len(r['failures']):>8}{r['elapsed_s']:>8}")
    for mech, r in results.items():
        print(f"\n{mech}: rejection reasons (top 12 of {len(r['rejection_reasons'])})")
        for reason, n in list(r["rejection_reasons"].items())[:12]:
            print(f"  {n:>5}  {reason}")

    report = {
        "gearcheck_version": __version__,
        "python": platform.python_version(),
        "settings": {"sets_per_mechanism": args.sets, "cad_per_mechanism": args.cad, "first_seed": args.seed,
                     "seed_bases": {m: get(m).fuzz_seed_base for m in results}, "mesh_tol_mm": MESH_TOL_MM},
        "elapsed_s": round(elapsed, 1),
        "totals": {**totals, "failures": len(failures)},
        "mechanisms": results,
    }
    ensure_out_dir(args.out.parent)
    atomic_write_text(args.out, json.dumps(report, indent=2, default=str) + "\n")
    print(f"\nwrote {args.out} ({elapsed:.0f} s){': FAILURES' if failures else ''}")
    return 1 if failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
