"""Track drive: the chain-wear limit (exact 2-D model; the check's verdict with a sweep, cad) and
the calc labels (the paper's printed values only beside the paper's own design; the sprocket speed
from the chain's real advance per turn)."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from gearcheck import pipeline
from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.mechanism import get
from gearcheck.mechanisms.track import calc, layout, wear
from gearcheck.params import ParamError

TEMPLATE = "eod_track_drive"
# The template's wear limit: the tip mode's closed form, 1.656423 %, which the bisection on the
# exact arcs brackets to WEAR_BISECTION_TOL (1e-6 = 0.0001 % of pitch).
WEAR_LIMIT_PCT = 1.656423
WEAR_LIMIT_TOL_PCT = 1e-6


@pytest.fixture(scope="module")
def template(templates_dir):
    return templates_dir / f"{TEMPLATE}.toml"


@pytest.fixture(scope="module")
def lay(template):
    return layout.track_layout(load_template(template).params)


@pytest.fixture(scope="module")
def limit(lay):
    return wear.wear_limit(lay.sprocket.gap, lay.link, lay.wrap, 0.015)


def closed_form_limit(gap, sleeve_radius_mm: float) -> float:
    """Independent closed form: at the limit the sleeve touches the flank exactly at the tip
    corner C, so its centre is C + r·n (n the flank's outward normal at C, from the flank centre
    through C), and its distance from the axis is R·(1 + e)."""
    c, f = gap.tip_corner, gap.flank_centre
    n = (c - f) / np.linalg.norm(c - f)
    return float(np.linalg.norm(c + sleeve_radius_mm * n)) / gap.pitch_radius_mm - 1.0


# --- the exact 2-D model (no CAD) ----------------------------------------------------------------


def test_template_wear_limit_figure_and_closed_form(lay, limit):
    """1.656423 % on the template, set by the sleeve riding up the flank to the tip corner: the
    closed form, held by the bisection bracket on the exact arcs."""
    assert limit.mode == "tip" and limit.closed_form
    assert 100 * limit.limit == pytest.approx(WEAR_LIMIT_PCT, abs=WEAR_LIMIT_TOL_PCT)
    exact = closed_form_limit(lay.sprocket.gap, lay.link.sleeve_radius_mm)
    assert limit.lo <= exact <= limit.fail_at and 0 < limit.fail_at - limit.lo <= wear.WEAR_BISECTION_TOL
    assert limit.limit == pytest.approx(exact, abs=1e-12)
    # the short tooth (tip 0.2 mm above the pitch circle) tolerates less than ANSI's 3 % ceiling
    assert limit.limit < 0.03 and limit.ok


def test_seat_check_modes_and_sweep(lay, limit):
    """Unworn and at the declared 1.5 % every link seats and the worn-pitch sweep is clear; just
    past the limit the flank contact is at the tip corner; far past it the sleeve clears the tooth."""
    gap, r = lay.sprocket.gap, lay.link.sleeve_radius_mm
    new = wear.seat_check(gap, r, 0.0)
    assert new.ok and new.contact_radius_mm < gap.tip_radius_mm
    assert limit.declared_seat.ok and limit.declared_sweep.ok
    assert limit.declared_sweep.min_plate_mm > 0.75  # the worn chain rides higher: the plate lifts away
    past = wear.seat_check(gap, r, limit.fail_at)
    assert not past.ok and past.mode == "tip"
    assert past.contact_radius_mm == pytest.approx(gap.tip_radius_mm, abs=1e-9)
    # just below the closed form the contact is on the flank, just below the corner; just above, at it
    below, above = wear.seat_check(gap, r, limit.limit - 1e-8), wear.seat_check(gap, r, limit.limit + 1e-8)
    assert below.ok and 0 < gap.tip_radius_mm - below.contact_radius_mm < 1e-5
    assert above.mode == "tip"
    # sleeve bottom above the tip circle: no contact at all before the tooth's centre line
    lifted = (gap.tip_radius_mm + r) / gap.pitch_radius_mm - 1.0 + 1e-3
    assert wear.seat_check(gap, r, lifted).mode == "jump"
    assert wear.sweep_check(gap, lay.link, lay.wrap, 0.0).min_sleeve_mm == pytest.approx(
        gap.seating_radius_mm - r, abs=1e-4)


def test_groove_distance_is_the_exact_arcs_one(lay):
    """The seat check's distance (exact arcs) against an independent one: a dense polyline of the
    outline (0.0005 mm chords), within its sagitta, for sleeve centres anywhere between the
    groove's centre line and the next tooth's."""
    from gearcheck.geometry import iso606

    gap = lay.sprocket.gap
    step = 5e-4
    poly = iso606.tooth_gap_profile(gap, step)
    a, b = poly[:-1], poly[1:]
    rng = np.random.default_rng(3)
    n = 300
    phi = rng.uniform(0.0, gap.half_pitch_angle_rad, n)
    rho = gap.pitch_radius_mm * rng.uniform(0.97, 1.06, n)
    pts = np.column_stack([rho * np.cos(phi), rho * np.sin(phi)])
    dist, q, _ = wear.groove_nearest(gap, pts)
    e = b - a
    for p, d, qq in zip(pts, dist, q, strict=True):
        t = np.clip(((p - a) * e).sum(1) / (e * e).sum(1), 0.0, 1.0)
        ref = np.hypot(*(a + t[:, None] * e - p).T).min()
        assert abs(d - ref) <= step**2 / (8 * gap.seating_radius_mm) + 1e-12
        assert np.hypot(*(qq - p)) == pytest.approx(d, abs=1e-12)


# Designs across z, flank radius, seating angle, pitch and sleeve (the first two printed 3.96929–
# 3.96938 % and 5.87349–5.87358 % before the seat check was made on the exact arcs, against the
# closed forms 3.96999 % and 5.87467 %).
INCH = ("chain.pitch_mm=25.4", "chain.sleeve_diameter_mm=6.35", "sprocket.seating_radius_mm=3.25")
DESIGNS = {
    "p25.4 z21 re25 a125": (*INCH, "sprocket.teeth=21", "sprocket.flank_radius_mm=25", "sprocket.seating_angle_deg=125"),
    "z15 re20 a124": ("sprocket.teeth=15", "sprocket.flank_radius_mm=20", "sprocket.seating_angle_deg=124",
                      "sprocket.initial_pitch_diameter_mm=70"),
    "p28 z15 re20 a124": ("sprocket.teeth=15", "sprocket.flank_radius_mm=20", "sprocket.seating_angle_deg=124",
                          "chain.pitch_mm=28"),
    "p25.4 z15 re20 a124 tall": (*INCH, "sprocket.teeth=15", "sprocket.flank_radius_mm=20",
                                 "sprocket.seating_angle_deg=124", "track_plate.tip_gap_mm=0.2",
                                 "sprocket.tip_over_pitch_mm=0.7"),
    "z49 re min a max": ("sprocket.flank_radius_mm=48.96", "sprocket.seating_angle_deg=138.16"),
    "z31 re60 a121 tip 2": ("sprocket.teeth=31", "sprocket.flank_radius_mm=60", "sprocket.seating_angle_deg=121",
                            "sprocket.tip_over_pitch_mm=2", "sprocket.initial_pitch_diameter_mm=150"),
    "z50 even": ("sprocket.teeth=50",),
}


@pytest.mark.parametrize("name", list(DESIGNS))
def test_wear_limit_is_the_closed_form_inside_an_honest_bracket(template, name):
    """The reported limit is the tip mode's closed form (computed here, independently), and the
    bracket the check reports holds it and is no wider than the tolerance it claims."""
    lay = layout.track_layout(load_template(template, list(DESIGNS[name])).params)
    gap, r = lay.sprocket.gap, lay.link.sleeve_radius_mm
    w = wear.wear_limit(gap, lay.link, lay.wrap, 0.015)
    exact = closed_form_limit(gap, r)
    assert w.mode == "tip"
    assert w.lo <= exact <= w.fail_at, (w.lo, exact, w.fail_at)
    assert 0 < w.fail_at - w.lo <= w.tolerance == wear.WEAR_BISECTION_TOL
    assert w.limit == pytest.approx(exact, rel=0, abs=1e-12) and w.closed_form
    text = w.bracket_text()
    assert "closed form" in text and f"{100 * w.lo:.6f}" in text and f"{100 * w.fail_at:.6f}" in text


def test_exact_section_within_its_sagitta(lay):
    """The worn-pitch sweep's polyline distances lie within its stated sagitta of a far finer
    outline's (the bound the sweep mode's bracket is widened by)."""
    from gearcheck.geometry.track_section import ExactSection

    gap, link = lay.sprocket.gap, lay.link
    coarse = ExactSection(gap, link)
    fine = ExactSection(gap, link, step_mm=0.002)
    for e in (0.0, 0.015):
        c = wear.sweep_check(gap, link, lay.wrap, e, exact=coarse)
        f = wear.sweep_check(gap, link, lay.wrap, e, exact=fine)
        assert abs(c.min_sleeve_mm - f.min_sleeve_mm) <= coarse.sagitta_mm
        assert abs(c.min_plate_mm - f.min_plate_mm) <= coarse.sagitta_mm
    # certainly clear (by the sagitta) at the declared wear; not certainly clear with a margin past the least
    assert wear.sweep_clear(gap, link, lay.wrap, 0.015, margin_mm=coarse.sagitta_mm)
    least = wear.sweep_check(gap, link, lay.wrap, 0.015).min_sleeve_mm
    assert not wear.sweep_clear(gap, link, lay.wrap, 0.015, margin_mm=least + 1e-6)


def test_sweep_check_reads_the_sweep_table_as_computed(lay):
    """The worn-pitch sweep check at β/30 steps reads the rows of the sweep's exact table (β/60
    steps: every other angle, the same numbers); the figures are those it computes itself."""
    from gearcheck.mechanisms.track import clearance
    from gearcheck.mechanisms.track.assembly import TrackModel

    model = TrackModel(lay.sprocket.gap, lay.wrap, lay.link, 0.75, 0.5, 1.0, 0.015)
    worn = clearance.worn_model(model)
    angles = clearance.sweep_angles(model.wrap)
    tables = [(m.wrap, angles, clearance.exact_table(m, angles)) for m in (model, worn)]
    gap, link = lay.sprocket.gap, lay.link
    for e in (0.0, 0.015):
        w = wear.worn_wrap(lay.wrap.teeth, link.pitch_mm, e, lay.wrap)
        before = int(np.ceil(wear.WORN_SWEEP_MARGIN_FRACTION * wear.WORN_SWEEP_STEPS_PER_CYCLE))
        coarse = np.arange(-before, wear.WORN_SWEEP_STEPS_PER_CYCLE + before + 1) * w.cycle_rad \
            / wear.WORN_SWEEP_STEPS_PER_CYCLE
        assert wear._table_rows(tables, w, coarse) is not None
        assert wear.sweep_check(gap, link, lay.wrap, e, tables=tables) == wear.sweep_check(gap, link, lay.wrap, e)
    # another wrap or other angles are not read from a table
    assert wear._table_rows(tables, wear.worn_wrap(lay.wrap.teeth, link.pitch_mm, 0.02, lay.wrap), angles) is None
    assert wear._table_rows(tables, model.wrap, angles + 1e-9) is None
    assert wear.wear_limit(gap, link, lay.wrap, 0.015, tables=tables) == wear.wear_limit(gap, link, lay.wrap, 0.015)


def test_sweep_clear_decides_as_the_full_sweep_check(lay, limit):
    """The bisection's clear/not-clear (measuring only what can decide it) is the full check's,
    for chains pulled into the teeth (not clear), new, worn to the declared wear and the limit,
    and worn far past it."""
    gap, link = lay.sprocket.gap, lay.link
    for e in (-0.03, -0.005, -0.001, 0.0, 0.015, limit.limit, limit.fail_at, 0.05, wear.WEAR_BRACKET_MAX):
        assert wear.sweep_clear(gap, link, lay.wrap, e) == wear.sweep_check(gap, link, lay.wrap, e).ok, e


def test_wear_field_range_and_default(template):
    assert load_template(template).params.chain.wear_elongation_pct == 1.5
    with pytest.raises(ParamError):
        load_template(template, ["chain.wear_elongation_pct=-1"])
    with pytest.raises(ParamError):
        load_template(template, ["chain.wear_elongation_pct=30"])


# --- the check (sweep, cad) ------------------------------------------------------------------------


@pytest.mark.cad
def test_template_passes_with_the_wear_verdict_and_figures(build_bodies):
    run = build_bodies(TEMPLATE)
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, options={"steps_per_cycle": 12})
    verdicts = {v.name: v for v in result.verdicts}
    assert result.passed, [v for v in result.verdicts if not v.passed]
    assert verdicts["chain_wear_within_limit"].passed
    s = result.summary
    assert s["wear_elongation_pct"] == 1.5
    assert s["wear_limit_pct"] == pytest.approx(WEAR_LIMIT_PCT, abs=WEAR_LIMIT_TOL_PCT)
    assert wear.MODES[s["wear_limit_mode"]] == "tip" and s["wear"]["limit_mode_tip"] == 1
    assert s["wear"]["declared_seats"] == 1 and s["wear"]["declared_sweep_clear"] == 1
    # the mesh sweep of the worn chain (same link meshes at pitch p·1.015) confirms the exact sweep
    w = s["wear"]
    assert w["mesh_confirms_declared_sweep"] == 1 and w["mesh_declared_collisions"] == 0
    assert w["mesh_declared_max_deviation_mm"] <= s["mesh_error_bound_mm"]
    assert w["mesh_declared_min_sleeve_mm"] > s["min_tooth_sleeve_clearance_mm"]  # the worn chain rides higher
    assert w["mesh_declared_min_plate_mm"] > s["min_tip_plate_distance_mm"]


@pytest.mark.cad
def test_declared_wear_above_the_limit_fails_with_exit_1(template, tmp_path):
    out = tmp_path / "worn"
    proc = subprocess.run([sys.executable, "-m", "gearcheck", "check", str(template), "--set",
                           "chain.wear_elongation_pct=2", "--out", str(out), "--jobs", "1"],
                          check=False, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 1, proc.stderr
    s = json.loads((out / "summary.json").read_text())["track"]
    assert s["verdicts"]["chain_wear_within_limit"] == 0
    assert all(v == 1 for k, v in s["verdicts"].items() if k != "chain_wear_within_limit")
    assert s["wear_elongation_pct"] == 2.0
    assert s["wear_limit_pct"] == pytest.approx(WEAR_LIMIT_PCT, abs=WEAR_LIMIT_TOL_PCT)
    assert s["wear"]["declared_seats"] == 0
    line = next(ln for ln in proc.stdout.splitlines() if "declared chain wear" in ln)  # one line, the shortfall
    assert "fail" in line.lower() and "declared wear 2.000 %, limit 1.656" in line and "…" not in line
    assert "declared 2.000 %, limit 1.656" in s["verdict_measured"]["chain_wear_within_limit"]  # the sentence


# --- labels --------------------------------------------------------------------------------------


def _calc(template, *overrides):
    return {f.key: f for f in calc(load_template(template, list(overrides)).params)}


def test_paper_values_beside_the_paper_design_only(template):
    paper = _calc(template)
    assert paper["pitch_diameter_mm"].paper == 234.6 and paper["max_drive_force_N"].paper == 234.0
    assert paper["teeth_for_initial_pitch_diameter"].note == "rounded up to the odd z = 49"
    assert "within 1 % of 234 N" in paper["max_drive_force_N"].note

    other = _calc(template, "sprocket.teeth=51", "chain.pitch_mm=25")
    assert all(f.paper is None for f in other.values())  # one rule: another design shows no paper value
    assert "234" not in other["max_drive_force_N"].note and "paper requires" not in other["tip_gap_mm"].note
    z = other["teeth_for_initial_pitch_diameter"]
    assert z.value == pytest.approx(57.69, abs=0.005)
    assert "rounded" not in z.note and "51" in z.note and "59" in z.note
    # g is a reading of the paper (its 234 N implies 10), and the template's own choices (marked
    # "chosen") are not the paper's: either may differ on the paper's design
    assert _calc(template, "robot.g_m_s2=9.81")["max_drive_force_N"].paper == 234.0
    assert _calc(template, "sprocket.seating_radius_mm=4.15")["pitch_diameter_mm"].paper == 234.6
    heavier = _calc(template, "robot.mass_kg=200")
    assert all(f.paper is None for f in heavier.values()) and "234" not in heavier["max_drive_force_N"].note


def test_paper_values_in_calc_json_only_for_the_paper_design(template, capsys):
    assert main(["calc", str(template), "--json", "--set", "sprocket.teeth=51", "--set", "chain.pitch_mm=25",
                 "--set", "robot.mass_kg=200"]) == 0
    data = json.loads(capsys.readouterr().out)["track"]
    assert "paper" not in data


def test_calc_shows_the_declared_wear_and_the_closed_form_limit(template):
    f = _calc(template)
    assert f["wear_elongation_pct"].value == 1.5
    assert f["wear_limit_tip_pct"].value == pytest.approx(WEAR_LIMIT_PCT, abs=WEAR_LIMIT_TOL_PCT)
    assert f["wear_limit_tip_pct"].note.startswith("pass")
    assert _calc(template, "chain.wear_elongation_pct=2")["wear_limit_tip_pct"].note.startswith("FAIL")


def test_sprocket_speed_from_the_chain_advance_per_turn(template):
    """Every other tooth engages: z/2 links of p pass per turn (735 mm at z = 49), not π·d
    (737.0 mm): 122.45 rpm at 1.5 m/s instead of 122.12 (π·d read 0.27 % slow)."""
    f = _calc(template)
    d = f["pitch_diameter_mm"].value
    rpm = f["sprocket_speed_rpm"].value
    assert rpm == pytest.approx(1.5 * 60_000 / (49 * 30 / 2), rel=1e-12)
    assert rpm == pytest.approx(122.449, abs=1e-3)
    assert 1.5 * 60_000 / (math.pi * d) / rpm - 1 == pytest.approx(-0.00274, abs=1e-4)


def test_assembly_carries_the_declared_wear(template):
    """The assembly carries the declared wear to the sweep (fraction); the worn wrap puts the seated
    pins on R·(1 + e), p·(1 + e) apart."""
    model = get("track").assembly(load_template(template, ["chain.wear_elongation_pct=2"]).params).layout
    assert model.wear_elongation == pytest.approx(0.02)
    w = wear.worn_wrap(model.wrap.teeth, model.wrap.pitch_mm, 0.02, model.wrap)
    pins = w.pin_positions(0.0)
    seated = np.flatnonzero(w.seated_pins(0.0))
    assert np.hypot(*pins[seated].T) == pytest.approx(model.gap.pitch_radius_mm * 1.02, rel=1e-12)
    assert np.hypot(*(pins[1:] - pins[:-1]).T) == pytest.approx(30.0 * 1.02, rel=1e-12)
