"""Roller-chain drive to ISO 606: a sprocket whose every tooth engages, with the standard's tooth
form anywhere between its minimum and maximum tooth gap, and a roller chain (B or A series, 1–3
strands) wrapped on it.

``calc(params)`` is the analytical model (ISO 606's formulas, the polygon effect's closed forms,
the wear limit's closed form); the mechanism (assembly, CAD hook, sweep, verdicts, report,
``gearcheck new``) is :class:`.mechanism.RollerChain`; docs/roller_chain.md has the model.
"""

from __future__ import annotations

import math

from gearcheck.figures import Figure
from gearcheck.geometry import iso606, iso606_chains
from gearcheck.geometry import roller_chain as rc
from gearcheck.mechanisms.roller_chain.model import RollerChainModel, build_model
from gearcheck.mechanisms.roller_chain.params import Params

# Meshing tolerance when --tol is not given; refined from the smallest clearance (the seated
# roller's ri − d1/2, 0.06 mm at the minimum gap of a 12B chain) by the resolution rule.
MESH_TOL_MM = 0.01


def calc(params: Params) -> list[Figure]:
    m = build_model(params)
    out = figures(m)
    dr, z, p = params.drive, m.teeth, m.size.pitch_mm
    v = z * p * dr.speed_rpm / 60_000.0
    pull = 1000.0 * dr.power_kW * dr.service_factor / v
    out += [
        Figure("chain_speed_m_s", "mean chain speed v = z·p·n / 60000", v, "m/s", None, "", 3),
        Figure("chain_speed_min_m_s", "least chain speed v·(π/z)/sin(π/z)·cos(π/z)",
               v * (math.pi / z) / math.sin(math.pi / z) * math.cos(math.pi / z), "m/s", None,
               "the span's speed at a handover (ω·R·cos(180°/z))", 3),
        Figure("chain_pull_N", "chain pull F = K·P / v", pull, "N", None, f"service factor K = {dr.service_factor:g}",
               1),
        Figure("sprocket_torque_Nm", "sprocket torque K·P / ω", 1000.0 * dr.power_kW * dr.service_factor
               / (dr.speed_rpm * math.pi / 30.0), "N·m", None, "", 2),
        Figure("max_speed_ripple_pct", "speed ripple the application allows", dr.max_speed_ripple_pct, "%", None,
               "pass" if 100 * rc.speed_ripple(z) <= dr.max_speed_ripple_pct else "exceeded: more teeth", 2),
    ]
    return out


def figures(m: RollerChainModel) -> list[Figure]:
    s, z, gap = m.size, m.teeth, m.gap
    p, d1 = s.pitch_mm, s.roller_diameter_mm
    out: list[Figure] = []

    def add(key, label, value, unit, note="", digits=3):
        out.append(Figure(key, label, float(value), unit, None, note, digits))

    add("pitch_mm", f"chain pitch p ({s.designation})", p, "mm", "ISO 606 table")
    add("roller_diameter_mm", "roller diameter d1", d1, "mm", "ISO 606 table (max)", 2)
    add("inner_width_mm", "width between inner plates b1", s.inner_width_mm, "mm", "ISO 606 table (min)", 2)
    add("pin_diameter_mm", "pin diameter d2", s.pin_diameter_mm, "mm", "ISO 606 table (max)", 2)
    add("plate_depth_mm", "inner plate depth h2", s.plate_depth_mm, "mm", "ISO 606 table (max)", 2)
    add("transverse_pitch_mm", "transverse pitch pt", s.transverse_pitch_mm, "mm", "ISO 606 table", 2)
    add("plate_thickness_mm", "plate thickness of the model t = (pt − b1)/4", s.plate_thickness_mm, "mm",
        "model: ISO 606 tabulates no plate thickness")
    add("strands", "strands", m.strands, "", digits=0)
    d = gap.pitch_radius_mm * 2.0
    add("pitch_diameter_mm", "pitch diameter d = p / sin(180°/z)", d, "mm", f"z = {z}", 3)
    add("root_diameter_mm", "root diameter df = d − d1", iso606_chains.root_diameter(p, d1, z), "mm", digits=3)
    add("seating_bottom_diameter_mm", "seating arcs' bottom d − 2·ri", d - 2 * gap.seating_radius_mm, "mm",
        "below df by 2(ri − d1/2)")
    da_lo, da_hi = iso606_chains.tip_diameter_range(p, d1, z)
    add("iso_tip_diameter_min_mm", "ISO 606 tip diameter min d + p(1 − 1.6/z) − d1", da_lo, "mm")
    add("iso_tip_diameter_max_mm", "ISO 606 tip diameter max d + 1.25p − d1", da_hi, "mm")
    add("tip_diameter_mm", "tip diameter da (template)", gap.tip_radius_mm * 2.0, "mm",
        "within ISO 606" if da_lo <= 2 * gap.tip_radius_mm <= da_hi else "outside ISO 606's range")
    lim = iso606.seating_limits(d1, z)
    add("form", "tooth form (0 minimum gap, 1 maximum gap)", m.form, "", digits=3)
    add("iso_seating_radius_min_mm", "ISO 606 ri min = 0.505·d1", lim.seating_radius_min_mm, "mm", digits=4)
    add("iso_seating_radius_max_mm", "ISO 606 ri max = 0.505·d1 + 0.069·d1^(1/3)", lim.seating_radius_max_mm, "mm",
        digits=4)
    add("seating_radius_mm", "roller seating radius ri", gap.seating_radius_mm, "mm", digits=4)
    add("iso_flank_radius_min_gap_mm", "ISO 606 re of the minimum gap 0.008·d1·(z² + 180)", lim.flank_radius_max_mm,
        "mm", "the flatter flank: the fuller tooth", 3)
    add("iso_flank_radius_max_gap_mm", "ISO 606 re of the maximum gap 0.12·d1·(z + 2)", lim.flank_radius_min_mm,
        "mm", "the rounder flank: the thinner tooth", 3)
    add("flank_radius_mm", "tooth flank radius re", gap.flank_radius_mm, "mm", digits=3)
    add("iso_seating_angle_min_deg", "ISO 606 α min = 120° − 90°/z", lim.seating_angle_min_deg, "°")
    add("iso_seating_angle_max_deg", "ISO 606 α max = 140° − 90°/z", lim.seating_angle_max_deg, "°")
    add("seating_angle_deg", "roller seating angle α", math.degrees(gap.seating_angle_rad), "°")
    add("tip_land_width_mm", "tip land width (arc)", gap.tip_land_width_mm, "mm")
    bf_max = iso606_chains.tooth_width_max(s.inner_width_mm, p, m.strands)
    add("tooth_width_mm", "tooth width bf1", m.sprocket.tooth_width_mm, "mm", digits=3)
    add("iso_tooth_width_max_mm", "ISO 606 tooth width bf1 max", bf_max, "mm", digits=3)
    add("hub_diameter_mm", "hub diameter dg = p·cot(180°/z) − 1.04·h2 − 0.76", 2 * m.sprocket.hub_radius_mm, "mm",
        "ISO 606 max; the groove floor between rows" if m.strands > 1 else "ISO 606 max (no groove: one row)")
    add("seated_roller_clearance_mm", "seated roller clearance ri − d1/2", m.seating_clearance_mm, "mm", digits=4)
    add("inner_plate_axial_gap_mm", "inner plate to tooth side (b1 − bf1)/2", m.inner_plate_gap_mm, "mm", digits=4)
    add("speed_ripple_pct", "chain speed ripple 1 − cos(180°/z)", 100 * rc.speed_ripple(z), "%", "polygon effect",
        4)
    add("chordal_rise_mm", "chordal rise R·(1 − cos(180°/z))", rc.chordal_rise(p, z), "mm", "polygon effect", 4)
    limit, rule = rc.replacement_limit_pct(z, m.fixed_centres)
    wear_limit = rc.wear_limit_closed_form(gap, m.roller_radius_mm)
    add("wear_limit_pct", "elongation at which a roller rides to the tip", 100 * wear_limit, "%",
        "closed form: R(1 + e) = |C + r·n| at the tip corner C", 3)
    add("replacement_limit_pct", "replacement elongation", limit, "%", rule, 2)
    return out


__all__ = ["MESH_TOL_MM", "Params", "calc", "figures"]
