"""Track-drive sprocket: the analytical model against the paper and against theory."""

import json
import math

import numpy as np
import pytest

from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.geometry import iso606
from gearcheck.mechanisms.track import analysis, calc
from gearcheck.params import ParamError

TEMPLATE = "eod_track_drive.toml"


@pytest.fixture
def template(templates_dir):
    return templates_dir / TEMPLATE


def figures(template, *overrides):
    loaded = load_template(template, list(overrides))
    return {f.key: f.value for f in calc(loaded.params)}


def gap_of(template, *overrides):
    params = load_template(template, list(overrides)).params
    s, p = params.sprocket, params.chain.pitch_mm
    d = iso606.every_other_tooth_pitch_diameter(p, s.teeth)
    return iso606.tooth_gap(d, s.teeth, s.seating_radius_mm, s.flank_radius_mm, s.seating_angle_deg,
                            d + s.tip_over_pitch_mm)


# --- the paper's printed geometry -------------------------------------------------------------

def test_paper_diameters(template):
    f = figures(template)
    # The paper prints one decimal: ±0.1 mm covers its rounding.
    assert f["pitch_diameter_mm"] == pytest.approx(234.6, abs=0.1)
    assert f["root_diameter_mm"] == pytest.approx(226.6, abs=0.1)
    assert f["tip_diameter_mm"] == pytest.approx(235.0, abs=0.1)
    # Groove chord: 15.031 (hand check), not 15.000 (which would make the link chord 29.94).
    assert f["groove_chord_mm"] == pytest.approx(15.031, abs=5e-4)
    # Two groove steps (2·asin(chord/d) at the centre) span exactly one chain pitch.
    d = f["pitch_diameter_mm"]
    assert d * math.sin(2 * math.asin(f["groove_chord_mm"] / d)) == pytest.approx(30.0, abs=1e-9)


def test_teeth_solved_from_initial_diameter(template):
    # Paper: z = 48.03 for d ≈ 230 mm, printed to two decimals.
    assert figures(template)["teeth_for_initial_pitch_diameter"] == pytest.approx(48.03, abs=0.01)
    for z in (7, 49, 51, 301):  # the inverse really inverts eq. 6
        d = iso606.every_other_tooth_pitch_diameter(30.0, z)
        assert iso606.teeth_for_pitch_diameter(30.0, d) == pytest.approx(z, rel=1e-12)


@pytest.mark.parametrize("override, p, z", [("sprocket.teeth=51", 30.0, 51), ("chain.pitch_mm=25", 25.0, 49)])
def test_diameters_follow_z_and_pitch(template, override, p, z):
    f = figures(template, override)
    d = p / math.sin(math.radians(360.0 / z))  # eq. 6 by hand
    assert f["pitch_diameter_mm"] == pytest.approx(d, abs=1e-9)
    assert f["root_diameter_mm"] == pytest.approx(d - 8.0, abs=1e-9)
    assert f["tip_diameter_mm"] == pytest.approx(d + 0.4, abs=1e-9)
    assert f["groove_chord_mm"] == pytest.approx(d * math.sin(math.pi / z), abs=1e-9)
    assert abs(f["pitch_diameter_mm"] - 234.6) > 5  # really changed


def test_iso606_limits(template):
    f = figures(template)
    # Hand check at z = 49, dR = 8: ri 4.04–4.18, re 48.96–165.2, α 118.2°–138.2°.
    assert f["iso_seating_radius_min_mm"] == pytest.approx(4.04, abs=1e-9)
    assert f["iso_seating_radius_max_mm"] == pytest.approx(4.178, abs=1e-9)  # 4.04 + 0.069·2
    assert f["iso_flank_radius_min_mm"] == pytest.approx(48.96, abs=1e-9)
    assert f["iso_flank_radius_max_mm"] == pytest.approx(165.184, abs=1e-9)
    assert f["iso_seating_angle_min_deg"] == pytest.approx(120 - 90 / 49, abs=1e-9)
    assert f["iso_seating_angle_max_deg"] == pytest.approx(140 - 90 / 49, abs=1e-9)
    # ISO tip range beside de (reference: 241.1–245.4 with the groove chord, 255.6–264.1 with p).
    assert f["iso_tip_diameter_min_mm"] == pytest.approx(241.1, abs=0.05)
    assert f["iso_tip_diameter_max_mm"] == pytest.approx(245.4, abs=0.05)
    assert f["iso_tip_diameter_min_chain_pitch_mm"] == pytest.approx(255.6, abs=0.05)
    assert f["iso_tip_diameter_max_chain_pitch_mm"] == pytest.approx(264.1, abs=0.05)
    assert f["tip_below_iso_min_mm"] > 5  # the deliberately short tooth is flagged


# --- tooth-gap profile ------------------------------------------------------------------------

def test_profile_is_the_iso_form(template):
    gap = gap_of(template)
    prof = iso606.tooth_gap_profile(gap, step_mm=0.02)
    polar = np.arctan2(prof[:, 1], prof[:, 0])
    assert np.all(np.diff(polar) > 0)  # one pitch, counter-clockwise, no fold
    assert polar[0] == pytest.approx(-math.pi / 49) and polar[-1] == pytest.approx(math.pi / 49)
    r = np.hypot(prof[:, 0], prof[:, 1])
    # Lowest point is the seating arc bottom, ri below the pitch circle (chordal sag of 0.02 mm steps).
    assert r.min() == pytest.approx(gap.pitch_radius_mm - 4.1, abs=1e-4)
    assert r.max() == pytest.approx(gap.tip_radius_mm, abs=1e-9)
    assert gap.tip_radius_mm == pytest.approx(gap.pitch_radius_mm + 0.2, abs=1e-12)
    to_seat = np.hypot(*(prof - gap.seating_centre).T)
    on_seat = np.isclose(to_seat, 4.1, atol=1e-9)
    # The seating arc spans α = 128° about the seating centre.
    seat = prof[on_seat] - gap.seating_centre
    span = np.ptp(np.arctan2(seat[:, 1], -seat[:, 0]))
    assert math.degrees(span) == pytest.approx(128.0, abs=1e-6)
    # Flank: radius re about its centre, tangent to the seating arc at the junction.
    to_flank = np.hypot(*(prof - gap.flank_centre).T)
    assert np.sum(np.isclose(to_flank, 100.0, atol=1e-9)) > 10
    n_seat = (gap.junction - gap.seating_centre) / 4.1
    n_flank = (gap.junction - gap.flank_centre) / 100.0
    assert float(n_seat @ n_flank) == pytest.approx(-1.0, abs=1e-12)


def test_outline_repeats_every_groove(template):
    gap = gap_of(template)
    outline = iso606.sprocket_outline(gap, step_mm=0.2)
    one = len(iso606.tooth_gap_profile(gap, step_mm=0.2)) - 1
    assert len(outline) == 49 * one
    a = 2 * math.pi / 49
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    assert np.allclose(outline[:one] @ rot.T, outline[one:2 * one], atol=1e-9)


# --- track plate over the tip -----------------------------------------------------------------

@pytest.mark.parametrize("tip_gap", [0.5, 0.75, 1.0])
def test_tip_gap_reproduced(template, tip_gap):
    f = figures(template, f"track_plate.tip_gap_mm={tip_gap}")
    assert f["tip_gap_mm"] == pytest.approx(tip_gap, abs=0.01)
    # Hand check: the plate sits about gap + 1.07 mm outside the pin line.
    assert f["plate_offset_mm"] == pytest.approx(tip_gap + 1.07, abs=0.01)
    assert f["link_pin_line_radius_mm"] == pytest.approx(116.34, abs=0.01)
    assert f["tip_gap_ok"] == 1.0


def test_plate_reaches_the_tip_at_zero_gap(template):
    """Contact from both sides: the face touches the tip corner at e − gap, cuts it just below."""
    gap = gap_of(template)
    outline = iso606.sprocket_outline(gap)
    e0 = analysis.plate_offset_for_tip_gap(gap, 0.0)
    assert analysis.measured_tip_gap(outline, gap, 30.0, e0) == pytest.approx(0.0, abs=1e-9)
    assert analysis.measured_tip_gap(outline, gap, 30.0, e0 - 0.02) < -0.019
    assert analysis.measured_tip_gap(outline, gap, 30.0, e0 + 0.02) == pytest.approx(0.02, abs=1e-9)


def test_gap_outside_the_paper_window_is_reported(template):
    f = figures(template, "track_plate.tip_gap_mm=1.5")
    assert f["tip_gap_mm"] == pytest.approx(1.5, abs=0.01)
    assert f["tip_gap_ok"] == 0.0


# --- loads and strength -----------------------------------------------------------------------

def test_drive_force(template):
    # Paper: P_Kφ = 234 N; (φ − f)·G/n with g = 10 gives 232.5 N (−0.6 %).
    assert figures(template)["max_drive_force_N"] == pytest.approx(234.0, rel=0.01)
    # g = 9.81: 0.62 · 150 · 9.81 / 4 = 228.08 N.
    assert figures(template, "robot.g_m_s2=9.81")["max_drive_force_N"] == pytest.approx(228.08, abs=0.01)


def test_slope_inconsistency_flagged(template):
    f = figures(template)
    assert f["required_adhesion_for_slope"] == pytest.approx(1.08, abs=1e-9)  # tan 45° + 0.08
    assert f["slope_climbable"] == 0.0
    assert f["max_slope_by_adhesion_deg"] == pytest.approx(math.degrees(math.atan(0.62)), abs=1e-9)
    assert figures(template, "robot.slope_deg=30")["slope_climbable"] == 1.0


def test_strength(template):
    f = figures(template)
    # F = max(G/n, P_Kφ) = max(375, 232.5) N.
    assert f["design_load_N"] == pytest.approx(375.0)
    # Pin: V = 232.5/(2·2) N per support, τ = 4V/(3·π·1.5²) = 10.96 MPa.
    assert f["pin_shear_stress_MPa"] == pytest.approx(10.96, abs=0.01)
    assert f["pin_shear_ok"] == 1.0
    # Concave contact ~40–80 MPa (reference: 40–70 with b = 10.8; b = 10.2 here); convex sum far larger.
    assert 40 < f["crush_stress_MPa"] < 80
    assert f["crush_stress_chosen_groove_MPa"] < f["crush_stress_MPa"]  # ri < ri_max: more conforming
    assert 230 < f["crush_stress_convex_sum_MPa"] < 500
    assert f["contact_half_width_mm"] < 0.2 * 4.0  # a ≪ R: Hertz line contact applies
    assert f["crush_ok"] == 1.0
    # Hertz: σ ∝ sqrt(F); doubling the mass doubles F (G/n governs).
    g = figures(template, "robot.mass_kg=300")
    assert g["crush_stress_MPa"] == pytest.approx(f["crush_stress_MPa"] * math.sqrt(2), rel=1e-12)


def test_crush_fails_with_a_low_allowable(template):
    f = figures(template, "strength.allowable_crush_stress_MPa=50")
    assert f["crush_ok"] == 0.0 and f["crush_safety_factor"] < 1


# --- validation -------------------------------------------------------------------------------

@pytest.mark.parametrize(
    "override, field, allowed",
    [
        ("sprocket.teeth=6", "sprocket.teeth", "allowed 7 to 301"),
        ("chain.pitch_mm=0", "chain.pitch_mm", "allowed >0 to 500 mm"),
        ("chain.sleeve_diameter_mm=15", "chain.sleeve_diameter_mm", "allowed < 14.882 mm"),
        ("sprocket.seating_radius_mm=4.2", "sprocket.seating_radius_mm", "allowed 4.040 to 4.178 mm"),
        ("sprocket.flank_radius_mm=200", "sprocket.flank_radius_mm", "allowed 48.96 to 165.18 mm"),
        ("sprocket.seating_angle_deg=117", "sprocket.seating_angle_deg", "allowed 118.17 to 138.16°"),
        ("sprocket.tooth_width_mm=10.5", "sprocket.tooth_width_mm", "allowed <= 10.260 mm"),
        ("sprocket.nonsense=1", "sprocket.nonsense", "unknown key"),
        ('chain.pitch_mm="30 mm"', "chain.pitch_mm", "wrong type"),
        ("track_plate.tip_gap_mm=0.01", "track_plate.tip_gap_mm", "allowed 0.05 to 5 mm"),
        ("sprocket.tip_over_pitch_mm=13", "sprocket.tip_over_pitch_mm", "allowed < "),
    ],
)
def test_bad_inputs_rejected(template, override, field, allowed):
    with pytest.raises(ParamError) as info:
        load_template(template, [override])
    text = str(info.value)
    assert info.value.field == field
    assert allowed in text
    assert "\n" not in text and str(template) in text


def test_large_sleeve(template):
    # Pitch 25 with the 8 mm sleeve leaves plenty of tooth (chord 12.53 mm): valid.
    f = figures(template, "chain.pitch_mm=25")
    assert f["tip_land_width_mm"] > 1
    # A 14 mm sleeve at p = 30, z = 49: even the best ISO form (ri min, re max, α max) has its flanks
    # meet 0.08 mm above the pitch circle, under the paper's 0.4 mm tip rule.
    best = ["chain.sleeve_diameter_mm=14", "sprocket.seating_radius_mm=7.071",
            "sprocket.flank_radius_mm=289", "sprocket.seating_angle_deg=138.16"]
    with pytest.raises(ParamError) as info:
        load_template(template, best)
    assert info.value.field == "sprocket.tip_over_pitch_mm"
    assert figures(template, *best, "sprocket.tip_over_pitch_mm=0.1")["tip_land_width_mm"] > 0


# --- the mechanism ---------------------------------------------------------------------------

def test_mechanism_analyse_is_calc(template):
    from gearcheck.mechanism import get

    impl = get("track")
    assert (impl.name, impl.section, impl.template, impl.mesh_tol_mm) == ("track", "track", TEMPLATE, 0.008)
    params = load_template(template).params
    assert [(f.key, f.value) for f in impl.analyse(params)] == [(f.key, f.value) for f in calc(params)]
    assert impl.fuzz_options(params) == {} and impl.nan_figures == frozenset()


def test_mechanism_sampler_redraws_the_template(template):
    from gearcheck.mechanism import get
    from gearcheck.mechanisms.sampling import RandomDraw
    from gearcheck.params import read_toml

    base = read_toml(template)
    data = json.loads(json.dumps(base))
    get("track").sample(data, RandomDraw(1))
    assert data["mechanism"] == "track" and set(data) == set(base)
    assert data["chain"]["pitch_mm"] != base["chain"]["pitch_mm"]
    assert data["sprocket"]["teeth"] != base["sprocket"]["teeth"] or data["robot"] != base["robot"]


# --- command line -----------------------------------------------------------------------------

def test_cli_json(template, capsys):
    assert main(["calc", str(template), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)["track"]
    for key in ("pitch_diameter_mm", "root_diameter_mm", "tip_diameter_mm", "tip_gap_mm", "max_drive_force_N",
                "groove_chord_mm", "plate_offset_mm", "crush_stress_MPa", "pin_shear_stress_MPa"):
        assert isinstance(data[key], float)
    assert data["paper"]["max_drive_force_N"] == 234.0
    assert data["paper"]["pitch_diameter_mm"] == 234.6


def test_cli_bad_input_exit_2(template, capsys):
    assert main(["calc", str(template), "--set", "sprocket.teeth=5"]) == 2
    assert "sprocket.teeth = 5" in capsys.readouterr().err
