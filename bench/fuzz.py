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

from gearcheck import __version__  # noqa: E402
from gearcheck.mechanisms import MECHANISMS, Loaded, load_template, mechanism_module  # noqa: E402
from gearcheck.mechanisms.sampling import NAN_FIGURES, RandomDraw, sample  # noqa: E402
from gearcheck.output import atomic_write_text, ensure_out_dir  # noqa: E402
from gearcheck.params import ParamError, validate  # noqa: E402

TEMPLATES = {
    "differential": ROOT / "templates" / "zhurong_differential.toml",
    "track": ROOT / "templates" / "eod_track_drive.toml",
    "steering": ROOT / "templates" / "nose_wheel_steering.toml",
}
MESH_TOL_MM = 0.02
# Seeds of mechanism k start at k·SEED_STRIDE (disjoint streams, reproducible one by one).
SEED_STRIDE = 1_000_000


# Verdicts that test the tool itself (mesh sweep vs an independent exact model), not the design:
# an accepted set may fail a design verdict (a mesh that binds cold), never one of these.
CONSISTENCY_VERDICTS = ("mesh_agrees_with_exact", "mesh_matches_exact", "towing_curve")
# The differential sweep at fuzz scale: 4 drive angles over the play period, the set's own shim.
FUZZ_DIFFERENTIAL_ANGLES = 4


def sweep_sample(loaded: Loaded, parts: list) -> dict | None:
    """The FCL sweep of one fuzzed, built set: mesh at the check's default tolerance, run the
    mechanism's check (the differential at reduced sampling), return its verdicts as numbers.

    Raises when a consistency verdict fails (mesh sweep disagrees with the exact model): that is
    a defect of gearcheck, whatever the design. Design verdicts are recorded, not failures."""
    import tempfile

    from gearcheck.cad.export import export_parts, sweep_bodies

    from gearcheck.sweep import resolution

    tol = loaded.module.MESH_TOL_MM  # the check's default, as `gearcheck check` meshes
    with tempfile.TemporaryDirectory() as tmp:
        _, exported = export_parts(parts, Path(tmp), name="fuzz", mechanism=loaded.mechanism,
                                   params_data=loaded.resolved_data, tol_mm=tol)
    bodies = sweep_bodies(exported)
    kwargs = {}
    if loaded.mechanism == "differential":
        kwargs = {"angles_per_cycle": FUZZ_DIFFERENTIAL_ANGLES, "shims_mm": [loaded.params.shim.thickness_mm]}
    result = loaded.check_module.run_check(loaded.params, bodies, **kwargs)
    resolution.enforce(result, bodies, tol, "fuzz")  # ParamError: rejected after meshing
    verdicts = {v.key: int(v.passed) for v in result.verdicts}
    broken = [k for k in CONSISTENCY_VERDICTS if verdicts.get(k) == 0]
    if broken:
        details = "; ".join(v.detail for v in result.verdicts if v.key in broken)
        raise AssertionError(f"mesh sweep disagrees with the exact model: {details}")
    return {"verdicts": verdicts, "verdict_pass": int(result.passed),
            "mesh_resolution": resolution.resolution_summary(result, bodies)}


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
    """What is wrong with a rejection message, or None."""
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


def check_figures(mech: str, figures) -> tuple[str | None, list[str]]:
    nan = []
    for f in figures:
        if math.isinf(f.value):
            return f"figure {f.key} is infinite", nan
        if math.isnan(f.value):
            if f.key not in NAN_FIGURES[mech]:
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


def fuzz_mechanism(mech: str, index: int, sets: int, cad: int, seed: int, log) -> dict:
    module = mechanism_module(mech)
    base = load_template(TEMPLATES[mech]).data
    stats = {"tried": 0, "accepted": 0, "rejected": 0, "calc_ok": 0, "cad_built": 0, "cad_ok": 0,
             "swept": 0, "rejected_after_meshing": 0}
    fields, reasons, nan_figures = collections.Counter(), collections.Counter(), collections.Counter()
    failures, swept_sets = [], []
    timing = {"validate_s": 0.0, "calc_s": 0.0, "cad_s": 0.0}
    parts_module = None

    def fail(stage: str, set_seed: int, data: dict, error: str) -> None:
        failures.append({"mechanism": mech, "seed": set_seed, "stage": stage, "error": error, "set": data})
        log(f"  FAIL {mech} seed {set_seed} [{stage}]: {error.splitlines()[-1] if error else ''}")

    for i in range(sets):
        set_seed = seed + index * SEED_STRIDE + i
        data = sample(base, RandomDraw(set_seed))
        body = {k: v for k, v in data.items() if k != "mechanism"}
        stats["tried"] += 1
        t0 = time.perf_counter()
        try:
            params = validate(module.Params, body, "fuzz")
        except ParamError as exc:
            timing["validate_s"] += time.perf_counter() - t0
            stats["rejected"] += 1
            fields[exc.field] += 1
            reasons[_reason(exc)] += 1
            problem = check_rejection(body, exc)
            if problem:
                fail("reject", set_seed, data, f"{problem}: {exc}")
            continue
        except Exception:
            timing["validate_s"] += time.perf_counter() - t0
            fail("validate", set_seed, data, traceback.format_exc())
            continue
        timing["validate_s"] += time.perf_counter() - t0
        stats["accepted"] += 1

        t0 = time.perf_counter()
        try:
            problem, nan = check_figures(mech, module.calc(params))
        except Exception:
            problem, nan = traceback.format_exc(), []
        timing["calc_s"] += time.perf_counter() - t0
        nan_figures.update(nan)
        if problem:
            fail("calc", set_seed, data, problem)
            continue
        stats["calc_ok"] += 1

        if stats["cad_built"] >= cad:
            continue
        if parts_module is None:
            parts_module = load_template(TEMPLATES[mech]).parts_module  # imports CadQuery once
        stats["cad_built"] += 1
        t0 = time.perf_counter()
        try:
            parts = parts_module.build_parts(params)
            problem, built = check_parts(parts)
        except Exception:
            problem, built = traceback.format_exc(), {}
        timing["cad_s"] += time.perf_counter() - t0
        if problem:
            fail("cad", set_seed, data, problem)
            continue
        stats["cad_ok"] += 1
        loaded = Loaded(path=Path(f"fuzz/{mech}-{set_seed}.toml"), mechanism=mech, params=params, data=data)
        try:
            result = sweep_sample(loaded, parts)
        except ParamError as exc:  # the mesh-resolution rule: a clear rejection, not a failure
            stats["rejected_after_meshing"] += 1
            problem = check_rejection({"--tol": 0}, exc, source="fuzz")
            if problem:
                fail("mesh-rule", set_seed, data, f"{problem}: {exc}")
            else:
                reasons[_reason(exc)] += 1
            continue
        except Exception:
            fail("sweep", set_seed, data, traceback.format_exc())
            continue
        stats["swept"] += 1
        if result is not None:
            swept_sets.append({"seed": set_seed, "build": built, "sweep": result})
        log(f"  {mech} CAD {stats['cad_built']}/{cad} seed {set_seed}: {built['parts']} parts, "
            f"{built['triangles']} triangles ({time.perf_counter() - t0:.1f} s)")

    return {
        **stats,
        "rejections_by_field": dict(fields.most_common()),
        "rejection_reasons": dict(reasons.most_common()),
        "documented_nan_figures": dict(nan_figures.most_common()),
        "swept_sets": swept_sets,
        "timing_s": {k: round(v, 2) for k, v in timing.items()},
        "failures": failures,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=1200, help="random sets per mechanism (default 1200)")
    parser.add_argument("--cad", type=int, default=35, help="accepted sets built per mechanism (default 35)")
    parser.add_argument("--seed", type=int, default=0, help="first seed (default 0)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "fuzz.json")
    parser.add_argument("--only", choices=sorted(MECHANISMS), action="append", help="fuzz only these mechanisms")
    args = parser.parse_args(argv)

    def log(text: str) -> None:
        print(text, flush=True)

    t_start = time.perf_counter()
    results = {}
    for index, mech in enumerate(TEMPLATES):
        if args.only and mech not in args.only:
            continue
        log(f"{mech}: {args.sets} sets, CAD for the first {args.cad} accepted ...")
        t0 = time.perf_counter()
        results[mech] = fuzz_mechanism(mech, index, args.sets, args.cad, args.seed, log)
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
                     "seed_stride": SEED_STRIDE, "mesh_tol_mm": MESH_TOL_MM},
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
