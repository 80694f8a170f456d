"""The assembly's clearance verdicts certified over the continuous motion: a bar turning past a
post comes closest between two sampled poses. Sampled, the requirement holds; certified, the
refinement finds the true closest approach and the verdict fails with it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

import gearcheck

pytestmark = pytest.mark.cad

GAP = 0.3  # the bar's end passes the post this close, at angle 0


def _write(path: Path) -> Path:
    import cadquery as cq  # noqa: TID251 (the user's CAD script)
    from cadquery.occ_impl.exporters.assembly import exportAssembly  # noqa: TID251

    assy = cq.Assembly(name="bar_and_post")
    assy.add(cq.Workplane("XY").box(20, 2, 2, centered=(False, True, True)), name="bar")
    assy.add(cq.Workplane("XY").box(1.7, 2, 2, centered=(False, True, True)).translate((20 + GAP, 0, 0)),
             name="post")
    assert exportAssembly(assy, str(path))
    return path


def test_a_closest_approach_between_two_samples_is_caught(tmp_path):
    step = _write(tmp_path / "bar.step")
    data = {
        "mechanism": "assembly", "name": "bar_and_post",
        "assembly": {"step": str(step)},
        "part": [{"name": "bar"}, {"name": "post"}],
        "joint": [{"part": "bar", "kind": "revolute", "axis": [0.0, 0.0, 1.0], "point": [0.0, 0.0, 0.0]}],
        "motion": {"part": "bar", "start_deg": -10.0, "end_deg": 10.0, "step_deg": 20.0},
        "require": [{"parts": ["bar", "post"], "min_clearance_mm": 0.5}],
    }
    run = gearcheck.load(data).check(out=tmp_path / "run", jobs=1)
    pair = run.summary["assembly"]["pairs"]["bar__post"]
    # at the two poses the bar is 1.5 mm off: the sampled figure passes the 0.5 mm requirement
    assert pair["min_clearance_mm"] > 1.0
    # between them it passes within 0.3 mm: found, certified below it, and the verdict fails
    assert pair["sampled_min_mm"] == pytest.approx(GAP, abs=pair["mesh_error_bound_mm"] + 1e-3)
    assert pair["certified_min_mm"] <= pair["sampled_min_mm"] and pair["intervals_refined"] >= 1
    lo, hi = pair["certified_min_between_deg"]
    assert lo <= 0.0 <= hi
    verdict = next(v for v in run.verdicts if v.name == "clearance_bar__post")
    assert verdict.level == "fail" and "between the samples" in verdict.shortfall
    assert "certified over the continuous motion" in verdict.evidence
    summary = json.loads((run.folder / "summary.json").read_text())["assembly"]
    assert summary["verdict_levels"]["clearance_bar__post"] == "fail"
    assert not run.passed and math.isfinite(pair["certified_min_mm"])


def test_the_interval_path_bounds_every_mesh_points_path(build_bodies):
    """interval_path (the relative speed on the pruned meshes' convex hulls, grown along each
    point's own path) is never below the path any vertex of the pair's pruned meshes takes relative
    to the other part, sampled finely, and not far above it."""
    import numpy as np

    from gearcheck.mechanism import get
    from gearcheck.mechanisms.assembly.sweep import interval_path

    run = build_bodies("assembly_spur_pair")
    plan = get("assembly").plan(run.design.params, run.assembly, run.bodies, None)
    spec = plan.tasks[0][1][0]
    meshes = {m.name: m for m in plan.meshes}
    rule = next(r for r in spec.pairs if r.key not in spec.far and r.moving)
    names = spec.meshes[rule.key]
    kin = spec.kin
    rng = np.random.default_rng(5)
    x_lo, x_hi = float(kin.coordinates[0]), float(kin.coordinates[-1])
    for _ in range(12):
        x0 = float(rng.uniform(x_lo, x_hi))
        x1 = x0 + float(rng.uniform(0.0, 0.2 * (x_hi - x_lo)))
        xs = np.linspace(x0, x1, 200)
        paths = []
        for part, other, name in ((rule.a, rule.b, names[0]), (rule.b, rule.a, names[1])):
            v = meshes[name].vertices
            placed = np.stack([(np.linalg.inv(kin.pose(other, x)) @ kin.pose(part, x))[:3] @ np.c_[v, np.ones(len(v))].T
                               for x in xs])  # (steps, 3, n): the vertices in the other part's frame
            paths.append(float(np.linalg.norm(np.diff(placed, axis=0), axis=1).sum(axis=0).max()))
        bound = interval_path(spec, rule, x0, x1)
        assert min(paths) <= bound * (1 + 1e-9) + 1e-12
        assert bound <= 1.5 * max(paths) + 1e-9
