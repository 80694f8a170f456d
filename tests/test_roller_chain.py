"""The roller-chain drive (ISO 606), numpy only: the chain table, the tooth form between the
standard's limits, the wrap's kinematics and polygon effect, the wear limit against an independent
calculation written here, the template's rules (every broken one named at once) and `gearcheck
new`'s derived values recomputed here from the standard's formulas."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.drafting import draft
from gearcheck.geometry import iso606_chains as iso
from gearcheck.geometry import roller_chain as rc
from gearcheck.params import ParamError, ParamErrors

TEMPLATE = "templates/roller_chain_12B_z21.toml"


def test_table_holds_the_b_and_a_series_with_iso_606_values():
    assert [d for d in iso.DESIGNATIONS if d.endswith("B")] == ["05B", "06B", "08B", "10B", "12B", "16B", "20B",
                                                                 "24B", "28B", "32B"]
    assert [d for d in iso.DESIGNATIONS if d.endswith("A")] == ["08A", "10A", "12A", "16A", "20A", "24A", "28A",
                                                                 "32A"]
    c = iso.chain("12b-1")
    assert (c.pitch_mm, c.roller_diameter_mm, c.inner_width_mm, c.pin_diameter_mm, c.plate_depth_mm,
            c.transverse_pitch_mm) == (19.05, 12.07, 11.68, 5.72, 16.13, 19.46)
    assert iso.chain("16A").pitch_mm == 25.4 and iso.chain("16A").roller_diameter_mm == 15.88
    for d in iso.DESIGNATIONS:  # the number is the pitch in sixteenths of an inch (05B: 8 mm)
        c = iso.chain(d)
        assert c.pitch_mm == pytest.approx(8.0 if d == "05B" else int(d[:2]) * 25.4 / 16, abs=1e-9)
        assert c.pin_diameter_mm < c.roller_diameter_mm < c.plate_depth_mm and c.inner_width_mm < c.transverse_pitch_mm
    with pytest.raises(KeyError):
        iso.chain("13B")


@pytest.mark.parametrize("z", [9, 17, 21, 60, 150])
def test_tooth_form_spans_the_standards_limits(z):
    d1 = 12.07
    lo, hi = iso.tooth_form(d1, z, 0.0), iso.tooth_form(d1, z, 1.0)
    # ISO 606: minimum tooth gap (ri min, the flatter flank 0.008·d1·(z² + 180), α max) and
    # maximum tooth gap (ri max, the rounder flank 0.12·d1·(z + 2), α min)
    assert lo.seating_radius_mm == pytest.approx(0.505 * d1)
    assert hi.seating_radius_mm == pytest.approx(0.505 * d1 + 0.069 * d1 ** (1 / 3))
    assert lo.flank_radius_mm == pytest.approx(0.008 * d1 * (z * z + 180))
    assert hi.flank_radius_mm == pytest.approx(0.12 * d1 * (z + 2))
    assert lo.seating_angle_deg == pytest.approx(140 - 90 / z) and hi.seating_angle_deg == pytest.approx(120 - 90 / z)
    mid = iso.tooth_form(d1, z, 0.25)
    assert mid.seating_radius_mm == pytest.approx(0.75 * lo.seating_radius_mm + 0.25 * hi.seating_radius_mm)
    d = 19.05 / math.sin(math.pi / z)
    expected = (d + 19.05 * (1 - 1.6 / z) - d1, d + 1.25 * 19.05 - d1)
    assert iso.tip_diameter_range(19.05, d1, z) == pytest.approx(expected)


def _wrap(z=21, p=19.05):
    return rc.RollerWrap.centred(z, p)


@pytest.mark.parametrize("z", [9, 10, 21, 40])
def test_wrap_seats_every_roller_in_a_groove_and_keeps_the_pitch(z):
    w = _wrap(z)
    r = w.pitch_radius_mm
    for theta in np.linspace(0.0, 2 * w.cycle_rad, 23):
        c = w.centres(theta)
        assert np.allclose(np.hypot(*np.diff(c, axis=0).T), 19.05, atol=1e-9)
        seated = w.seated(theta)
        assert seated.sum() >= z // 2 + 1
        local = w.in_sprocket_frame(theta)[seated]
        assert np.allclose(np.hypot(*local.T), r, atol=1e-9)
        k = np.arctan2(local[:, 1], local[:, 0]) / (2 * math.pi / z)
        assert np.allclose(k, np.round(k), atol=1e-9)  # on a groove's centre line
        for m in w.link_matrices(theta):
            assert np.allclose(m[:3, :3].T @ m[:3, :3], np.eye(3), atol=1e-12)
        # spans horizontal, over the top to +x and under the bottom to +x
        a_out, a_in = w.anchors(theta)
        assert np.allclose(c[a_in:, 1], c[a_in, 1]) and np.all(np.diff(c[a_in:, 0]) > 0)
        assert np.allclose(c[:a_out + 1, 1], c[a_out, 1]) and np.all(np.diff(c[:a_out + 1, 0]) < 0)


@pytest.mark.parametrize("z", [9, 21, 100])
def test_top_span_speed_and_height_give_the_closed_forms(z):
    w = _wrap(z)
    r = w.pitch_radius_mm
    theta = np.linspace(0.0, 2 * w.cycle_rad, 401)
    speed = np.array([w.top_speed_ratio(t) for t in theta])
    height = np.array([w.centres(t)[-1, 1] for t in theta])
    ripple = 1 - math.cos(math.pi / z)  # independent of the module
    assert 1 - speed.min() / speed.max() == pytest.approx(ripple, rel=1e-9)
    assert height.max() - height.min() == pytest.approx(r * ripple, rel=1e-9)
    # the speed is the height's companion: x of the span moves at ω·R·sin β
    x = np.array([w.centres(t)[-1, 0] for t in theta])
    assert np.allclose(-np.gradient(x, theta)[1:-1] / r, speed[1:-1], atol=2e-3)
    assert rc.speed_ripple(z) == pytest.approx(ripple) and rc.chordal_rise(19.05, z) == pytest.approx(r * ripple)


def _independent_wear_limit(p, d1, z, form, da):
    """The elongation at which the roller's first contact reaches the tip corner, from scratch:
    the tooth gap's arcs solved here (not with gearcheck's solver), then R·(1 + e) = |C + r·n|."""
    ri = 0.505 * d1 + form * 0.069 * d1 ** (1 / 3)
    re = 0.008 * d1 * (z * z + 180) + form * (0.12 * d1 * (z + 2) - 0.008 * d1 * (z * z + 180))
    alpha = math.radians(140 - 90 / z - 20 * form)
    R = p / (2 * math.sin(math.pi / z))
    u = np.array([-math.cos(alpha / 2), math.sin(alpha / 2)])
    centre = np.array([R, 0.0]) + (ri + re) * u  # flank centre
    # tip corner: the flank circle meets the tip circle; the intersection nearer the groove
    rt, dc = da / 2, float(np.hypot(*centre))
    a = (rt * rt - re * re + dc * dc) / (2 * dc)
    h = math.sqrt(rt * rt - a * a)
    base = centre / dc
    perp = np.array([-base[1], base[0]])
    corners = [a * base + h * perp, a * base - h * perp]
    corner = min(corners, key=lambda q: math.atan2(q[1], q[0]))
    n = (corner - centre) / np.hypot(*(corner - centre))
    return float(np.hypot(*(corner + d1 / 2 * n))) / R - 1.0


@pytest.mark.parametrize(("name", "z", "form"), [("12B", 21, 0.5), ("08B", 17, 0.0), ("16A", 25, 1.0),
                                                 ("05B", 9, 0.3), ("32A", 120, 0.7)])
def test_wear_limit_equals_an_independent_calculation(name, z, form):
    c = iso.chain(name)
    lo, hi = iso.tip_diameter_bounds(c.pitch_mm, c.roller_diameter_mm, z, form)
    da_lo, da_hi = iso.tip_diameter_range(c.pitch_mm, c.roller_diameter_mm, z)
    da = min(0.5 * (da_lo + da_hi), hi - 0.05 * c.pitch_mm)
    gap = iso.tooth_gap(c.pitch_mm, c.roller_diameter_mm, z, form, da)
    w = rc.wear_limit(gap, c.roller_diameter_mm / 2)
    expected = _independent_wear_limit(c.pitch_mm, c.roller_diameter_mm, z, form, da)
    assert w.limit == pytest.approx(expected, abs=2 * rc.WEAR_TOL)  # the bisection on the exact contact
    assert w.closed_form == pytest.approx(expected, rel=1e-9)
    # just below the limit the roller's first contact is on the flank, just above on the tip
    r, rp = c.roller_diameter_mm / 2, gap.pitch_radius_mm
    assert rc.first_contact(gap, r, rp * (1 + expected - 1e-5)).piece == rc.FLANK
    assert rc.first_contact(gap, r, rp * (1 + expected + 1e-5)).on_tip


def test_replacement_limit_rules():
    assert rc.replacement_limit_pct(21, False)[0] == 3.0
    assert rc.replacement_limit_pct(21, True)[0] == 1.5
    assert rc.replacement_limit_pct(100, False)[0] == pytest.approx(2.0)
    assert rc.replacement_limit_pct(150, True)[0] == pytest.approx(200 / 150)


def _data():
    return tomllib.loads(open(TEMPLATE, encoding="utf-8").read())


def test_template_rules_name_every_broken_one_at_once():
    from gearcheck.design import from_data

    data = _data()
    data["chain"]["strands"] = 2
    data["sprocket"].update(tip_diameter_mm=200.0, tooth_width_mm=30.0, bore_diameter_mm=120.0)
    with pytest.raises(ParamErrors) as exc:
        from_data(data)
    fields = [e.field for e in exc.value.errors]
    assert fields == ["sprocket.tip_diameter_mm", "sprocket.tooth_width_mm", "sprocket.bore_diameter_mm"]
    assert len(str(exc.value).splitlines()) == 3 and "<138.870" in str(exc.value)
    data = _data()
    data["chain"]["designation"] = "13B"
    with pytest.raises(ParamError, match="allowed one of 05B"):
        from_data(data)


def test_cli_rejects_input_no_design_can_meet_with_exit_2(capsys):
    assert main(["calc", TEMPLATE, "--set", "sprocket.tip_diameter_mm=100.0"]) == 2
    assert "sprocket.tip_diameter_mm = 100.0: allowed >122.676 to <138.870 mm" in capsys.readouterr().err
    assert main(["new", "roller_chain", "--chain", "13B", "--teeth", "21"]) == 2
    assert main(["new", "roller_chain", "--chain", "12B", "--teeth", "8"]) == 2
    assert main(["new", "roller_chain", "--chain", "12B", "--teeth", "21", "--strands", "4"]) == 2


@pytest.mark.parametrize(("chain", "teeth", "strands"), [("08B", 17, None), ("12B", 21, None), ("16A", 25, 2)])
def test_new_derives_every_value_from_the_standard(chain, teeth, strands):
    d = draft("roller_chain", None, chain=chain, teeth=teeth, strands=strands)
    data = d.data()
    c = {"08B": (12.7, 8.51, 7.75, 11.81), "12B": (19.05, 12.07, 11.68, 16.13), "16A": (25.4, 15.88, 15.75, 24.13)}
    p, d1, b1, h2 = c[chain]
    n = strands or 1
    assert data["chain"] == {"designation": chain, "strands": n, "fixed_centres": False}
    s = data["sprocket"]
    assert s["teeth"] == teeth and s["form"] == 0.5
    # tip diameter: the middle of ISO 606's range (this form leaves a tip land there), to 0.01 mm below
    dp = p / math.sin(math.pi / teeth)
    mid = 0.5 * ((dp + p * (1 - 1.6 / teeth) - d1) + (dp + 1.25 * p - d1))
    assert mid - 0.01 < s["tip_diameter_mm"] <= mid
    # tooth width: bf1 max, 0.95·b1 simplex / 0.93·b1 duplex (p > 12.7 mm), 0.93·b1 simplex at p = 12.7
    factor = {("08B", 1): 0.93, ("12B", 1): 0.95, ("16A", 2): 0.93}[(chain, n)]
    assert factor * b1 - 0.01 < s["tooth_width_mm"] <= factor * b1
    dg = p / math.tan(math.pi / teeth) - 1.04 * h2 - 0.76
    assert s["bore_diameter_mm"] == math.floor(dg / 2)
    text = d.toml()
    assert "# middle of ISO 606's da" in text and "# ISO 606 bf1 max" in text and "ri = " in text
    design = gearcheck.load(data)
    assert design.params.sprocket.tip_diameter_mm == s["tip_diameter_mm"]


def test_new_takes_the_form_as_an_input_to_the_derivation():
    d = draft("roller_chain", ["sprocket.form=1.0"], chain="12B", teeth=21)
    s = d.data()["sprocket"]
    assert s["form"] == 1.0
    lo, hi = iso.tip_diameter_bounds(19.05, 12.07, 21, 1.0)
    assert s["tip_diameter_mm"] <= hi - 0.05 * 19.05 + 1e-9  # kept below where the rounder flanks meet
    gearcheck.load(d.data())


def test_shipped_template_is_the_new_design():
    shipped = _data()
    made = draft("roller_chain", None, chain="12B", teeth=21).data()
    assert {k: shipped[k] for k in ("chain", "sprocket")} == {k: made[k] for k in ("chain", "sprocket")}


def test_a_short_tooth_is_a_design_result_a_verdict_not_a_rejection():
    """A tip just above the seating arcs' ends is a valid (if poor) design: it loads, and the wear
    verdict fails it; a 9-tooth sprocket's speed ripple is above 2 %, a warning of `check`."""
    from types import SimpleNamespace

    from gearcheck.mechanisms.roller_chain.model import build_model
    from gearcheck.mechanisms.roller_chain.report import _wear

    design = gearcheck.load(TEMPLATE, ["sprocket.tip_diameter_mm=124.0", "chain.fixed_centres=true"])
    m = build_model(design.params)
    w = rc.wear_limit(m.gap, m.roller_radius_mm)
    assert w.limit < 0.015
    replacement, rule = rc.replacement_limit_pct(21, True)
    verdict = _wear(SimpleNamespace(wear=w, replacement_pct=replacement, replacement_rule=rule))
    assert verdict.level == "fail" and "required ≥ 1.50 %" in verdict.shortfall
    nine = gearcheck.load(TEMPLATE, ["sprocket.teeth=9", "sprocket.tip_diameter_mm=62.0",
                                     "sprocket.bore_diameter_mm=10.0"])
    assert 100 * rc.speed_ripple(9) > nine.params.drive.max_speed_ripple_pct
