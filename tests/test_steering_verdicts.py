"""The steering check's verdicts on designs that must fail, and the template that must pass.

Continuous drive is the whole drive (towing and power mode, every hand-over between tooth pairs:
exact contact intervals, ``geometry/rack_pinion_contact.py``) and the mesh, whichever is least;
the contact ratio at the machined hS4 must meet trim.min_contact_ratio (docs/steering.md).
"""

import json
import math

import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.geometry.rack_pinion_contact import pair_contacts, whole_drive
from gearcheck.mechanisms.steering import analysis as an

TEMPLATE = "nose_wheel_steering"
# The failing verdicts below are decided by the exact model, so a coarse grid does not change
# them (the grid only sets the mesh curve's sampling).
COARSE = {"towing_step_deg": 1.0, "power_step_deg": 1.0}
SHORT_TOP = ["pinion.topped_radius_mm=82.9", "targets.continuous_angle_deg=61"]
HANDOVER_GAP = ["trim.hS2_mm=24.1", "trim.hS6_mm=24.6", "targets.continuous_angle_deg=60.5"]


def _design(templates_dir, overrides=()):
    return gearcheck.load(templates_dir / f"{TEMPLATE}.toml", list(overrides))


def _geometry(templates_dir, overrides=()):
    return an.geometry_from_params(_design(templates_dir, overrides).params)


# ----------------------------------------------------------------------------- pure numpy

def test_whole_drive_matches_the_closed_forms_on_the_template(templates_dir):
    g = _geometry(templates_dir)
    towing, power = whole_drive(g)
    assert towing.angle_rad == pytest.approx(an.phi_towing_conjugate_end(g, g.sector_first_tooth), abs=1e-12)
    assert power.angle_rad == pytest.approx(an.continuous_power_angle(g), abs=1e-12)
    assert math.degrees(power.angle_rad) == pytest.approx(62.327, abs=1e-3)
    assert "G1" in towing.event and "S1" in towing.event and towing.gap_rad is None
    assert "S6" in power.event
    # conjugate contact of every inner pair spans one contact ratio of pitches
    tau = g.angular_pitch
    inner = [p for p in pair_contacts(g, "towing") if abs(p.j) < 4]
    for p in inner:
        assert (p.end_rad - p.start_rad) / tau == pytest.approx(an.contact_ratio(g, g.rack_top_height), rel=1e-9)


def test_short_topped_radius_ends_towing_drive_at_S1(templates_dir):
    towing, power = whole_drive(_geometry(templates_dir, SHORT_TOP[:1]))
    assert towing.angle_deg == pytest.approx(60.120, abs=1e-3)
    assert towing.gap_rad is None and "G1's conjugate contact ends" in towing.event
    assert power.angle_deg == pytest.approx(62.327, abs=1e-3)


def test_low_hS2_leaves_a_handover_gap(templates_dir):
    towing, _ = whole_drive(_geometry(templates_dir, HANDOVER_GAP[:2]))
    assert towing.gap_rad is not None
    a, b = (math.degrees(x) for x in towing.gap_rad)
    assert a == pytest.approx(60.073, abs=1e-3) and b == pytest.approx(60.184, abs=2e-3)
    assert "hand-over gap G2→G1" in towing.event and towing.angle_deg == pytest.approx(a)


# ----------------------------------------------------------------------------- full checks

def _verdict(run, name):
    return next(v for v in run.result.verdicts if v.name == name)


@pytest.mark.cad
def test_template_passes_every_verdict(templates_dir, tmp_path):
    code = main(["check", str(templates_dir / f"{TEMPLATE}.toml"), "--out", str(tmp_path), "--jobs", "2"])
    assert code == 0
    s = json.loads((tmp_path / "summary.json").read_text())["steering"]
    assert all(v == 1 for v in s["verdicts"].values())
    assert {"continuous_drive", "contact_ratio"} <= set(s["verdicts"])
    assert s["continuous_drive_deg"] == pytest.approx(62.327, abs=1e-3)
    assert s["model_continuous_towing_deg"] == pytest.approx(62.662, abs=1e-3)
    assert s["model_contact_ratio"] == pytest.approx(1.2011, abs=1e-4)


@pytest.mark.cad
@pytest.mark.parametrize("overrides, limit_deg, event", [
    (SHORT_TOP, 60.120, "towing: G1's conjugate contact ends at 60.120°"),
    (HANDOVER_GAP, 60.073, "hand-over gap G2→G1 60.073°–60.18"),
])
def test_continuous_drive_fails_on_the_whole_drive(templates_dir, tmp_path, overrides, limit_deg, event):
    run = _design(templates_dir, overrides).check(out=tmp_path, jobs=2, options=COARSE)
    v = _verdict(run, "continuous_drive")
    assert not v.passed and not run.result.passed
    assert v.figures["continuous_drive_deg"] == pytest.approx(limit_deg, abs=1e-3)
    assert event in v.measured
    assert _verdict(run, "contact_ratio").passed


@pytest.mark.cad
def test_contact_ratio_rule_fails_at_the_machined_hS4(templates_dir, tmp_path):
    code = main(["check", str(templates_dir / f"{TEMPLATE}.toml"), "--set", "trim.min_contact_ratio=1.3",
                 "--out", str(tmp_path), "--jobs", "2"])
    assert code == 1
    s = json.loads((tmp_path / "summary.json").read_text())["steering"]
    assert s["verdicts"]["contact_ratio"] == 0 and s["verdicts"]["continuous_drive"] == 1
    assert s["model_contact_ratio"] == pytest.approx(1.2011, abs=1e-4)


# ----------------------------------------------------------------------------- labels

def test_stop_is_named_by_the_corner_that_decides_it(templates_dir):
    from gearcheck.geometry.rack_pinion_contact import stop_phrase

    cases = (((), "G1's tip land grazes S2"), (("pinion.topped_radius_mm=82.3",), "G2's tip land grazes S4"))
    for overrides, phrase in cases:
        g = _geometry(templates_dir, overrides)
        tow = an.analyse_towing(g, 100.0)
        assert stop_phrase(g, tow.last_pusher) == phrase
    g = _geometry(templates_dir)
    assert math.isnan(an.analyse_towing(g, 75.0).disengage_rad)


def test_paper_values_only_beside_the_paper_design(templates_dir):
    paper = gearcheck.load(templates_dir / f"{TEMPLATE}.toml").calc()
    other = gearcheck.load(templates_dir / f"{TEMPLATE}.toml", ["pinion.topped_radius_mm=84.0"]).calc()
    assert any(f.paper is not None for f in paper.figures)
    assert all(f.paper is None for f in other.figures)
    text = " ".join(f"{f.label} {f.note}" for f in other.figures)
    for printed in ("ADAMS", "75.32", "110.20", "75.89", "62.11", "84.294", "test 64"):
        assert printed not in text


def test_calc_json_has_no_null_for_a_missing_solved_trim(templates_dir, capsys):
    code = main(["calc", str(templates_dir / f"{TEMPLATE}.toml"), "--set", "trim.min_contact_ratio=1.3", "--json"])
    assert code == 0
    body = json.loads(capsys.readouterr().out)["steering"]
    assert "hS2_solved_mm" not in body and body["RS1_solved_mm"] == pytest.approx(82.837, abs=1e-3)
    assert main(["calc", str(templates_dir / f"{TEMPLATE}.toml"), "--set", "trim.min_contact_ratio=1.3"]) == 0
    assert "hS2 solved: none in range" in capsys.readouterr().out


@pytest.mark.cad
def test_towing_swing_too_short_says_the_rack_is_still_moving(templates_dir, tmp_path):
    run = _design(templates_dir, ["towing.max_angle_deg=75"]).check(out=tmp_path, jobs=2)
    stops, past = _verdict(run, "rack_stops"), _verdict(run, "no_interference_past_disengage")
    assert not stops.passed and "still moving at the end of the swing" in stops.measured
    assert "not reached within towing.max_angle_deg" in stops.measured
    assert "nan" not in stops.measured.lower() and "nan" not in past.measured.lower()
    assert past.level == "warn"


@pytest.mark.cad
def test_other_design_report_has_no_paper_values(templates_dir, tmp_path):
    run = _design(templates_dir, ["pinion.topped_radius_mm=84.0"]).check(out=tmp_path, jobs=2, options=COARSE)
    assert not any(k.startswith("paper_") for k in run.summary["steering"])
    res = run.result
    assert all(c.paper is None for c in res.comparisons)
    assert not any("ADAMS" in c.label or "paper" in c.note for c in res.comparisons)
    assert all(x is not None for p in res.plots for _, x in p.markers + p.hlines)


@pytest.mark.cad
def test_g2_corner_deciding_the_stop_is_named(templates_dir, tmp_path):
    run = _design(templates_dir, ["pinion.topped_radius_mm=82.3"]).check(out=tmp_path, jobs=2, options=COARSE)
    past = _verdict(run, "no_interference_past_disengage")
    assert "G2's tip land grazes S4" in past.label and "G1" not in past.label
    assert any("G2's tip land grazes S4" in c.label for c in run.result.comparisons)
    assert not any("G1's tip land" in n for n in run.result.notes)
