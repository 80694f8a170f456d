"""Benchmarks (`make bench`): the baseline commit and the current code measured side by side.

The baseline is checked out into a temporary git worktree (removed at the end, also on error);
every measurement runs in a fresh process with the same Python and ``PYTHONPATH`` set to one
side's ``src``, so ``import gearcheck`` resolves to that side (checked: each probe reports the
file it imported, and the run stops if a side's import comes from anywhere else). Baseline and
current runs alternate (B, C, B, C, ...) so that the load of a shared machine falls on both
alike; each figure is the median of ``--repeat`` runs, and every run's raw times are kept.

Figures: ``check --all`` and ``build --all`` wall time in a fresh process, with the CAD built
(an empty CAD cache) and, on the current side, with the CAD from its cache (filled by one untimed
``build --all`` first; the baseline has no cache, so a re-run is held to its one run); the steering
template's analytical model (first call and warm median); each mechanism's sweep on 1 worker and
on every core (built and meshed once per probe, untimed); the differential's play measurements
and collide calls, and its rate as "poses/s equivalent" (the collide calls the baseline's method
makes for each side's contacts, over that side's time on the meshes per worker — the rate the
baseline reports — and, beside it, over the sweep's whole wall time: the same evidence per unit
time, however many FCL queries the current code needs for it); steering poses/s and track
sprocket poses/s over the sweep's wall time; the worker pool's speed-up from 1 to 2 workers (and
to every core). Written to ``--out`` with the ratios (current / baseline) and each target's met
flag; the study section (bench/study.py) and the assembly section (bench/assembly.py: an assembly's
sweep against the native mechanism's on the same poses, a 10⁶-triangle file) measure the current
code only; the certify section (bench/certify.py) sets the templates' sweeps beside the commit
before they were certified over the continuous motion.

Speed targets live here, never in timed tests.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import platform
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

# The baseline's method: per mesh contact (one pair, one way) the centred pose, the bracket's two
# ends and 12 halvings of a 0.35′ bracket to 1e-4′: 15 collide calls. The current code sweeps
# more thermal states (more contacts); its work is counted as what the baseline would have made.
BASELINE_CALLS_PER_CONTACT = 15

ROOT = Path(__file__).resolve().parents[1]
BENCH = Path(__file__).resolve().parent
BASELINE_COMMIT = "94ef928"
PROBE = BENCH / "probe.py"
# The template each mechanism's figures come from (the same stem at both commits).
TEMPLATES = {"differential": "zhurong_differential", "steering": "nose_wheel_steering", "track": "eod_track_drive"}
CALC_REPEAT = 5  # warm calls of the analytical model per probe
RUN_TIMEOUT_S = 1800.0


def log(message: str) -> None:
    print(f"[bench {time.strftime('%H:%M:%S')}] {message}", file=sys.stderr, flush=True)


def cores() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def median(values: list[float | None]) -> float | None:
    present = [v for v in values if v is not None]
    return statistics.median(present) if present else None


def ratio(current: float | None, baseline: float | None) -> float | None:
    if current is None or baseline is None or baseline == 0:
        return None
    return current / baseline


# ------------------------------------------------------------------------------------------
# The two sides


@dataclass
class Side:
    """One side of the comparison: a source tree, run with ``PYTHONPATH`` = its ``src``."""

    label: str  # "baseline" | "current"
    root: Path
    commit: str
    dirty: bool = False
    changed: list[str] = field(default_factory=list)
    gearcheck_file: str | None = None

    @property
    def src(self) -> Path:
        return self.root / "src"

    @property
    def env(self) -> dict[str, str]:
        env = dict(os.environ)
        env["PYTHONPATH"] = str(self.src)
        env.pop("PYTHONHOME", None)
        env["GEARCHECK_CACHE"] = "off"  # probes build untimed; run_command_all names a cache of its own
        return env

    def template(self, mechanism: str) -> Path:
        return self.root / "templates" / f"{TEMPLATES[mechanism]}.toml"

    def imported_here(self, path: str | None) -> bool:
        return path is not None and Path(path).resolve().is_relative_to(self.src.resolve())


def git(*args: str, cwd: Path = ROOT) -> str:
    return subprocess.run(["git", "-C", str(cwd), *args], check=True, capture_output=True, text=True).stdout.strip()


def current_side() -> Side:
    sha = git("rev-parse", "HEAD")
    changed = [line[3:] for line in git("status", "--porcelain").splitlines()
               if line[3:] and not line[3:].startswith("out/")]
    return Side("current", ROOT, sha, dirty=bool(changed), changed=changed[:100])


@contextlib.contextmanager
def baseline_worktree(commit: str) -> Iterator[Side]:
    """A detached worktree of ``commit`` in a temporary folder, removed (and pruned) on the way
    out, also on error or SIGTERM."""
    holder = Path(tempfile.mkdtemp(prefix="gearcheck-baseline-"))
    tree = holder / "tree"
    previous = signal.getsignal(signal.SIGTERM)
    signal.signal(signal.SIGTERM, lambda _signum, _frame: sys.exit(143))  # run the cleanup below
    try:
        git("worktree", "add", "--detach", str(tree), commit)
        yield Side("baseline", tree, git("rev-parse", "HEAD", cwd=tree))
    finally:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False,
                       capture_output=True)
        subprocess.run(["git", "-C", str(ROOT), "worktree", "prune"], check=False, capture_output=True)
        shutil.rmtree(holder, ignore_errors=True)
        signal.signal(signal.SIGTERM, previous)


def verify_and_warm(side: Side) -> None:
    """Import gearcheck (and the CAD kernel, warming the file cache) the way every run of this
    side does; stop if the import resolves outside the side's ``src`` (an installed copy winning)."""
    code = "import gearcheck, cadquery; print(gearcheck.__file__)"
    out = subprocess.run([sys.executable, "-c", code], check=False, cwd=side.root, env=side.env,
                         capture_output=True, text=True, timeout=RUN_TIMEOUT_S)
    path = out.stdout.strip().splitlines()[-1] if out.stdout.strip() else None
    if out.returncode != 0 or not side.imported_here(path):
        raise SystemExit(f"bench: the {side.label} side imports gearcheck from {path!r}, not {side.src} "
                         f"(exit {out.returncode}): {out.stderr.strip()[-800:]}")
    side.gearcheck_file = path


# ------------------------------------------------------------------------------------------
# Measurements (each in a fresh process)


def run_probe(side: Side, args: list[str]) -> dict:
    """``probe.py ARGS`` on ``side``: its JSON line (``ok`` False with the error when it failed)."""
    t0 = time.perf_counter()
    try:
        out = subprocess.run([sys.executable, str(PROBE), *args], check=False, cwd=side.root, env=side.env,
                             capture_output=True, text=True, timeout=RUN_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return {"ok": False, "error": f"timed out after {RUN_TIMEOUT_S:.0f} s"}
    lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
    try:
        result = json.loads(lines[-1])
    except (IndexError, json.JSONDecodeError):
        result = {"ok": False, "error": f"no result (exit {out.returncode}): {out.stderr.strip()[-800:]}"}
    if result.get("ok") and not side.imported_here(result.get("gearcheck_file")):
        raise SystemExit(f"bench: a {side.label} probe imported {result.get('gearcheck_file')}, not {side.src}")
    if not result.get("ok"):
        result.setdefault("stderr_tail", out.stderr.strip()[-800:])
    result["process_s"] = time.perf_counter() - t0
    return result


def run_command_all(side: Side, command: str, cache: Path | None = None) -> dict:
    """``python -m gearcheck COMMAND --all --out TMP`` from the side's root: wall time, exit code.
    The CAD cache (``GEARCHECK_CACHE``; the baseline has none and ignores it) is ``cache``, or, by
    default, an empty folder of this run's own: the CAD is built as on a first run."""
    with tempfile.TemporaryDirectory(prefix=f"gearcheck-bench-{command}-") as tmp, \
            tempfile.TemporaryDirectory(prefix="gearcheck-bench-cad-cache-") as empty:
        env = {**side.env, "GEARCHECK_CACHE": str(cache if cache is not None else empty)}
        t0 = time.perf_counter()
        try:
            out = subprocess.run([sys.executable, "-m", "gearcheck", command, "--all", "--out", tmp],
                                 check=False, cwd=side.root, env=env, capture_output=True, text=True,
                                 timeout=RUN_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            return {"wall_s": None, "returncode": None, "ok": False, "error": "timed out"}
        wall = time.perf_counter() - t0
    result: dict[str, Any] = {"wall_s": wall, "returncode": out.returncode, "ok": out.returncode == 0}
    if out.returncode != 0:
        lines = out.stderr.strip().splitlines()
        result["error"] = f"exit {out.returncode}: {lines[-1] if lines else ''}"
        result["stderr_tail"] = out.stderr.strip()[-800:]
    return result


@dataclass
class Step:
    """One measurement to take on both sides, ``repeat`` times, alternating sides."""

    key: str
    describe: str
    measure: Callable[[Side], dict]
    sides: tuple[str, ...] = ("baseline", "current")  # the sides it is measured on


def alternate(sides: list[Side], steps: list[Step], repeat: int, raw: dict[str, dict[str, list]]) -> None:
    """``repeat`` rounds of every step, each step on the baseline then on the current code: the
    runs of one figure are spread over the whole benchmark, and each baseline run sits right
    beside its current run, so bursts of load on a shared machine fall on both sides alike."""
    total, n = sum(len([s for s in sides if s.label in step.sides]) for step in steps) * repeat, 0
    for r in range(repeat):
        for step in steps:
            for side in (s for s in sides if s.label in step.sides):
                n += 1
                log(f"{n}/{total} round {r + 1}/{repeat} {side.label:8s} {step.describe} ...")
                t0, load = time.perf_counter(), os.getloadavg()[0]
                result = step.measure(side)
                result.setdefault("run", r + 1)
                result["loadavg_1m_before"] = load
                raw[side.label].setdefault(step.key, []).append(result)
                status = "ok" if result.get("ok", True) else f"FAILED: {result.get('error', '')}"
                log(f"{n}/{total} round {r + 1}/{repeat} {side.label:8s} {step.describe}: "
                    f"{time.perf_counter() - t0:.1f} s {status}")


def sweep_probe(mech: str, jobs: str) -> Callable[[Side], dict]:
    return lambda side: run_probe(side, ["sweep", str(side.template(mech)), "--jobs", jobs])


def steps_for(jobs_all: list[int], cad_cache: Path) -> list[Step]:
    """The steps; ``cad_cache``: the current side's CAD cache for its re-runs (filled first)."""
    jobs = ",".join(str(j) for j in jobs_all)
    steps = [Step("steering_calc", "calc steering",
                  lambda s: run_probe(s, ["calc", str(s.template("steering")), "--repeat", str(CALC_REPEAT)]))]
    steps += [Step("build_all", "build --all", lambda s: run_command_all(s, "build")),
              Step("build_all_cached", "build --all, CAD from the cache",
                   lambda s: run_command_all(s, "build", cad_cache), ("current",))]
    for mech in TEMPLATES:
        steps.append(Step(f"sweep_{mech}", f"sweep {mech} (jobs {jobs})", sweep_probe(mech, jobs)))
    steps += [Step("check_all", "check --all", lambda s: run_command_all(s, "check")),
              Step("check_all_cached", "check --all, CAD from the cache",
                   lambda s: run_command_all(s, "check", cad_cache), ("current",))]
    return steps


# ------------------------------------------------------------------------------------------
# Figures from the raw runs


def _ok(runs: list[dict]) -> list[dict]:
    return [r for r in runs if r.get("ok", True)]


def _timing(run: dict, key: str) -> float | None:
    value = run.get("timings", {}).get(key)
    return float(value) if isinstance(value, (int, float)) else None


def sweep_figures(runs: list[dict], jobs_all: list[int]) -> dict[str, Any]:
    """Per worker count: median wall time, the work count, the per-second rate over the wall
    time, and the median of every scalar figure in the sweep's own timings."""
    out: dict[str, Any] = {}
    good = _ok(runs)
    for jobs in jobs_all:
        per = [r["runs"][f"jobs_{jobs}"] for r in good if f"jobs_{jobs}" in r.get("runs", {})]
        walls = [p["wall_s"] for p in per]
        counts = [p["count"] for p in per if p.get("count") is not None]
        keys = sorted({k for p in per for k, v in p["timings"].items() if isinstance(v, (int, float))})
        wall = median(walls)
        count = median(counts)
        out[f"jobs_{jobs}"] = {
            "median_s": wall, "runs_s": walls, "unit": per[0].get("unit") if per else None, "count": count,
            "per_s_over_wall": count / wall if count is not None and wall else None,
            "cpu_s": median([p.get("cpu_s") for p in per]),
            # CPU seconds (this process and the pool's workers) per wall second: the cores kept busy
            "cores_busy": median([p["cpu_s"] / p["wall_s"] for p in per if p.get("cpu_s") and p["wall_s"]]),
            "timings_median": {k: median([_timing(p, k) for p in per]) for k in keys},
        }
    out["default_jobs"] = good[0].get("default_jobs") if good else None
    out["build_s_runs"] = [r.get("build_s") for r in good]
    out["failed_runs"] = [r.get("error") for r in runs if not r.get("ok", True)]
    return out


def side_figures(raw: dict[str, list], jobs_all: list[int], n_cores: int) -> dict[str, Any]:
    """The flat figures of one side (None where its runs failed)."""
    fig: dict[str, Any] = {}
    for key in ("check_all", "build_all", "check_all_cached", "build_all_cached"):
        good = _ok(raw.get(key, []))
        fig[f"{key}_s"] = median([r["wall_s"] for r in good])
    calc = _ok(raw.get("steering_calc", []))
    fig["steering_calc_s"] = median([t for r in calc for t in r["warm_runs_s"]])
    fig["steering_calc_first_s"] = median([r["first_s"] for r in calc])
    top = f"jobs_{jobs_all[-1]}"
    sweeps = {m: sweep_figures(raw.get(f"sweep_{m}", []), jobs_all) for m in TEMPLATES}
    for mech, sw in sweeps.items():
        one, every = sw["jobs_1"], sw[top]
        fig[f"{mech}_sweep_s"] = every["median_s"]
        fig[f"{mech}_sweep_jobs_1_s"] = one["median_s"]
        fig[f"{mech}_work"] = every["count"]
        fig[f"{mech}_work_unit"] = every["unit"]
        fig[f"{mech}_speedup_1_to_{n_cores}"] = ratio(one["median_s"], every["median_s"])
        if "jobs_2" in sw:
            fig[f"{mech}_speedup_1_to_2"] = ratio(one["median_s"], sw["jobs_2"]["median_s"])
        fig[f"{mech}_workers_reported"] = every["timings_median"].get("workers")
        fig[f"{mech}_default_jobs"] = sw["default_jobs"]
        fig[f"{mech}_cores_busy"] = every["cores_busy"]
    diff = sweeps["differential"][top]["timings_median"]
    fig["differential_ms_per_play_measurement"] = diff.get("ms_per_play_measurement")
    fig["differential_ms_per_play_measurement_max"] = diff.get("ms_per_play_measurement_max")
    fig["differential_collide_calls"] = diff.get("collide_calls")  # the baseline's name
    fig["differential_fcl_queries"] = diff.get("fcl_queries", diff.get("collide_calls"))
    fig["differential_contacts"] = diff.get("contacts")  # mesh contacts (one pair, one way); current code
    per_worker = diff.get("fcl_queries_per_s_per_worker", diff.get("collide_calls_per_s_per_worker"))
    queries, workers = fig["differential_fcl_queries"], diff.get("workers")
    # the time spent on the meshes, per worker (what the baseline's own calls/s figure is taken over)
    fig["differential_mesh_s_per_worker"] = (queries / per_worker / workers
                                             if queries and per_worker and workers else None)
    fig["steering_poses_per_s"] = sweeps["steering"][top]["per_s_over_wall"]
    fig["steering_poses_per_s_own_timing"] = sweeps["steering"][top]["timings_median"].get("poses_per_s")
    fig["track_sprocket_poses_per_s"] = sweeps["track"][top]["per_s_over_wall"]
    fig["track_sprocket_poses_per_s_own_timing"] = sweeps["track"][top]["timings_median"].get("poses_per_s")
    fig["sweeps"] = sweeps
    return fig


def _le(value: float | None, bound: float) -> bool:
    return value is not None and value <= bound


def _ge(value: float | None, bound: float) -> bool:
    return value is not None and value >= bound


def compare(base: dict[str, Any], cur: dict[str, Any], n_cores: int) -> tuple[dict[str, Any], list[dict]]:
    """Ratios (current / baseline) of every numeric figure both sides have, and the targets."""
    # The same evidence per unit time: the collide calls the baseline's method makes for each side's
    # contacts (BASELINE_CALLS_PER_CONTACT per contact; the baseline's own count as it is), over
    # each side's time on the meshes per worker (the rate the baseline reports as collide calls/s
    # on its workers), and over each side's whole sweep wall time (pool start, BVHs, exact range).
    for fig in (base, cur):
        contacts = fig.get("differential_contacts")
        calls = (BASELINE_CALLS_PER_CONTACT * contacts if contacts else fig.get("differential_collide_calls"))
        wall, mesh = fig.get("differential_sweep_s"), fig.get("differential_mesh_s_per_worker")
        fig["differential_baseline_calls_equivalent"] = calls
        fig["differential_poses_per_s_equivalent"] = calls / mesh if calls and mesh else None
        fig["differential_poses_per_s_equivalent_over_wall"] = calls / wall if calls and wall else None
    ratios = {k: ratio(cur.get(k), v) for k, v in base.items()
              if isinstance(v, (int, float)) and not isinstance(v, bool) and isinstance(cur.get(k), (int, float))}

    def row(figure: str, key: str, target: str, met: bool, unit: str, base_key: str | None = None,
            **extra: Any) -> dict:
        """``base_key``: the baseline figure to compare with, where it has none of this key."""
        return {"figure": figure, "key": key, "unit": unit, "baseline": base.get(base_key or key),
                "current": cur.get(key), "ratio": ratio(cur.get(key), base.get(base_key or key)) if base_key
                else ratios.get(key), "target": target, "met": bool(met), **extra}

    # a re-run with the CAD from the cache, against the baseline's run (it has no cache)
    recheck = ratio(cur.get("check_all_cached_s"), base.get("check_all_s"))

    pool_key = "differential_speedup_1_to_2"
    every_core = (cur.get("differential_default_jobs") == n_cores
                  and cur.get("differential_workers_reported") in (None, n_cores))
    targets = [
        row("check --all, fresh process", "check_all_s", "≤ 1/3 of baseline", _le(ratios.get("check_all_s"), 1 / 3),
            "s"),
        row("differential: one play measurement", "differential_ms_per_play_measurement", "≤ 10 ms",
            _le(cur.get("differential_ms_per_play_measurement"), 10.0), "ms",
            max_ms=cur.get("differential_ms_per_play_measurement_max")),
        row("differential sweep, poses/s equivalent", "differential_poses_per_s_equivalent", "≥ 5000 poses/s",
            _ge(cur.get("differential_poses_per_s_equivalent"), 5000.0), "poses/s"),
        row("steering sweep, poses/s", "steering_poses_per_s", "≥ 3× baseline",
            _ge(ratios.get("steering_poses_per_s"), 3.0), "poses/s"),
        row("steering calc (towing analysis), warm", "steering_calc_s", "≤ 0.2 s",
            _le(cur.get("steering_calc_s"), 0.2), "s", first_call_s=cur.get("steering_calc_first_s")),
        row("track sweep, sprocket poses/s", "track_sprocket_poses_per_s", "≥ 3× baseline",
            _ge(ratios.get("track_sprocket_poses_per_s"), 3.0), "poses/s"),
        row("check --all, fresh process, CAD from the cache", "check_all_cached_s", "≤ 1/3 of baseline",
            _le(recheck, 1 / 3), "s", base_key="check_all_s"),
        row("build --all, fresh process", "build_all_s", "≤ 6 s", _le(cur.get("build_all_s"), 6.0), "s"),
        row("build --all, fresh process, CAD from the cache", "build_all_cached_s", "≤ 6 s",
            _le(cur.get("build_all_cached_s"), 6.0), "s", base_key="build_all_s"),
        row("worker pool: differential sweep 1 → 2 workers", pool_key if pool_key in cur else
            f"differential_speedup_1_to_{n_cores}", "every core used, ≥ 1.8×",
            every_core and _ge(cur.get(pool_key, cur.get(f"differential_speedup_1_to_{n_cores}")), 1.8), "×",
            every_core_used=every_core, cores=n_cores, default_jobs=cur.get("differential_default_jobs"),
            cores_busy={m: cur.get(f"{m}_cores_busy") for m in TEMPLATES},
            speedups_1_to_2={m: cur.get(f"{m}_speedup_1_to_2") for m in TEMPLATES},
            speedups_1_to_every_core={m: cur.get(f"{m}_speedup_1_to_{n_cores}") for m in TEMPLATES}),
    ]
    return ratios, targets


# ------------------------------------------------------------------------------------------
# Output


def machine() -> dict[str, Any]:
    model = None
    with contextlib.suppress(OSError):
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    return {"python": platform.python_version(), "platform": platform.platform(), "machine": platform.machine(),
            "cpu": model, "cores": cores(), "loadavg_start": list(os.getloadavg())}


def write_json(path: Path, data: dict) -> None:
    """Atomically (a temporary file beside it, then a rename)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        fh.write(json.dumps(data, indent=2, allow_nan=False) + "\n")
    os.replace(tmp, path)


def _num(value: Any, unit: str = "") -> str:
    if value is None:
        return "—"
    text = str(value)
    if isinstance(value, float):
        text = f"{value:.3g}" if abs(value) < 100 else f"{value:.0f}"
    return f"{text} {unit}".rstrip()


def table(targets: list[dict], cur: dict[str, Any], base: dict[str, Any], n_cores: int) -> str:
    head = ("figure", "baseline", "current", "ratio", "target", "met")
    rows = [head] + [(t["figure"], _num(t["baseline"], t["unit"]), _num(t["current"], t["unit"]),
                      _num(t["ratio"]) if t["ratio"] is not None else "—", t["target"], "yes" if t["met"] else "NO")
                     for t in targets]
    for mech in TEMPLATES:
        for n in dict.fromkeys((2, n_cores)):
            key = f"{mech}_speedup_1_to_{n}"
            if key in cur:
                rows.append((f"{mech} sweep, 1 → {n} workers", _num(base.get(key), "×"), _num(cur.get(key), "×"),
                             _num(ratio(cur.get(key), base.get(key))), "(reported)", ""))
    for mech in TEMPLATES:
        rows.append((f"{mech} sweep, wall ({n_cores} workers)", _num(base.get(f"{mech}_sweep_s"), "s"),
                     _num(cur.get(f"{mech}_sweep_s"), "s"), _num(ratio(cur.get(f"{mech}_sweep_s"),
                                                                       base.get(f"{mech}_sweep_s"))), "(reported)", ""))
    widths = [max(len(r[i]) for r in rows) for i in range(len(head))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _section(module: str, function: str, label: str) -> dict[str, Any]:
    """``bench/MODULE.py``'s FUNCTION on the current code, in this process; an error is recorded,
    never a reason to lose the side-by-side figures."""
    sys.path[:0] = [str(ROOT / "src"), str(BENCH)]
    try:
        import importlib

        return getattr(importlib.import_module(module), function)()
    except Exception as exc:
        log(f"{label} section failed: {type(exc).__name__}: {exc}")
        return {"error": f"{type(exc).__name__}: {exc}"}


def study_section() -> dict[str, Any]:
    """bench/study.py on the current code."""
    return _section("study", "bench_study", "study")


def assembly_section() -> dict[str, Any]:
    """bench/assembly.py on the current code: an assembly's sweep against the native mechanism's on
    the same poses, and a 10⁶-triangle file's time and peak memory."""
    return _section("assembly", "bench_assembly", "assembly")


def certify_section() -> dict[str, Any]:
    """bench/certify.py: the three templates' sweeps on one worker, the commit before the certified
    sweeps against the current code, side by side (CPU seconds)."""
    return _section("certify", "bench_certify", "certify")


def tca_section() -> dict[str, Any]:
    """bench/tca.py on the current code: the tooth contact analysis's CPU seconds against its budget."""
    return _section("tca", "bench_tca", "tca")


def _sections(result: dict[str, Any], args: argparse.Namespace) -> None:
    """The sections beside the side-by-side figures (each written out as soon as it is done)."""
    if not (args.quick or args.skip_study):
        log("study section (current code) ...")
        result["study"] = study_section()
    if not args.quick:
        log("tca section (current code) ...")
        result["tca"] = tca_section()
        write_json(args.out, result)
        log("assembly section (current code) ...")
        result["assembly"] = assembly_section()
        write_json(args.out, result)
        log("certify section (the commit before the certified sweeps against the current code) ...")
        result["certify"] = certify_section()
        write_json(args.out, result)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "bench.json")
    ap.add_argument("--repeat", type=int, default=3, help="runs of every figure on each side (default 3)")
    ap.add_argument("--baseline", default=BASELINE_COMMIT, help=f"baseline commit (default {BASELINE_COMMIT})")
    ap.add_argument("--quick", action="store_true", help="one run of each figure, no study section (harness trials)")
    ap.add_argument("--skip-study", action="store_true", help="leave out the study section")
    args = ap.parse_args(argv)
    repeat = 1 if args.quick else max(1, args.repeat)
    n_cores = cores()
    jobs_all = sorted({1, 2, n_cores}) if n_cores >= 2 else [1]
    t_start = time.perf_counter()
    started = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    current = current_side()
    result: dict[str, Any] = {"machine": machine(), "started_utc": started, "repeat": repeat, "jobs": jobs_all}
    raw: dict[str, dict[str, list]] = {"baseline": {}, "current": {}}
    with baseline_worktree(args.baseline) as baseline:
        sides = [baseline, current]
        for side in sides:
            log(f"{side.label}: {side.commit[:12]}{' (dirty)' if side.dirty else ''} from {side.root}; "
                f"checking its import and warming the file cache")
            verify_and_warm(side)
        with tempfile.TemporaryDirectory(prefix="gearcheck-bench-cad-cache-") as cad_cache:
            log("filling the current side's CAD cache (build --all, untimed) ...")
            filled = run_command_all(current, "build", Path(cad_cache))
            if not filled["ok"]:
                raise SystemExit(f"bench: build --all to fill the CAD cache failed: {filled.get('error')}")
            alternate(sides, steps_for(jobs_all, Path(cad_cache)), repeat, raw)
    figures = {label: side_figures(raw[label], jobs_all, n_cores) for label in raw}
    base, cur = figures["baseline"], figures["current"]
    ratios, targets = compare(base, cur, n_cores)
    result["baseline"] = {"commit": args.baseline, "sha": baseline.commit, "gearcheck_file": baseline.gearcheck_file,
                          **base, "runs": raw["baseline"]}
    result["current"] = {"commit": current.commit, "dirty": current.dirty, "changed_files": current.changed,
                         "gearcheck_file": current.gearcheck_file, **cur, "runs": raw["current"]}
    result["ratios"] = ratios
    result["targets"] = targets
    result["side_by_side_s"] = time.perf_counter() - t_start
    write_json(args.out, result)
    _sections(result, args)
    result["machine"]["loadavg_end"] = list(os.getloadavg())
    result["total_s"] = time.perf_counter() - t_start
    write_json(args.out, result)
    print(table(targets, cur, base, n_cores))
    for name, fig in {**(result.get("assembly") or {}), **(result.get("certify") or {})}.items():
        if isinstance(fig, dict) and "target" in fig:
            print(f"{name.replace('_', ' ')}: {'met' if fig['met'] else 'NOT met'} ({fig['target']}): "
                  + ", ".join(f"{k} {v:.4g}" for k, v in fig.items() if isinstance(v, float)))
    met = sum(t["met"] for t in targets)
    print(f"\n{met}/{len(targets)} targets met; baseline {args.baseline}, current {current.commit[:12]}"
          f"{' (dirty)' if current.dirty else ''}; medians of {repeat} run(s) each, {n_cores} cores, "
          f"{result['total_s'] / 60:.1f} min")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
