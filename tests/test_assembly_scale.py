"""A large assembly is bounded: its sweep's cost is predicted before it starts (poses × the pairs
left after pruning × the cost of one pair at one pose, measured on a sample of its own), stated on
the progress display and in the run's files, and over the budget (``--budget``) the run is refused
in one line naming the motion's step and the step that would fit, nothing written.

The assemblies are grids of small cubes drawn by a CadQuery script (tests/step_boxes.py), every
cube turning about its own axis, all coupled to the first, a least clearance required between
grid neighbours: 200 cubes are 19,900 pairs, of which the 370 neighbour pairs can ever come near.
"""

from __future__ import annotations

import json
import math
import re
import time
from pathlib import Path

import numpy as np
import pytest
import tomli_w

from gearcheck.cli import main
from gearcheck.sweep_budget import SweepCost
from step_boxes import boxes_template, least_gap, neighbours, write_boxes

pytestmark = pytest.mark.cad


@pytest.fixture(scope="module")
def steps(tmp_path_factory) -> dict[int, Path]:
    folder = tmp_path_factory.mktemp("boxes")
    return {200: write_boxes(folder / "boxes200.step", count=200, columns=20),
            20: write_boxes(folder / "boxes20.step", count=20, columns=10)}


def _toml(path: Path, data: dict) -> Path:
    path.write_bytes(tomli_w.dumps(data).encode())
    return path


def test_200_turning_boxes_over_the_budget_are_refused_with_the_step_that_fits(steps, tmp_path, capsys):
    """7201 poses of 200 turning cubes: the 19,530 pairs that never come near are pruned before
    the cost is predicted, the 370 neighbour pairs priced, and the run refused (exit 2, one line,
    nothing written) with the step that fits the budget, in seconds, not the hour it would take."""
    template = _toml(tmp_path / "boxes200.toml", boxes_template(steps[200], count=200, columns=20, step_deg=0.05))
    out = tmp_path / "run"
    t0 = time.perf_counter()
    code = main(["check", str(template), "--out", str(out), "--budget", "30", "--jobs", "1"])
    elapsed = time.perf_counter() - t0
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("gearcheck:")]
    assert code == 2 and len(err) == 1, err
    found = re.fullmatch(r"gearcheck: error: motion\.step_deg = 0\.05: allowed ≥ ([0-9.e+-]+) deg for this "
                         r"assembly's 370 pairs within the budget of 30 CPU s \(predicted ([0-9]+) CPU s, .* at "
                         r"7201 poses: .*; or raise --budget\)", err[0])
    assert found, err[0]
    fits, predicted = float(found.group(1)), float(found.group(2))
    assert predicted > 30 and fits > 0.05
    # the step named scales the poses down by the prediction's excess over the budget (90 % of it)
    assert fits == pytest.approx(360.0 / (7200 * 0.9 * 30 / predicted), rel=0.25)
    assert not out.exists()
    assert elapsed < 120, elapsed  # build, prune, price: no sweep


def test_a_sweep_within_its_budget_states_its_cost_first_and_takes_about_that(steps, tmp_path, capsys, monkeypatch):
    """20 cubes (two rows of ten), 37 poses: the prediction is announced before the sweep (where
    stderr is not a terminal: a line, then a line per tenth of the poses), the run passes, the
    measured CPU seconds stand beside the prediction in manifest.json and the report, and only the
    28 neighbour pairs are queried (summary.json counts them; sweep.csv has their columns)."""
    from gearcheck import sweep_budget

    monkeypatch.setattr(sweep_budget, "ANNOUNCE_CPU_S", 0.0)  # announce even this small one
    template = _toml(tmp_path / "boxes20.toml", boxes_template(steps[20], count=20, columns=10, step_deg=10.0))
    out = tmp_path / "run"
    assert main(["check", str(template), "--out", str(out), "--jobs", "1"]) == 0
    err = capsys.readouterr().err.splitlines()
    pairs = len(neighbours(20, 10))
    announced = next(i for i, line in enumerate(err) if line.startswith("sweeping boxes_20: about "))
    assert re.fullmatch(rf"sweeping boxes_20: about [0-9]+ CPU s: 37 poses × {pairs} pairs × [0-9.e+-]+ ms "
                        rf"\({190 - pairs} pairs never near: not queried\); budget 3600 CPU s, on 1 worker\(s\)",
                        err[announced]), err[announced]
    assert any(line.strip().endswith("37/37 pose (100 %)") for line in err[announced:]), err
    cost = json.loads((out / "manifest.json").read_text())["sweep_cost"]
    assert cost["poses"] == 37 and cost["pairs_every_pose"] == pairs and cost["pairs_never_near"] == 190 - pairs
    assert 0 < cost["actual_cpu_s"] <= 3 * cost["predicted_cpu_s"] + 0.5, cost  # a measured figure: loose
    assert cost["budget_cpu_s"] == 3600
    summary = json.loads((out / "summary.json").read_text())["assembly"]
    assert (summary["pairs_checked"], summary["pairs_queried"], summary["pairs_never_near"]) == (190, pairs,
                                                                                               190 - pairs)
    assert summary["verdict_pass"] == 1
    least = min(v["certified_min_mm"] for v in summary["pairs"].values() if "certified_min_mm" in v)
    assert 0.25 <= least <= least_gap() + 1e-6  # a lower bound of the corners' closest approach, which passes
    header = (out / "sweep.csv").read_text().splitlines()[0].split(",")
    assert sum(c.startswith("clearance_") for c in header) == pairs
    assert "Sweep cost: predicted before the sweep" in (out / "report.html").read_text(encoding="utf-8")


def test_pairs_the_broad_phase_drops_never_come_within_the_margin(steps, tmp_path):
    """The swept boxes and capsules drop a pair only where its parts never come within the margin
    (measured between the meshes every degree, between the sweep's 15° poses too), and keep the
    neighbours."""
    from gearcheck import load, pipeline
    from gearcheck.mechanisms.assembly.meshes import base_margin, box_corners, near_pairs
    from gearcheck.sweep.engine import Scene

    design = load(boxes_template(steps[20], count=20, columns=10, step_deg=15.0, min_clearance_mm=0.5))
    built = pipeline.build(design, tmp_path / "run")
    lay, bodies = built.assembly.layout, built.bodies
    kin = lay.kin
    near = near_pairs(lay, kin, {p: box_corners(b.mesh) for p, b in bodies.items()}, 0.0)
    names = [p.name for p in design.params.part]
    assert {f"{names[a]}__{names[b]}" for a, b in neighbours(20, 10)} <= {r.key for r, k in zip(lay.pairs, near,
                                                                                                  strict=True) if k}
    assert near.sum() < len(lay.pairs)
    base = base_margin(lay)
    scene = Scene([b.mesh for b in bodies.values()])
    for x in np.arange(0.0, 361.0, 1.0):
        scene.set_poses({p: kin.pose(p, float(x)) for p in bodies})
        for rule, kept in zip(lay.pairs, near, strict=True):
            if not kept:
                assert scene.distance(rule.a, rule.b).distance > 2 * base, (rule.key, x)


def _cost(**given) -> SweepCost:
    values = dict(poses=1441, states=2, pairs=370, static_pairs=10, pruned_pairs=19520, pair_pose_s=1e-4,
                  play_pose_s=2e-3, setup_s=0.5, calibration_s=0.1, setting="motion.step_deg", value=0.25,
                  unit="deg", extent=360.0)
    values.update(given)
    return SweepCost(**values)  # type: ignore[arg-type]


def test_the_step_a_refusal_names_fits_the_budget():
    cost = _cost()
    total = cost.cpu_s(2)
    assert total == pytest.approx(2 * (10 * 1e-4 + 2 * 0.5) + 1441 * 2 * (370 * 1e-4 + 2e-3))
    assert cost.refusal(total * 1.01, 4.0, 2) is None
    budget = total / 5
    err = cost.refusal(budget, 4.0, 2)
    assert err is not None and err.field == "motion.step_deg" and err.value == 0.25
    fits = float(re.search(r"allowed ≥ ([0-9.]+) deg", str(err)).group(1))
    poses = math.floor(360.0 / fits + 1e-9) + 1
    assert _cost(poses=poses, value=fits).cpu_s(2) <= budget
    assert _cost(poses=poses + 20).cpu_s(2) > 0.9 * budget  # and is not far coarser than needed
    # nothing fits where the pairs at the first pose and the BVHs alone are over the budget
    err = cost.refusal(0.5, 4.0, 2)
    assert err is not None and "no motion fits the budget of 0.5 CPU s" in str(err)


def test_stops_are_counted_and_memory_is_bounded_too():
    cost = _cost(setting="motion.stops_deg", value=1441.0, extent=0.0)
    err = cost.refusal(cost.cpu_s(1) / 4, 4.0, 1)
    assert err is not None and "motion.stops_deg = '1441 stops': allowed at most" in str(err)
    big = _cost(poses=90_000, pair_pose_s=1e-7, play_pose_s=0.0)
    assert big.memory_gb > 4.0
    err = big.refusal(3600.0, 4.0, 1)
    assert err is not None and "within the memory budget of 4 GB" in str(err)
    fits = float(re.search(r"allowed ≥ ([0-9.]+) deg", str(err)).group(1))
    assert _cost(poses=math.floor(360.0 / fits) + 1).memory_gb <= 4.0


def test_segment_distances_are_the_least_distance_between_the_segments():
    from gearcheck.sweep.prune import segment_distances

    rng = np.random.default_rng(3)
    n = 300
    p1, p2 = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    q1 = p1 + rng.normal(size=(n, 3)) * rng.choice([0.0, 1.0], size=(n, 1))  # some are points
    q2 = p2 + rng.normal(size=(n, 3)) * rng.choice([0.0, 1.0], size=(n, 1))
    q2[:40] = p2[:40] + 2.0 * (q1[:40] - p1[:40])  # parallel
    d = segment_distances(p1, q1, p2, q2)
    s = np.linspace(0.0, 1.0, 301)
    for k in range(n):
        a, b = p1[k] + np.outer(s, q1[k] - p1[k]), p2[k] + np.outer(s, q2[k] - p2[k])
        brute = np.linalg.norm(a[:, None] - b[None], axis=2).min()
        assert brute - 0.02 <= d[k] <= brute + 1e-9


def test_only_the_closest_worst_poses_are_drawn():
    from gearcheck.report.pictures import MAX_WORST_PICTURES, drawn_worst
    from gearcheck.scene import PoseView

    views = [PoseView(f"v{i}", {}, distance_mm=d) for i, d in enumerate([5.0, 0.1, math.nan, *range(30)])]
    drawn = drawn_worst(views)
    assert len(drawn) == MAX_WORST_PICTURES and drawn == sorted(drawn) and 2 in drawn and 3 not in drawn
    assert drawn_worst(views[:4]) == [1, 2, 3, 4]
