"""The steering's transmission error under mounting errors: a centre-distance error Δa (the pinion
centre Δa farther from the rack, the parts as made unchanged) and a tilt of the rack about its
travel axis. As designed the figures are the nominal ones; with Δa the involute drive stays
conjugate (flat TE, shifted by Δa·tan α), the backlash opens to 2·Δa·tan α (measured on the exact
teeth), the contact ratio falls with Δa > 0; under a tilt the face edge nearer the pinion bears."""

import math

import numpy as np
import pytest

from gearcheck.design import load_template
from gearcheck.geometry import rack_pinion as rp
from gearcheck.geometry import rack_pinion_clearance as rc
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import tca
from gearcheck.mechanisms.steering.layout import FACE_WIDTH_MM

TEMPLATE = "nose_wheel_steering"
MAX_DEG = 100.0
FLAT_MM = 1e-9  # conjugate drive: TE peak to peak, and exact figures against each other
POLYLINE_MM = 5e-5  # the push model's polyline teeth lie within 0.04 µm of the exact ones


@pytest.fixture(scope="module")
def geometry(templates_dir):
    return an.geometry_from_params(load_template(templates_dir / f"{TEMPLATE}.toml").params)


@pytest.fixture(scope="module")
def summary(geometry):
    return tca.tca_summary(geometry, an.analyse_towing(geometry, MAX_DEG))


def _flank_gaps(g: rp.RackPinionGeometry) -> np.ndarray:
    """At angle 0 and travel 0, the exact gaps (in rack travel) between pinion tooth j = −1 and its
    two rack neighbours: its right flank to rack tooth 0's left flank, its left flank to rack tooth
    −1's right flank, each the separation along the rack flank's normal over that normal's x part
    (negative: overlap)."""
    tp = rc.ToothPairs(g, [(-1, 0), (-1, -1)])
    psi = np.array([[tp.edges[0, 3]], [tp.edges[1, 1]]])
    return tp.separation(0.0, 0.0, psi)[..., 0] / np.abs(np.sin(psi[:, 0]))


def test_without_a_mounting_error_the_figures_are_the_nominal_ones(geometry, summary):
    """Δa = 0: the mounted geometry is the drawing itself, the pinion where it was, and the TE under
    no error is the nominal TE figure for figure (the push model started at −0·tan α)."""
    g = geometry
    same = tca.mounted(g, 0.0)
    assert same.centre_height == g.centre_to_datum_mm and same.rolling_line_height == g.made_rolling_line_height
    assert np.array_equal(same.pinion_blank_outline(0.3), g.pinion_blank_outline(0.3))
    assert np.array_equal(rp.pinion_pose(same, 0.3), rp.pinion_pose(g, 0.3))
    none = tca.mounting_te(g, MAX_DEG)
    for key, value in summary["towing"].items():
        if key in none["towing"]:
            assert none["towing"][key] == value, key
    for key, value in summary["power"].items():
        assert none["power"][key] == value, key
    assert none["backlash_mm"] == pytest.approx(0.0, abs=FLAT_MM) and none["fits"]
    # the template's nominal figures
    assert summary["towing"]["te_departs_deg"] == pytest.approx(62.8, abs=1e-9)
    assert summary["towing"]["te_at_disengage_mm"] == pytest.approx(-1.2531872261268262, abs=1e-9)
    assert summary["power"]["te_departs_deg"] == pytest.approx(62.58839288604652, abs=1e-9)
    assert summary["power"]["te_at_stroke_end_mm"] == pytest.approx(-3.546684103906955, abs=1e-9)


def test_a_centre_error_moves_the_pinion_and_not_the_parts(geometry):
    """Δa moves the pinion centre and the line rolling on the pitch circle; the rack's teeth, its
    trims and the pinion's own outline stay as made."""
    g, m = geometry, tca.mounted(geometry, 0.1)
    assert m.centre_height - g.centre_height == pytest.approx(0.1, abs=1e-12)
    assert m.rolling_line_height - g.rolling_line_height == pytest.approx(0.1, abs=1e-12)
    assert np.array_equal(m.rack_outline(0.7), g.rack_outline(0.7))
    shifted = g.pinion_blank_outline(0.3) + np.array([0.0, m.centre_height - g.centre_height])
    assert np.allclose(m.pinion_blank_outline(0.3), shifted, rtol=0.0, atol=1e-12)


@pytest.mark.parametrize("name, error", tca.CENTRE_ERRORS_MM)
def test_the_involute_drive_stays_conjugate_and_the_backlash_opens(geometry, summary, name, error):
    """Under Δa the TE over the continuous drive is flat (the involute–rack property), at the flank
    offset −Δa·tan α; the backlash, measured on the exact teeth at angle 0 (both flank gaps) and by
    the return swing, is 2·Δa·tan α; Δa < 0 closes it below zero: the push model finds the teeth
    overlapping by as much, and the entry says the mesh binds."""
    g, entry = geometry, summary[name]
    offset = error * math.tan(g.pressure_angle_rad)
    assert entry["towing"]["conjugate_te_pp_mm"] <= FLAT_MM
    assert entry["towing"]["conjugate_te_mean_mm"] == pytest.approx(-offset, abs=FLAT_MM)
    gaps = _flank_gaps(tca.mounted(g, error))
    assert gaps == pytest.approx([offset, offset], abs=FLAT_MM)
    assert entry["backlash_mm"] == pytest.approx(float(gaps.sum()), abs=FLAT_MM)
    assert entry["backlash_mm"] == pytest.approx(2.0 * offset, abs=FLAT_MM)
    if error > 0:
        assert entry["fits"] and entry["binds_mm"] == 0.0
    else:
        assert not entry["fits"] and entry["binds_mm"] == pytest.approx(-2.0 * offset, abs=POLYLINE_MM)
    assert np.all(np.abs(_flank_gaps(g)) <= FLAT_MM)  # as designed: zero backlash


def test_the_contact_ratio_falls_as_the_pinion_moves_away(geometry, summary):
    """Δa > 0: the rack's top corners meet the line of action later (towing) and sooner (power mode),
    so every hand-over overlaps less and the power drive, which ends at S6, ends sooner and leaves
    its flat TE sooner; the towing drive ends at G1's tip corner S1, on the pinion, where it was.
    Δa < 0 the other way."""
    nominal = {d.mode: d for d in tca.whole_drive(geometry)}
    plus, minus = summary["centre_error_0p1mm"], summary["centre_error_m0p1mm"]
    for mode in ("towing", "power"):
        overlap = math.degrees(min(end - start for end, start in nominal[mode].handovers))
        assert minus[mode]["handover_overlap_min_deg"] > overlap > plus[mode]["handover_overlap_min_deg"]
    power_end = nominal["power"].angle_deg
    assert minus["power"]["continuous_drive_end_deg"] > power_end > plus["power"]["continuous_drive_end_deg"]
    assert plus["power"]["te_departs_deg"] < summary["power"]["te_departs_deg"] < minus["power"]["te_departs_deg"]
    assert plus["towing"]["continuous_drive_end_deg"] == nominal["towing"].angle_deg
    assert minus["towing"]["continuous_drive_end_deg"] == nominal["towing"].angle_deg


@pytest.mark.parametrize("tilt", [0.1, -0.1])
def test_under_a_tilt_the_near_face_edge_bears(geometry, tilt):
    """A tilt ψ: the face edge at the smaller centre distance (w = −b/2 for ψ > 0) carries the rack in
    both modes; the drive stays flat at that edge's flank offset, and the figures are that edge's
    own (the rack travel the largest of the sections')."""
    g = geometry
    entry = tca.mounting_te(g, MAX_DEG, tilt_deg=tilt)
    near = -math.copysign(FACE_WIDTH_MM / 2.0, tilt)
    error = near * math.sin(math.radians(tilt))
    assert error < 0.0 and entry["bearing_section_w_mm"] == near
    assert entry["towing"]["conjugate_te_pp_mm"] <= FLAT_MM
    assert entry["towing"]["conjugate_te_mean_mm"] == pytest.approx(-error * math.tan(g.pressure_angle_rad),
                                                                    abs=FLAT_MM)
    edge = tca.mounting_te(g, MAX_DEG, centre_error_mm=error)
    for key in ("te_departs_deg", "te_at_disengage_mm", "continuous_drive_end_deg", "handover_overlap_min_deg"):
        assert entry["towing"][key] == pytest.approx(edge["towing"][key], abs=1e-9), key
    assert entry["power"]["continuous_drive_end_deg"] == edge["power"]["continuous_drive_end_deg"]
    assert entry["power"]["te_departs_deg"] == pytest.approx(edge["power"]["te_departs_deg"], abs=1e-9)



def test_the_api_returns_each_mechanisms_tca_as_arrays():
    """``Design.tca()`` beyond the bevel pair: the steering's TE curves (flat through the continuous
    drive, as the summary's figures say), the track's and the roller chain's polygon effect (the
    speed's ripple the closed forms give)."""
    import math

    import numpy as np

    import gearcheck
    from gearcheck.geometry import roller_chain as rcg
    from gearcheck.geometry import track_chain as tcg

    from gearcheck.geometry.rack_pinion_contact import whole_drive

    design = gearcheck.load("templates/nose_wheel_steering.toml")
    s = design.tca()
    conj = s.towing.phi_rad <= whole_drive(an.geometry_from_params(design.params))[0].angle_rad
    assert conj.sum() > 100 and np.ptp(s.towing.te_mm[conj]) <= 1e-9 < np.ptp(s.towing.te_mm)
    assert s.towing.te_mm[-1] == s.summary["towing"]["te_at_disengage_mm"]
    assert s.power.te_mm[-1] == pytest.approx(s.summary["power"]["te_at_stroke_end_mm"], abs=1e-12)
    t = gearcheck.load("templates/eod_track_drive.toml")
    p = t.tca()
    assert isinstance(p, tcg.PolygonEffect)
    assert p.ripple == pytest.approx(1 - math.cos(2 * math.pi / t.params.sprocket.teeth), abs=1e-6)
    c = gearcheck.load("templates/roller_chain_12B_z21.toml")
    got = c.tca()
    z = c.params.sprocket.teeth
    assert 1 - got["speed"].min() / got["speed"].max() == pytest.approx(rcg.speed_ripple(z), abs=1e-9)
