"""Every design gets a verdict, never a refusal for a mesh too coarse: the track drive with a tip
gap of 0.05 mm (a plain failure of the 0.5–1.0 mm window) and with the ISO minimum seating radius
(a 0.04 mm tooth–sleeve clearance) are meshed fine enough to decide their least clearance on the
mesh, and get their verdicts (exit 1 and exit 0), not exit 2."""

import json

import pytest

from gearcheck.cli import main

pytestmark = pytest.mark.cad


def _check(tmp_path, templates_dir, *sets):
    args = ["check", str(templates_dir / "eod_track_drive.toml"), "--out", str(tmp_path)]
    for s in sets:
        args += ["--set", s]
    code = main(args)
    return code, json.loads((tmp_path / "summary.json").read_text())["track"]


def test_a_tip_gap_below_the_window_fails_with_a_resolved_mesh(tmp_path, templates_dir):
    code, s = _check(tmp_path, templates_dir, "track_plate.tip_gap_mm=0.05")
    assert code == 1
    rule = s["mesh_resolution"]
    assert rule["smallest_clearance_mm"] == pytest.approx(0.05, abs=1e-6)  # the tip gap, exact 2-D
    assert rule["tol_mm"] <= 0.05 / 20 and rule["rule_met"] == 1
    assert rule["pair_error_bound_mm"] <= rule["allowed_bound_mm"]
    assert s["verdict_levels"]["seated_tip_gap_in_window"] == "fail"
    assert s["verdict_levels"]["min_tip_plate_distance"] == "fail"
    assert s["verdict_levels"]["no_interference"] == "pass"  # 0.05 mm is a clearance, not a contact
    assert s["min_tip_plate_distance_mm"] == pytest.approx(0.05, abs=rule["pair_error_bound_mm"])


def test_the_iso_minimum_seating_radius_gets_its_exact_verdicts(tmp_path, templates_dir):
    code, s = _check(tmp_path, templates_dir, "sprocket.seating_radius_mm=4.04")
    assert code == 0
    rule = s["mesh_resolution"]
    assert rule["smallest_clearance_mm"] == pytest.approx(0.04, abs=2e-4)  # tooth–sleeve, exact 2-D
    assert rule["rule_met"] == 1 and rule["pair_error_bound_mm"] <= rule["allowed_bound_mm"]
    assert s["verdict_pass"] == 1
    exact = s["exact"]["min_tooth_sleeve_clearance_mm"]
    assert s["min_tooth_sleeve_clearance_mm"] == pytest.approx(exact, abs=rule["pair_error_bound_mm"])


def test_a_play_no_practical_mesh_resolves_is_decided_on_the_exact_evidence(tmp_path, templates_dir):
    """Differential at shim 0.04 mm: +0.08′ per side at the cold design point on the exact flanks
    (≈ 1 µm on d1/2) would need 0.05 µm meshes. Not a refusal: the default meshes are kept, the
    rule is recorded as not met, the play verdicts rest on the exact model, and the worst poses
    are confirmed on the exact B-rep."""
    code = main(["check", str(templates_dir / "zhurong_differential.toml"), "--set", "shim.thickness_mm=0.04",
                 "--out", str(tmp_path)])
    s = json.loads((tmp_path / "summary.json").read_text())["differential"]
    rule = s["mesh_resolution"]
    assert rule["rule_met"] == 0
    assert rule["resolving_tol_mm"] < 0.0005 < rule["tol_mm"]  # finer than any practical mesh: default kept
    assert rule["smallest_clearance_mm"] < 0.002
    assert s["verdict_evidence"]["cold_play_positive"].startswith("exact model")
    assert s["verdict_levels"]["cold_play_positive"] == "pass"  # +0.08′: free, on the exact flanks
    assert s["verdict_evidence"]["exact_confirmation"].startswith("exact B-rep: the meshes cannot resolve")
    assert s["verdict_levels"]["storage_play_positive"] == "warn"
    assert code == 0  # warnings do not fail a design
