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


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "bench.json")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    ensure_out_dir(args.out.parent)
    result = {
        "gearcheck_version": __version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
        "cpus": __import__("os").cpu_count(),
        "calc": bench_calc(args.repeat),
    }
    atomic_write_text(args.out, json.dumps(result, indent=2) + "\n")
    for name, fig in result["calc"].items():
        print(f"calc {name:28s} median {fig['median_s'] * 1e3:8.1f} ms")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
