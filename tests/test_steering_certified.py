"""The steering's exact model certified over the continuous motion: the closed-form clearance of a
tooth pair against brute force, the interval bounds against the motion sampled densely, a minimum
hidden between two samples caught, and on the template and a coarse grid the certified minima never
above the exact model sampled 100× finer, with the same verdicts."""

import math

import numpy as np
import pytest

from gearcheck import pipeline
from gearcheck.design import load_template
from gearcheck.geometry import rack_pinion_clearance as rc
from gearcheck.geometry.rack_pinion_power import power_corner, power_model_angle
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import certified as ce
from gearcheck.mechanisms.steering import push

TEMPLATE = "nose_wheel_steering"
COARSE_DEG = 2.0
# The exact polyline of the pinion (100 chords per involute) lies within 0.04 µm of the exact
# profile, so the polyline's clearance (brute force) can exceed the closed form by that much.
POLYLINE_MM = 5e-5


@pytest.fixture(scope="module")
def geometry(templates_dir):
    return an.geometry_from_params(load_template(templates_dir / f"{TEMPLATE}.toml").params)


def _brute(g, j, phi, k, travel, n=20000):
    """Signed clearance of the polyline tooth and the rack tooth: the best separation over many
    directions and every edge normal of both (exact for two polygons)."""
    a, b = g.pinion_contact_polygon(j, phi), g.rack_tooth_polygon(k, travel)
    psi = [np.linspace(-math.pi, math.pi, n, endpoint=False)]
    for poly, sign in ((b, -1.0), (a, 1.0)):
        d = np.roll(poly, -1, axis=0) - poly
        psi.append(rc.angle_of(sign * np.stack([d[:, 1], -d[:, 0]], axis=1)))
    e = rc.direction(np.concatenate(psi))
    return float(((e @ b.T).min(axis=1) - (e @ a.T).max(axis=1)).max())


def test_the_support_function_is_the_profiles(geometry):
    """The closed-form support of a tooth bounds its inscribed polyline from above, within the
    polyline's chord error, in every direction (the end tooth G1 is topped to RS1)."""
    d = np.linspace(-math.pi, math.pi, 4001)
    for j in (0, geometry.sector_first_tooth):
        tp = rc.ToothPairs(geometry, [(j, 0)])
        rho, gam = geometry.pinion_contact_polygon_polar(j)
        poly = (rho[None, :] * np.cos(gam[None, :] - d[:, None])).max(axis=1)
        exact = tp.h(d[:, None, None])[:, 0, 0]
        assert np.all(poly <= exact + 1e-12) and np.max(exact - poly) < POLYLINE_MM


def test_the_signed_clearance_is_exact(geometry):
    """Apart, touching and overlapping pairs at random poses around the mesh: the closed form equals
    the polygons' clearance within the polyline's error, never above it."""
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(150):
        j = int(rng.integers(-3, 3))
        k = j + int(rng.integers(-1, 3))
        phi = float(rng.uniform(-0.3, 0.3))
        travel = geometry.pitch_radius * phi + float(rng.uniform(-1.5, 1.5))
        exact = float(rc.signed_clearance(geometry, j, k, phi, travel)[0])
        brute = _brute(geometry, j, phi, k, travel)
        # the sampled directions miss a corner-to-corner one by ≤ Δψ/2: d·Δψ²/8 ≤ 1e-6 mm apart
        assert exact <= brute + 1e-6
        worst = max(worst, brute - exact)
    assert worst < POLYLINE_MM


def test_conjugate_mesh_touches_at_zero_clearance_on_both_flanks(geometry):
    """Zero backlash: at conjugate travel r·φ the tooth in mesh touches both its neighbours, at
    zero clearance to 1e-9 mm, and the interval bound between two poses 2° apart says so too."""
    tp = rc.ToothPairs(geometry, [(-1, 0), (-1, -1)])
    phis = np.radians([0.0, 2.0])
    sd, psi = tp.signed_clearance(phis, geometry.pitch_radius * phis)
    assert np.all(np.abs(sd) < 1e-9)
    r = geometry.pitch_radius
    edges = np.broadcast_to(tp.edges, (2, 4))
    bound = tp.fixed_direction_bound(phis[0], phis[1], r * phis[0], r * phis[1], edges, r, r).max(axis=-1)
    assert np.all(bound > -1e-9)
    # the path bound alone cannot show it: half a tooth's path, a third of a millimetre
    path = tp.r_tip[:, 0] * (phis[1] - phis[0]) + r * (phis[1] - phis[0])
    assert np.all(0.5 * (sd[0] + sd[1] - path) < -0.3)


@pytest.mark.parametrize("motion", ["stand", "conjugate", "drag"])
def test_the_interval_bounds_hold_against_the_motion_sampled_densely(geometry, motion):
    """Every pair's bound over an interval lies below its clearance at 200 poses inside it: the
    rack standing, in conjugate mesh, and dragged by G1's tip corner past its conjugate end."""
    g = geometry
    pairs = push.tooth_pairs(g)
    tp = rc.ToothPairs(g, pairs)
    r = g.pitch_radius
    j, k = g.sector_first_tooth, g.rack_first_tooth
    if motion == "stand":
        a0, a1 = math.radians(77.0), math.radians(80.0)

        def travel(p):
            return 110.18 + 0.0 * p
    elif motion == "conjugate":
        a0, a1 = math.radians(30.0), math.radians(33.0)

        def travel(p):
            return r * p
    else:
        a0, a1 = math.radians(63.0), math.radians(65.0)

        def travel(p):
            corner = g.pinion_tip_corner(j, p)
            return corner[..., 0] - k * g.pitch + g.rack_half_width(corner[..., 1])
    stroke = ce._Stroke(tp, np.array([a0, a1]), travel(np.array([a0, a1])), +1, "towing")
    a, b = stroke.samples
    lb, n, known = stroke.bound(a, b)
    assert known  # a stand, a conjugate pusher, a tip corner on the flank
    inside = np.linspace(a0, a1, 200)
    sd, _ = tp.signed_clearance(inside, travel(inside))
    assert lb <= float(sd.min()) + 1e-9
    assert float(sd.min()) - lb < 1e-3  # and not far below it


def test_a_minimum_between_two_samples_is_caught(geometry):
    """A rack tooth standing with its corner 0.05 mm inside the tip circle: the poses either side,
    a pitch apart, see the corner in a tooth space (clear), while a tooth sweeps over it in between.
    The samples pass; the certificate finds the overlap, its true depth, and fails."""
    g = geometry
    k, depth = 3, 0.05
    c = g.centre_to_datum_mm - g.rack_corner_heights(k)[0]
    x = math.sqrt((g.tip_radius - depth) ** 2 - c * c)
    travel = x - (k * g.pitch - float(g.rack_half_width(g.rack_corner_heights(k)[0])))
    gamma = math.atan2(x, c)
    start = gamma - 3 * g.angular_pitch  # the corner centred in a tooth space
    tp = rc.ToothPairs(g, [(j, k) for j in range(g.sector_first_tooth, g.sector_last_tooth + 1)])
    phis = np.array([start, start + g.angular_pitch])
    stroke = ce._Stroke(tp, phis, np.full(2, travel), +1, "towing")
    assert min(s.sd.min() for s in stroke.samples) > 0.3  # sampled: clear
    part = ce._certify_part(stroke, 0, 1, "stand", -ce.EXACT_TOL_MM)
    dense = np.linspace(*phis, 4001)
    truth = float(tp.signed_clearance(dense, np.full(dense.size, travel))[0].min())
    assert truth == pytest.approx(-depth, abs=0.01)
    assert part.certified_min <= truth + 1e-9 and truth - part.certified_min < 1e-3
    assert part.certified_min < -ce.EXACT_TOL_MM and part.refined > 0


def _exact_strokes(g, step_deg):
    tow = an.analyse_towing(g, 100.0)
    phis = an.towing_grid(100.0, step_deg, ())
    out = push.sweep(g, phis, 0.0, +1)
    back = push.sweep(g, phis[::-1], float(out.travel_mm[-1]), -1)
    stroke = 0.99 * power_corner(g)[2]
    travels = np.linspace(0.0, stroke, int(math.ceil(math.degrees(stroke / g.pitch_radius) / step_deg)) + 1)
    return tow, phis, out.travel_mm, back.travel_mm, travels


@pytest.mark.parametrize("step_deg", [0.25, COARSE_DEG], ids=["template", "coarse"])
def test_certified_minima_never_lie_above_the_exact_model_sampled_100_times_finer(geometry, step_deg):
    g = geometry
    tow, phis, out, back, travels = _exact_strokes(g, step_deg)
    cert = ce.certify_exact(g, phis, out, phis[::-1], back, travels, tow.disengage_rad)
    _, fine, fine_out, fine_back, fine_travels = _exact_strokes(g, step_deg / 100.0)
    tp = rc.ToothPairs(g, push.tooth_pairs(g))
    strokes = {"forward": ce._Stroke(tp, fine, fine_out, +1, "towing"),
               "back": ce._Stroke(tp, fine[::-1], fine_back, -1, "towing"),
               "power": ce._Stroke(tp, np.array([power_model_angle(g, t) for t in fine_travels]), fine_travels, -1,
                                   "power")}
    least = {}
    for name, stroke in strokes.items():
        phi = np.array([s.phi for s in stroke.samples])
        sd = np.array([s.sd.min() for s in stroke.samples])
        if name == "forward":
            least["forward"] = float(sd[phi < tow.disengage_rad].min())
            least["past"] = float(sd[phi >= tow.disengage_rad].min())
        else:
            least[name] = float(sd.min())
    for name, part in cert.parts.items():
        assert part.certified_min <= least[name] + 1e-12, name
        # the same verdict: no interference, within the exact model's tolerance, both ways
        assert part.certified_min >= -ce.EXACT_TOL_MM and least[name] >= -ce.EXACT_TOL_MM
        assert part.undecided == 0
    # the coarse grid needs the motion known between its poses: few pieces are split
    assert sum(p.refined for p in cert.parts.values()) < 100


@pytest.fixture(scope="module")
def coarse(build_bodies):
    run = build_bodies(TEMPLATE)
    return pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1,
                          options={"towing_step_deg": COARSE_DEG, "power_step_deg": COARSE_DEG}), run


@pytest.mark.cad
def test_a_coarse_check_certifies_the_same_verdicts(coarse, template_check):
    """The check on 2° steps: every interference claim reads the certified bound, and every verdict
    equals the template check's (default grid)."""
    outcome, run = coarse
    coarse_verdicts = {v.name: v.level for v in outcome.verdicts}
    fine = template_check(TEMPLATE)
    fine_verdicts = {v.name: v.level for v in fine.verdicts if v.name in coarse_verdicts}
    assert coarse_verdicts == fine_verdicts
    certified = outcome.summary["certified"]
    assert set(certified) == {"anywhere", "return_swing", "past_disengage"}
    for scope, entry in certified.items():
        assert entry["certified_min_mm"] <= entry["sampled_min_mm"] and entry["certified_min_mm"] >= -1e-4, scope
    for v in outcome.verdicts:
        if v.name.startswith("no_interference"):
            assert "certified ≥" in v.measured and "over the continuous motion" in v.measured
            assert v.evidence.startswith("exact model certified over the continuous motion")


def test_the_transmission_error_of_the_towing_swing_and_the_power_stroke(geometry):
    """TE from the exact model's motion: zero over the continuous drive (every hand-over included),
    leaving zero as the drive runs onto G1's tip corner (towing) or S6 (power mode), the rack lagging
    when it stops; back at angle 0 the return swing has brought it back with no TE."""
    from gearcheck.geometry.rack_pinion_contact import whole_drive
    from gearcheck.mechanisms.steering.tca import tca_summary

    g = geometry
    tca = tca_summary(g, an.analyse_towing(g, 100.0))
    towing, power = tca["towing"], tca["power"]
    drive_towing, drive_power = (d.angle_deg for d in whole_drive(g))
    assert towing["conjugate_te_pp_mm"] <= 1e-9 and abs(towing["conjugate_te_mean_mm"]) <= 1e-9
    assert drive_towing < towing["te_departs_deg"] < drive_towing + 1.0
    assert towing["te_at_disengage_mm"] < -0.5 and abs(towing["return_te_at_end_mm"]) <= 1e-9
    assert 0.0 < towing["contact_height_min"] < 0.5 < towing["contact_height_max"] <= 1.0
    assert drive_power < power["te_departs_deg"] < drive_power + 1.0 and power["te_at_stroke_end_mm"] < 0.0


@pytest.mark.cad
def test_the_check_reports_the_transmission_error(coarse):
    """summary.json ``tca``: the towing swing and the power stroke, as designed and under each
    mounting error (centre-distance errors of ±0.1 mm, a tilt of 0.1°)."""
    from gearcheck.mechanisms.steering.tca import CENTRE_ERRORS_MM, TILTS_DEG

    outcome, _ = coarse
    tca = outcome.summary["tca"]
    errors = {name for name, _ in CENTRE_ERRORS_MM + TILTS_DEG}
    assert set(tca) == {"towing", "power"} | errors
    assert errors == {"centre_error_0p1mm", "centre_error_m0p1mm", "tilt_0p1deg"}
    for name in errors:
        assert set(tca[name]["towing"]) >= {"conjugate_te_pp_mm", "te_departs_deg", "te_at_disengage_mm",
                                            "continuous_drive_end_deg"}
        assert tca[name]["towing"]["conjugate_te_pp_mm"] <= 1e-9
    assert tca["centre_error_0p1mm"]["fits"] and not tca["centre_error_m0p1mm"]["fits"]
