"""Benchmarks (`make bench`): figures go to a JSON file, medians of repeated runs.

Speed targets live here, never in timed tests. Each entry: median seconds, the runs, and what
was measured.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from typing import Any
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from gearcheck import __version__, pipeline  # noqa: E402
from gearcheck.design import load_template  # noqa: E402
from gearcheck.executor import available_cores  # noqa: E402
from gearcheck.output import atomic_write_text, ensure_out_dir  # noqa: E402

from study import bench_study  # noqa: E402  (bench/study.py, beside this file)

TEMPLATES = sorted((ROOT / "templates").glob("*.toml"))


def median_time(fn, repeat: int) -> dict:
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t0)
    return {"median_s": statistics.median(runs), "runs_s": runs}


def bench_calc(repeat: int) -> dict:
    out = {}
    for path in TEMPLATES:
        design = load_template(path)
        out[path.stem] = median_time(design.calc, repeat)
    return out


def bench_build(repeat: int) -> dict:
    """CAD build time per template (assembly as data → solids, no meshing, no files; median of
    ``repeat``), cadquery imported once beforehand."""
    import gearcheck.cad.export  # noqa: F401  (the CAD kernel's import cost kept out of the figures)

    out = {}
    for path in TEMPLATES:
        design = load_template(path)
        out[path.stem] = median_time(lambda d=design: pipeline.build_parts(d), repeat)
    return out


def bench_sweeps(repeat: int) -> dict:
    """Each mechanism's sweep on its default meshes (the tolerance `check` uses), through the
    pipeline on 1 worker and on every core, side by side: wall time (median), the speed-up, and
    the speed figures the check reports (poses/s, ms per play measurement...) from the median
    run on every core."""
    import tempfile

    out = {}
    cores = available_cores()
    for path in TEMPLATES:
        design = load_template(path)
        with tempfile.TemporaryDirectory() as tmp:
            run = pipeline.build(design, Path(tmp))
        entry: dict = {"mesh_tol_mm": run.tol_mm}
        for label, jobs in (("jobs_1", 1), (f"jobs_{cores}", cores)):
            runs = []
            for _ in range(repeat):
                t0 = time.perf_counter()
                result = pipeline.sweep(design, run.assembly, run.bodies, jobs=jobs)
                runs.append((time.perf_counter() - t0, result.timings))
            runs.sort(key=lambda r: r[0])
            wall, timings = runs[len(runs) // 2]
            entry[label] = {"median_s": wall, "runs_s": [r[0] for r in runs], "figures_of_median_run": timings}
        entry["median_s"] = entry[f"jobs_{cores}"]["median_s"]
        entry["speedup_all_cores_over_1"] = entry["jobs_1"]["median_s"] / entry["median_s"]
        out[path.stem] = entry
    return out


def bench_command_all(command: str, repeat: int) -> dict:
    """`gearcheck COMMAND --all` wall time in a fresh process (includes import cadquery)."""
    import subprocess
    import tempfile

    def run():
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run([sys.executable, "-m", "gearcheck", command, "--all", "--out", tmp],
                           cwd=ROOT, check=True, capture_output=True)

    return median_time(run, repeat)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "bench.json")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--repeat-sweep", type=int, default=3, help="runs of each sweep and of check --all")
    args = ap.parse_args()
    ensure_out_dir(args.out.parent)
    result: dict[str, Any] = {
        "gearcheck_version": __version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
        "cpus": available_cores(),
        "calc": bench_calc(args.repeat),
        "build": bench_build(3),
        "build_all_wall": bench_command_all("build", 3),
        "sweep": bench_sweeps(args.repeat_sweep),
        "check_all_wall": bench_command_all("check", args.repeat_sweep),
        "study": bench_study(),
    }
    atomic_write_text(args.out, json.dumps(result, indent=2) + "\n")
    for group in ("calc", "build"):
        for name, fig in result[group].items():
            print(f"{group:5s} {name:28s} median {fig['median_s'] * 1e3:8.1f} ms")
    print(f"build --all (fresh process)         median {result['build_all_wall']['median_s']:8.2f} s")
    for name, fig in result["sweep"].items():
        speedup = fig["speedup_all_cores_over_1"]
        print(f"sweep {name:28s} median {fig['median_s']:8.2f} s  ({speedup:.2f}x over 1 worker)")
    print(f"check --all (fresh process)         median {result['check_all_wall']['median_s']:8.2f} s")
    st = result["study"]
    for name, fig in st["analytical_batch"].items():
        print(f"study {name}: analytical, {fig['variants']} variants in {fig['seconds']:.2f} s on one core")
    for name, fig in st["exact_level"].items():
        print(f"study {name}: {fig['level']} level {fig['variants_per_s_per_core']:.2f} variants/s per core")
    d = st["dask_vs_local"]
    print(f"study {d['study']}: Dask LocalCluster {d['dask_s']:.1f} s vs local {d['local_s']:.1f} s "
          f"({d['workers']} workers), rows identical: {d['rows_identical']}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
