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
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from gearcheck import __version__  # noqa: E402
from gearcheck.mechanisms import load_template  # noqa: E402
from gearcheck.output import atomic_write_text, ensure_out_dir  # noqa: E402

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
        loaded = load_template(path)
        out[path.stem] = median_time(lambda: loaded.module.calc(loaded.params), repeat)
    return out


def bench_build(repeat: int) -> dict:
    """CAD build time per part kind (median of ``repeat``), cadquery imported once beforehand."""
    import cadquery  # noqa: F401  (import cost kept out of the figures)

    from gearcheck.cad.bevel import build_bevel_gear
    from gearcheck.cad.rack_pinion import build_pinion, build_rack
    from gearcheck.cad.sprocket import build_sprocket, sprocket_spec
    from gearcheck.mechanisms.differential.poses import gear_specs
    from gearcheck.mechanisms.steering.analysis import geometry_from_params

    diff = load_template(ROOT / "templates" / "zhurong_differential.toml").params
    track = load_template(ROOT / "templates" / "eod_track_drive.toml").params
    steer = load_template(ROOT / "templates" / "nose_wheel_steering.toml").params
    specs = gear_specs(diff)
    g = geometry_from_params(steer)
    spec = sprocket_spec(track)
    return {
        "bevel_gear_z33": median_time(lambda: build_bevel_gear(specs.big), repeat),
        "bevel_gear_z13": median_time(lambda: build_bevel_gear(specs.small), repeat),
        "sprocket_z49": median_time(lambda: build_sprocket(spec), repeat),
        "pinion_z42": median_time(lambda: build_pinion(g), repeat),
        "rack": median_time(lambda: build_rack(g), repeat),
    }


def bench_sweeps(repeat: int) -> dict:
    """Each mechanism's sweep on its default meshes (the tolerance `check` uses: differential
    0.003 mm, track 0.008, steering 0.01): wall time (median) and the speed figures the check
    reports (poses/s, ms per play measurement...) from the median run."""
    import tempfile

    from gearcheck.cad.export import export_parts, sweep_bodies

    out = {}
    for path in TEMPLATES:
        loaded = load_template(path)
        parts = loaded.parts_module.build_parts(loaded.params)
        with tempfile.TemporaryDirectory() as tmp:
            _, exported = export_parts(parts, Path(tmp), name=loaded.name, mechanism=loaded.mechanism,
                                       params_data=loaded.resolved_data, tol_mm=loaded.module.MESH_TOL_MM)
        bodies = sweep_bodies(exported)
        runs = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            result = loaded.check_module.run_check(loaded.params, bodies)
            runs.append((time.perf_counter() - t0, result.timings))
        runs.sort(key=lambda r: r[0])
        wall, timings = runs[len(runs) // 2]
        out[path.stem] = {"median_s": wall, "runs_s": [r[0] for r in runs], "mesh_tol_mm": loaded.module.MESH_TOL_MM,
                          "figures_of_median_run": timings}
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
    result = {
        "gearcheck_version": __version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
        "cpus": __import__("os").cpu_count(),
        "calc": bench_calc(args.repeat),
        "build": bench_build(3),
        "build_all_wall": bench_command_all("build", 3),
        "sweep": bench_sweeps(args.repeat_sweep),
        "check_all_wall": bench_command_all("check", args.repeat_sweep),
    }
    atomic_write_text(args.out, json.dumps(result, indent=2) + "\n")
    for group in ("calc", "build"):
        for name, fig in result[group].items():
            print(f"{group:5s} {name:28s} median {fig['median_s'] * 1e3:8.1f} ms")
    print(f"build --all (fresh process)         median {result['build_all_wall']['median_s']:8.2f} s")
    for name, fig in result["sweep"].items():
        print(f"sweep {name:28s} median {fig['median_s']:8.2f} s  {fig['figures_of_median_run']}")
    print(f"check --all (fresh process)         median {result['check_all_wall']['median_s']:8.2f} s")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
