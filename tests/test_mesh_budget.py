"""The triangle budget: a tolerance fine enough to exhaust the machine is refused in one line with
the finest that fits, before any fine mesh is made (before: a module-10 differential at
--tol 0.0005 wrote nothing in 10 minutes and took 2.2 GB); the estimate it rests on is measured
against the mesh it predicts."""

from __future__ import annotations

import pytest

import gearcheck
from conftest import TEMPLATES, messages
from gearcheck import pipeline, resolution
from gearcheck.cli import main

pytestmark = pytest.mark.cad

TRACK = TEMPLATES / "eod_track_drive.toml"


@pytest.mark.parametrize("template, tol", [("eod_track_drive", 0.002), ("nose_wheel_steering", 0.001)])
def test_the_estimate_lies_within_its_stated_factors_of_the_real_count(template, tol):
    """Measured: 0.8 to 3.4 times the count it predicts (module docstring of gearcheck.cad.mesh);
    the meshing counts too, so an estimate on the low side cannot let a run past the budget."""
    from gearcheck.cad.mesh import estimate_triangles, triangle_count

    design = gearcheck.load(TEMPLATES / f"{template}.toml")
    _, parts = pipeline.build_parts(design)
    solids = list({id(p.solid): p.solid for p in parts}.values())
    real = sum(triangle_count(s, tol) for s in solids)
    estimated = estimate_triangles(solids, tol)
    assert 0.8 * real <= estimated <= 3.4 * real, (real, estimated)


def test_meshing_stops_once_the_count_passes_the_budget(tmp_path, monkeypatch):
    """An estimate on the low side: the meshes counted as they are made stop the run at the
    budget (before: nothing stopped a mesh, or the sweep's BVHs, from growing without bound)."""
    from gearcheck.cad import mesh

    monkeypatch.setattr(mesh, "estimate_triangles", lambda _shapes, _tol: 1)
    monkeypatch.setattr(resolution, "TRIANGLE_BUDGET", 20_000)
    with pytest.raises(gearcheck.ParamError, match=r"--tol = 0\.002: .*over the budget of 20,000"):
        gearcheck.load(TRACK).build(out=tmp_path / "run", tol=0.002)
    assert not (tmp_path / "run").exists()


def test_a_tol_over_the_budget_is_one_line_with_the_finest_that_fits(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(resolution, "TRIANGLE_BUDGET", 40_000)
    out = tmp_path / "run"
    assert main(["build", str(TRACK), "--tol", "0.001", "--out", str(out), "--no-cache"]) == 2
    lines = messages(capsys.readouterr().err)
    assert len(lines) == 1, lines
    err = lines[0]
    assert err.startswith("gearcheck: error: --tol = 0.001: the meshes of this design would hold about ")
    assert "over the budget of 40,000: allowed " in err
    fit = float(err.rsplit("allowed ", 1)[1].split(" mm")[0])
    assert not out.exists() and [p.name for p in tmp_path.iterdir()] == [".run.lock"]
    # the tolerance it names does fit: that build goes through, under the budget
    run = gearcheck.load(TRACK).build(out=out, tol=fit)
    distinct = {p["name"]: p["triangles"] for p in run.manifest["parts"]}
    assert run.tol_mm == fit and 0 < sum(distinct.values())


def test_a_tolerance_the_resolution_rule_chooses_stops_at_the_budget(tmp_path, monkeypatch):
    """Not the user's request: the rule's finer tolerance is coarsened to fit, noted in the
    manifest; the exact B-rep decides what the meshes then cannot resolve."""
    design = gearcheck.load(TRACK)
    plan = pipeline.mesh_plan(design, None)
    finer = resolution.MeshPlan(plan.tol_mm / 8, plan.requested_mm, False, plan.clearance)
    monkeypatch.setattr(pipeline, "mesh_plan", lambda _d, _t: finer)
    monkeypatch.setattr(resolution, "TRIANGLE_BUDGET", 40_000)
    run = design.build(out=tmp_path / "run")
    tol = run.manifest["mesh_tolerance"]
    assert tol["triangle_budget"] == 40_000 and tol["tol_mm"] > finer.tol_mm
    assert run.tol_mm == tol["tol_mm"]


def test_fitting_tolerance_rounds_up_to_two_digits():
    assert resolution.fitting_tolerance(0.0005, 10_629_027, 3_000_000) == pytest.approx(0.0016)
    fit = resolution.fitting_tolerance(0.001, 4_000_000, 3_000_000)
    assert fit >= 0.001 * (4 / 3) ** (1 / 1.1) and float(f"{fit:.2g}") == fit
