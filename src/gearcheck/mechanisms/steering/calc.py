"""`gearcheck calc` for the nose-wheel steering: the paper's design figures from a consistent
model (closed forms on the line of action plus the exact-polyline towing push model) beside the
paper's printed values. Reconstruction and every paper slip: docs/steering.md.
"""

from __future__ import annotations

import dataclasses
import math

from gearcheck.figures import Figure
from gearcheck.geometry.rack_pinion_contact import stop_phrase, whole_drive
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering.params import Params


def _deg(rad: float) -> float:
    return math.degrees(rad)


def calc(params: Params) -> list[Figure]:
    """The figures `gearcheck calc` prints (numpy/scipy only)."""
    P = an.PAPER
    g = an.geometry_from_params(params)
    first_k, first_j = g.rack_first_tooth, g.sector_first_tooth
    H, h, rs1 = g.centre_height, g.rolling_line_height, g.topped_radius_mm
    tan_a = math.tan(g.pressure_angle_rad)

    # --- trimming design chain (solved) and the machined travels ---------------------------
    design = an.solve_trims(g, params.trim.min_contact_ratio, math.radians(params.targets.continuous_drive_deg))
    travel_s3s4 = an.travel_corner_on_circle(g, first_k + 1, g.hS4_mm, g.tip_radius)
    travel_s1s2 = an.travel_corner_on_circle(g, first_k, g.hS2_mm, rs1)

    # --- tangent constructions for hS8 / hS6 -----------------------------------------------
    s4_on_tip_circle = g.trim_corners(travel_s3s4)["S4"]
    s2_on_rs1_circle = g.trim_corners(travel_s1s2)["S2"]
    hs8_max = an.tangent_top_height(g, s4_on_tip_circle, first_k + 1, travel_s3s4)
    hs8_half = an.tangent_top_height(g, s4_on_tip_circle, first_k + 1, travel_s3s4, flank_through_centre=True)
    hs6_max = an.tangent_top_height(g, s2_on_rs1_circle, first_k, travel_s1s2)
    hs6_half = an.tangent_top_height(g, s2_on_rs1_circle, first_k, travel_s1s2, flank_through_centre=True)
    # The paper evaluated its S2 tangent at x = B, the first tooth's centre when eq (4) holds.
    b_x = travel_s3s4 + first_k * g.pitch
    hs6_at_b = s2_on_rs1_circle[1] + s2_on_rs1_circle[0] / (H - s2_on_rs1_circle[1]) * (b_x - s2_on_rs1_circle[0])

    # --- engagement angles -------------------------------------------------------------------
    phi_s1 = an.phi_towing_conjugate_end(g, first_j)
    phi_s6 = an.phi_power_conjugate_end(g, first_k, g.hS6_mm)
    phi_s6_paper = an.phi_power_conjugate_end(g, first_k, hs6_half)
    towing_drive, power_drive = whole_drive(g)
    drive = min(towing_drive, power_drive, key=lambda d: d.angle_rad)  # towing and power, every hand-over
    continuous = drive.angle_rad

    # --- towing push model -----------------------------------------------------------------
    max_deg = params.towing.max_angle_deg
    adams = (P["adams_disengage_deg"],) if an.is_paper_design(params) else ()  # as the sweep's model
    tow = an.analyse_towing(g, max_deg, extra_deg=an.CHECK_ANGLES_DEG + adams)
    dis_deg = _deg(tow.disengage_rad)

    def travel_at(angle_deg: float) -> float:
        return an.travel_on_curve(tow, math.radians(angle_deg)) if angle_deg <= max_deg else math.nan

    # --- sensitivities (closed forms, central differences) ---------------------------------
    d = 1e-3
    g_up, g_dn = an.with_inputs(g, topped_radius_mm=rs1 + d), an.with_inputs(g, topped_radius_mm=rs1 - d)
    dtravel_drs1 = (an.disengage_closed_form(g_up)[1] - an.disengage_closed_form(g_dn)[1]) / (2 * d)
    dphi_drs1 = _deg(an.disengage_closed_form(g_up)[0] - an.disengage_closed_form(g_dn)[0]) / (2 * d)
    dphi_dhs6 = _deg(an.phi_power_conjugate_end(g, first_k, g.hS6_mm + d)
                     - an.phi_power_conjugate_end(g, first_k, g.hS6_mm - d)) / (2 * d)

    beyond = "rack still moving at towing.max_angle_deg" if math.isnan(dis_deg) else ""
    F = Figure
    figures = [
        # geometry
        F("pitch_radius_mm", "pitch radius r = m·z/2", g.pitch_radius, "mm",
          note="paper: H − h = 107 − 23 = 84 needs m = 4 (not 5)"),
        F("tip_radius_mm", "tip radius Ra", g.tip_radius, "mm", note="line (10) gives 88.00"),
        F("rack_pitch_line_mm", "rack pitch line h = H − r", h, "mm"),
        F("reference_contact_radius_mm", "OS: contact radius at angle 0 (fig. 7)", an.reference_contact_radius(g), "mm",
          paper=P["OS_mm"], note="misprint of 82.84"),
        # contact ratio and the solved trims
        F("contact_ratio", "contact ratio ε at the machined hS4", an.contact_ratio(g, g.hS4_mm), "1", digits=4,
          note=f"design rule ε ≥ {params.trim.min_contact_ratio:g}"),
        F("hS4_mm", "hS4 solved from ε = trim.min_contact_ratio", design.hS4_mm, "mm", paper=P["hS4_mm"]),
        F("travel_S3S4_mm", "L when S3 meets S4, machined hS4 (eq 3)", travel_s3s4, "mm", paper=P["travel_S3S4_mm"]),
        F("travel_S3S4_solved_mm", "L when S3 meets S4, solved hS4 (eq 3)", design.travel_S3S4_mm, "mm",
          paper=P["travel_S3S4_mm"]),
        F("RS1_solved_mm", "RS1 solved: S1 engages at the target angle", design.RS1_mm, "mm",
          paper=P["RS1_from_S1_mm"],
          note="no RS1 up to Ra reaches the target" if math.isnan(design.RS1_mm)
          else "60° = 7 pitches gives RS1 = OS; paper's lost (5)-(7) gave 84.294 (φS1 62.67°)"),
        F("hS2_solved_mm", "hS2 solved: S1 meets S2 at the S3/S4 travel (eq 4)", design.hS2_mm, "mm",
          paper=P["hS2_mm"],
          note="no hS2 up to the rack top gives equal travel"
          if math.isnan(design.hS2_mm) and not math.isnan(design.RS1_mm)
          else "paper set hS2 = hS4 'for machining'"),
        F("RS1_equal_travel_mm", "RS1 giving equal travel at the machined hS2 (eq 4)",
          design.RS1_equal_travel_at_machined_hS2_mm, "mm", paper=P["RS1_from_S1_mm"],
          note="eq (4) as printed needs S1x = 19.69; the printed S1x is 20.07"),
        # tangent constructions
        F("hS8_max_mm", "largest hS8: tip-circle tangent at S4 meets the real flank", hs8_max, "mm",
          paper=P["hS8_mm"],
          note="paper drew flank S8S9 through the tooth centre (half a tooth off)"),
        F("hS8_half_tooth_mm", "hS8 by the paper's construction (flank through centre)", hs8_half, "mm",
          paper=P["hS8_mm"]),
        F("hS6_max_mm", "largest hS6: RS1-circle tangent at S2 meets the real flank", hs6_max, "mm",
          paper=P["hS6_mm"],
          note="paper read its S2 tangent at x = B"),
        F("hS6_half_tooth_mm", "hS6 by the paper's lines (13), (16) (flank through centre)", hs6_half, "mm",
          note="what the paper's 62.11° and αS6 = 21.42° correspond to"),
        F("hS6_read_at_B_mm", "hS6 as printed: S2 tangent read at x = B", hs6_at_b, "mm", paper=P["hS6_mm"]),
        # engagement angles
        F("phi_S1_deg", "S1 engagement: G1's conjugate contact ends (eq 17)", _deg(phi_s1), "deg",
          paper=P["phi_S1_deg"]),
        F("phi_S6_deg", "S6 engagement: power-mode contact ends at S6 (eq 19)", _deg(phi_s6), "deg",
          paper=P["phi_S6_deg"],
          note="paper used hS6 = 25.38 from its own lines"),
        F("phi_S6_paper_hS6_deg", "S6 engagement at the paper's-lines hS6", _deg(phi_s6_paper), "deg",
          paper=P["phi_S6_deg"]),
        F("alpha_S6_deg", "pressure angle at S6, αS6 (eq 18)", _deg(an.pressure_angle_at_power_corner(g, g.hS6_mm)),
          "deg", paper=P["alpha_S6_deg"],
          note=f"{_deg(an.pressure_angle_at_power_corner(g, hs6_half)):.2f} at the paper's-lines hS6"),
        F("continuous_drive_deg", "continuous drive to (towing and power, every hand-over)", _deg(continuous), "deg",
          paper=P["phi_S6_deg"],
          note=f"{drive.event}; ADAMS 62-63°, test {P['test_continuous_deg']:g}° (backlash, deflection)"),
        F("towing_drive_deg", "towing: continuous drive to (every hand-over)", towing_drive.angle_deg, "deg"),
        F("power_drive_deg", "power: continuous drive to (every hand-over)", power_drive.angle_deg, "deg"),
        F("continuous_margin_deg", "continuous drive beyond targets.continuous_drive_deg",
          _deg(continuous) - params.targets.continuous_drive_deg, "deg",
          note="≥ 0: power-steering requirement met"),
        # towing push model
        F("disengage_angle_deg", "towing: rack stops for good (full disengage)", dis_deg, "deg",
          paper=P["disengage_deg"],
          note=beyond or f"paper adds −(hS2 − h)·tanα/r; ADAMS {P['adams_disengage_deg']:g}°, "
                         f"test {P['test_disengage_deg']:g}°"),
        F("disengage_angle_paper_bookkeeping_deg", "disengage with the paper's extra −(hS2 − h)·tanα/r",
          dis_deg - _deg((g.hS2_mm - h) * tan_a / g.pitch_radius), "deg", paper=P["disengage_deg"]),
        F("rack_travel_at_disengage_mm", "towing: rack travel where it stops (eq 22)", tow.travel_at_disengage_mm, "mm",
          paper=P["travel_disengage_mm"],
          note=beyond or f"S1 rounded: RS1 84.298 gives 110.20; ADAMS {P['adams_travel_mm']:g}, "
                         f"test {P['test_travel_mm']:g}"),
        F("grazing_span_deg", f"{stop_phrase(g, tow.last_pusher)} at zero clearance for"
          if tow.last_pusher else "tip land grazes the stop corner at zero clearance for",
          _deg(tow.grazing_end_rad - tow.disengage_rad), "deg",
          note=beyond or ("S2 lies on the RS1 circle by design" if tow.last_pusher == (first_j, first_k)
                          else "the stop corner lies on the tip circle that passes over it")),
        F("reengage_angle_deg", "return swing picks the rack up at", _deg(tow.reengage_rad), "deg",
          note=beyond or "S6 met by the next tooth's trailing flank"),
        F("towing_travel_mm_at_068deg", "towing curve L(68°)", travel_at(68.0), "mm"),
        F("towing_travel_mm_at_072deg", "towing curve L(72°)", travel_at(72.0), "mm"),
        F("towing_travel_mm_at_075deg", "towing curve L(75°)", travel_at(75.0), "mm"),
        F("towing_travel_mm_at_adams_angle", f"towing curve at ADAMS's {P['adams_disengage_deg']}°",
          travel_at(P["adams_disengage_deg"]), "mm",
          paper=P["adams_travel_mm"], note="ADAMS's disengage lies on this curve"),
        F("towing_travel_mm_at_max_angle", "towing curve at towing.max_angle_deg", float(tow.forward.travel_mm[-1]),
          "mm"),
        F("towing_max_overlap_mm", "deepest tooth overlap, both swings (interference)",
          max(tow.forward.max_overlap_mm, tow.back.max_overlap_mm), "mm",
          digits=6, note="0: no interference; flanks touch at zero clearance"),
        # sensitivities
        F("dtravel_dRS1", "sensitivity dL(disengage)/dRS1", dtravel_drs1, "mm/mm", digits=2),
        F("ddisengage_dRS1_deg_per_mm", "sensitivity dφ(disengage)/dRS1", dphi_drs1, "deg/mm", digits=2),
        F("dphiS6_dhS6_deg_per_mm", "sensitivity dφS6/dhS6", dphi_dhs6, "deg/mm", digits=2),
    ]
    if an.is_paper_design(params):
        return _without_missing(figures, params, tow)
    # another design: no printed targets, no notes about the paper's figures, no sample at ADAMS's angle
    keep = {"contact_ratio", "continuous_margin_deg", "towing_max_overlap_mm", "grazing_span_deg",
            "travel_S3S4_solved_mm", "reengage_angle_deg"}
    out = []
    for f in figures:
        if f.key == "towing_travel_mm_at_adams_angle":
            continue
        note = f.note
        if f.key == "continuous_drive_deg":
            note = drive.event
        elif f.key not in keep and note != beyond:
            note = ""
        out.append(dataclasses.replace(f, paper=None, note=note))
    return _without_missing(out, params, tow)


# Where a figure without a value is accounted for in the table: the row whose note says why (the
# solved trims beside the solved L(S3/S4) the solver starts from, the towing figures beside the
# travel at the end of the swing, which always has one).
TRIM_KEYS = ("RS1_solved_mm", "hS2_solved_mm")
TOWING_KEYS = ("disengage_angle_deg", "disengage_angle_paper_bookkeeping_deg", "rack_travel_at_disengage_mm",
               "grazing_span_deg", "reengage_angle_deg", "towing_travel_mm_at_068deg",
               "towing_travel_mm_at_072deg", "towing_travel_mm_at_075deg", "towing_travel_mm_at_adams_angle")


def _why_missing(key: str, params: Params, tow) -> str:
    """Why the model has no value for ``key`` (a figure of :func:`calc`)."""
    max_deg = params.towing.max_angle_deg
    if key.startswith("towing_travel_mm_at_"):
        return f"beyond towing.max_angle_deg = {max_deg:g}°"
    why = {"RS1_solved_mm": "no RS1 up to Ra reaches the target",
           "hS2_solved_mm": "no hS2 up to the rack top gives equal travel",
           "reengage_angle_deg": "the return swing never picks the rack up again"}
    if key in why:
        return why[key]
    if math.isnan(tow.disengage_rad):
        return f"the rack is still moving at towing.max_angle_deg = {max_deg:g}°"
    if key == "grazing_span_deg":
        return "the tip land still touches the stop corner at the end of the swing"
    return "the model has no value for this design"


def _without_missing(figures: list[Figure], params: Params, tow) -> list[Figure]:
    """The figures with a value; each one without (NaN) is left out — calc --json has no null — and
    named with its reason in the note of the row that accounts for it (the row before it when none
    does): "label, label: — (why)"."""
    anchors = {key: "travel_S3S4_solved_mm" for key in TRIM_KEYS}
    anchors.update({key: "towing_travel_mm_at_max_angle" for key in TOWING_KEYS})
    missing: dict[str, dict[str, list[str]]] = {}  # anchor → why → labels
    kept: list[Figure] = []
    for f in figures:
        if math.isfinite(f.value):
            kept.append(f)
            continue
        anchor = anchors.get(f.key) or (kept[-1].key if kept else "")
        missing.setdefault(anchor, {}).setdefault(_why_missing(f.key, params, tow), []).append(f.label)
    out = []
    for f in kept:
        extra = [f"{', '.join(labels)}: — ({why})" for why, labels in missing.get(f.key, {}).items()]
        out.append(dataclasses.replace(f, note="; ".join(filter(None, [f.note, *extra]))) if extra else f)
    return out
