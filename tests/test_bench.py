"""The bench harness's arithmetic on made-up probe results: medians over runs, the work each sweep
did recovered from its timings, ratios (current / baseline), the differential's poses/s
equivalent (the baseline's collide calls over each side's time on the meshes) and each target's met
flag. No timing is measured here: speed targets live only in `make bench`."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"


def _module(name: str):
    spec = importlib.util.spec_from_file_location(f"bench_{name}", BENCH / f"{name}.py")
    assert spec and spec.loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


run = _module("run")
probe = _module("probe")
JOBS = [1, 2]


def _sweep(mech: str, walls: dict[int, float], timings: dict, count: int, unit: str) -> dict:
    return {"ok": True, "mechanism": mech, "build_s": 1.0, "default_jobs": 2,
            "runs": {f"jobs_{j}": {"jobs": j, "wall_s": w, "cpu_s": w * j, "timings": timings, "count": count,
                                   "unit": unit} for j, w in walls.items()}}


def _side(scale: float) -> dict[str, list]:
    """Raw runs of one side; ``scale`` divides every time (scale 1: the baseline)."""
    # the baseline: 60 000 collide calls, 24 s on the meshes (12 s per worker); the current side
    # names its count FCL queries and makes a third of them, 4x faster in all
    if scale == 1:
        diff = {"collide_calls": 60_000, "collide_calls_per_s_per_worker": 2500.0}
    else:
        # the same 4000 contacts the baseline bisected in 15 calls each
        diff = {"fcl_queries": 20_000, "fcl_queries_per_s_per_worker": 20_000 / (24.0 / scale), "contacts": 4000}
    diff.update({"ms_per_play_measurement": 30.0 / scale, "ms_per_play_measurement_max": 45.0 / scale, "workers": 2})
    cached = {} if scale == 1 else {  # the current side's re-runs with the CAD from its cache
        "check_all_cached": [{"wall_s": 30.0 / scale, "ok": True}],
        "build_all_cached": [{"wall_s": 6.0 / scale, "ok": True}]}
    return cached | {
        "check_all": [{"wall_s": w / scale, "ok": True} for w in (46.0, 45.0, 48.0)],
        "build_all": [{"wall_s": w / scale, "ok": True} for w in (14.0, 15.0, 13.0)],
        "steering_calc": [{"ok": True, "first_s": 1.5 / scale, "warm_runs_s": [1.2 / scale, 1.4 / scale]}],
        "sweep_differential": [_sweep("differential", {1: 30.0 / scale, 2: 15.0 / scale}, diff,
                                      diff.get("collide_calls", diff.get("fcl_queries")), "collide calls")],
        "sweep_steering": [_sweep("steering", {1: 4.0 / scale, 2: 2.0 / scale}, {"poses_per_s": 1000.0}, 2000,
                                  "poses")],
        "sweep_track": [_sweep("track", {1: 2.0 / scale, 2: 1.0 / scale}, {"poses_per_s": 77.0}, 77, "sprocket poses")],
    }


def _compare(scale: float):
    base = run.side_figures(_side(1.0), JOBS, 2)
    cur = run.side_figures(_side(scale), JOBS, 2)
    ratios, targets = run.compare(base, cur, 2)
    return base, cur, ratios, {t["key"]: t for t in targets}


def test_figures_and_ratios():
    base, cur, ratios, _ = _compare(4.0)
    assert base["check_all_s"] == 46.0 and cur["check_all_s"] == 11.5
    assert ratios["check_all_s"] == pytest.approx(0.25)
    assert base["steering_calc_s"] == pytest.approx(1.3)  # warm calls pooled over the runs
    assert base["differential_sweep_s"] == 15.0 and base["differential_speedup_1_to_2"] == 2.0
    assert base["steering_poses_per_s"] == pytest.approx(1000.0)  # poses over the sweep's wall time
    assert cur["track_sprocket_poses_per_s"] == pytest.approx(308.0)
    assert ratios["track_sprocket_poses_per_s"] == pytest.approx(4.0)
    assert base["check_all_cached_s"] is None and cur["check_all_cached_s"] == 7.5


def test_cached_reruns_are_held_to_the_baselines_run():
    """The baseline has no CAD cache: a re-run's ratio is taken to its one run."""
    _, _, _, targets = _compare(2.0)
    recheck = targets["check_all_cached_s"]
    assert recheck["baseline"] == 46.0 and recheck["current"] == 15.0
    assert recheck["ratio"] == pytest.approx(15.0 / 46.0) and recheck["met"]
    assert not targets["check_all_s"]["met"]  # 23 s: half
    assert targets["build_all_cached_s"]["current"] == 3.0 and targets["build_all_cached_s"]["met"]


def test_poses_per_s_equivalent_counts_the_baselines_work():
    base, cur, _, targets = _compare(4.0)
    # the current side makes a third of the calls; its rate is what the baseline's method makes for
    # its contacts (15 calls each, 60 000) over its time on the meshes per worker (3 s), and over its
    # sweep's wall time (15 / 4 s) beside it
    assert base["differential_poses_per_s_equivalent"] == pytest.approx(5000.0)
    assert cur["differential_poses_per_s_equivalent"] == pytest.approx(20_000.0)
    assert cur["differential_poses_per_s_equivalent_over_wall"] == pytest.approx(16_000.0)
    assert targets["differential_poses_per_s_equivalent"]["met"]


def test_targets_met_and_unmet():
    _, _, _, met = _compare(4.0)
    assert all(t["met"] for k, t in met.items() if k not in ("build_all_s", "steering_calc_s"))
    assert met["build_all_s"]["current"] == 3.5 and met["build_all_s"]["met"]
    assert not met["steering_calc_s"]["met"]  # 0.325 s > 0.2 s
    _, _, _, unmet = _compare(2.0)
    assert not any(unmet[k]["met"] for k in ("check_all_s", "steering_poses_per_s", "track_sprocket_poses_per_s"))
    assert unmet["differential_speedup_1_to_2"]["met"]  # 2x from 1 to 2 workers, every core by default


def test_failed_runs_give_no_figure_and_an_unmet_target():
    raw = _side(4.0)
    raw["check_all"] = [{"wall_s": None, "ok": False, "error": "timed out"}]
    raw["sweep_differential"] = [{"ok": False, "error": "ImportError: x"}]
    base, cur = run.side_figures(_side(1.0), JOBS, 2), run.side_figures(raw, JOBS, 2)
    ratios, targets = run.compare(base, cur, 2)
    by_key = {t["key"]: t for t in targets}
    assert cur["check_all_s"] is None and "check_all_s" not in ratios
    assert not by_key["check_all_s"]["met"] and not by_key["differential_ms_per_play_measurement"]["met"]
    assert cur["sweeps"]["differential"]["failed_runs"] == ["ImportError: x"]
    json.dumps({"b": base, "c": cur, "r": ratios, "t": targets}, allow_nan=False)
    assert "check --all" in run.table(targets, cur, base, 2)


def test_probe_work_counts_from_either_versions_timings():
    assert probe.work_count("differential", {"collide_calls": 123.0}) == {"unit": "collide calls", "count": 123}
    assert probe.work_count("differential", {"fcl_queries": 45.0}) == {"unit": "FCL queries", "count": 45}
    assert probe.work_count("steering", {"poses_per_s": 400.0, "elapsed_s": 5.6})["count"] == 2240
    assert probe.work_count("track", {"poses_per_s": 38.5, "sweep_s": 2.0})["count"] == 77
    assert probe.work_count("track", {"link_poses_per_s": 1.0}) == {"unit": None, "count": None}
    assert probe._plain({"a": float("nan"), "b": (1, 2.5), "c": True}) == {"a": None, "b": [1, 2.5], "c": True}
