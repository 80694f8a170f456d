"""The exact B-rep confirmation at the worst poses is a verdict, and right where the meshes
overlap: the differential at −130 °C binds (exact play −1.42′ per side at shim 0.10), its worst
poses collide, and there the mesh's nearest points mean nothing. Before: the near-face shortcut,
centred on FCL's nearest point, reported 0.00946 mm between overlapping gears. Now the whole
solids are measured: distance 0 and a positive common volume."""

from __future__ import annotations

import math

import pytest

from gearcheck import pipeline

pytestmark = pytest.mark.cad


def test_overlapping_worst_poses_are_measured_on_the_whole_solids(build_bodies):
    run = build_bodies("zhurong_differential", ("operating.cold_C=-130",))
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1,
                            options={"angles_per_cycle": 4, "shims_mm": [0.1]})
    confirmations = pipeline.confirm(result, run.parts, run.bodies)
    overlapping = [c for c in confirmations if c.meshes_overlap]
    assert overlapping, "the cold worst poses of a binding differential must collide"
    for c in overlapping:
        assert c.mesh_mm == 0.0
        assert c.brep_mm < 1e-9  # the exact solids intersect too
        assert math.isfinite(c.overlap_mm3) and c.overlap_mm3 > 0.0
        assert c.agrees and c.contact == "overlapping"  # a zero distance, told apart from touching
        assert c.figures()["contact"] == "overlapping"
    verdict = pipeline.confirmation_verdict(confirmations)
    assert verdict.passed and "meshes overlap" in verdict.measured and "solids overlapping" in verdict.measured


def test_a_free_pose_that_disagrees_fails_the_verdict():
    from gearcheck.results import Confirmation

    ok = Confirmation("free", "free", "a / b", 0.100, 0.097, 0.006)
    off = Confirmation("free", "free", "a / b", 0.100, 0.080, 0.006)
    touching = Confirmation("overlap", "overlap", "a / b", 0.0, 0.02, 0.006, overlap_mm3=0.0)
    assert ok.agrees and not off.agrees and not touching.agrees  # meshes overlap, solids 0.02 mm apart
    assert pipeline.confirmation_verdict([ok]).passed
    assert not pipeline.confirmation_verdict([ok, off]).passed
    assert not pipeline.confirmation_verdict([touching]).passed
