"""Track-drive sprocket of a bomb-disposal robot for the paper's articulated track (grooves every
half pitch): ISO 606 groove form, every other tooth engaging, short tooth under the track plate;
drive force, pin shear and crush stress.

``calc(params)`` returns the figures, beside the paper's printed values (``PAPER``) for the paper's
own design only (:func:`is_paper_design`); the model and
its readings are in :mod:`.analysis` and docs/track.md. The mechanism itself (assembly, CAD hook,
sweep, verdicts, report) is :class:`.mechanism.TrackDrive`.
"""

from __future__ import annotations

import math

from gearcheck.figures import Figure
from gearcheck.geometry import iso606
from gearcheck.mechanisms.track import analysis, wear
from gearcheck.mechanisms.track.params import Params

# Meshing tolerance when --tol is not given: the mesh-error bound must stay within 1/10 of the
# least clearance checked (template: tooth–sleeve 0.100 mm, so ≤ 0.010 mm; 20 % margin).
MESH_TOL_MM = 0.008

# The paper's printed values (data for the report, never used in the model).
PAPER = {
    "teeth_for_initial_pitch_diameter": 48.03,
    "pitch_diameter_mm": 234.6,
    "root_diameter_mm": 226.6,
    "tip_diameter_mm": 235.0,
    "max_drive_force_N": 234.0,
}
# The paper's own design: every input the paper gives (as the template holds it). Its printed
# values (and the notes about them) stand beside this design only, in calc, summary.json and the
# report; beside another design they would read as targets. The template's own choices where the
# paper gives none (marked "chosen": pin segments, ri, re, α, tooth width, middle groove, tip gap,
# crush allowable, wear tolerance) and the reading of g (the paper's 234 N implies 10; 9.81 is
# shown against it on purpose) may differ.
PAPER_DESIGN = {
    "robot.mass_kg": 150.0,
    "robot.speed_m_s": 1.5,
    "robot.slope_deg": 45.0,
    "robot.tracks": 4,
    "ground.adhesion_coefficient": 0.7,
    "ground.rolling_resistance_coefficient": 0.08,
    "chain.pitch_mm": 30.0,
    "chain.sleeve_diameter_mm": 8.0,
    "chain.pin_diameter_mm": 3.0,
    "chain.sleeve_inner_width_mm": 10.8,
    "chain.pin_support_span_mm": 21.0,
    "chain.track_width_mm": 60.0,
    "sprocket.teeth": 49,
    "sprocket.initial_pitch_diameter_mm": 230.0,
    "sprocket.tip_over_pitch_mm": 0.4,
    "sprocket.tooth_rows": 2,
    "track_plate.required_gap_min_mm": 0.5,
    "track_plate.required_gap_max_mm": 1.0,
    "materials.sprocket_E_MPa": 75000.0,
    "materials.sprocket_poisson": 0.33,
    "materials.sleeve_E_MPa": 75000.0,
    "materials.sleeve_poisson": 0.33,
    "strength.pin_allowable_shear_MPa": 210.0,
    "strength.loaded_tooth_rows": 1,
}


def _input(params: Params, dotted: str) -> float:
    section, field = dotted.split(".")
    return float(getattr(getattr(params, section), field))


def is_paper_design(params: Params) -> bool:
    """The template is the paper's mechanism (every input of :data:`PAPER_DESIGN`): only then do its
    printed figures stand beside the results."""
    return all(math.isclose(_input(params, n), float(v), rel_tol=1e-12, abs_tol=1e-12)
               for n, v in PAPER_DESIGN.items())


def _whose(params: Params) -> str:
    """Who sets the tip-gap window: the paper for its own design, else the template."""
    return "paper requires" if is_paper_design(params) else "required (track_plate)"


def odd_round_up(x: float) -> int:
    """The smallest odd whole number ≥ x (the paper rounds its 48.03 up to the odd 49)."""
    n = math.ceil(x - 1e-9)
    return n if n % 2 else n + 1

# Outline sampling for the independent tip-gap measurement; corners are exact vertices anyway.
GAP_CHECK_STEP_MM = 0.05


def _verdict(ok: bool) -> tuple[float, str]:
    return (1.0 if ok else 0.0), ("pass" if ok else "FAIL")


class _Figures(list):
    """The figures in table order; ``add`` attaches the paper's value where it has one, beside the
    paper's own design only (:func:`is_paper_design`)."""

    def __init__(self, params: Params):
        super().__init__()
        self.paper = is_paper_design(params)

    def add(self, key, label, value, unit, note="", digits=3):
        paper = PAPER.get(key) if key in PAPER and self.paper else None
        self.append(Figure(key, label, float(value), unit, paper, note, digits))


def calc(params: Params) -> list[Figure]:
    F = _Figures(params)
    d, gap, lim = _geometry(params, F.add)
    _plate(params, F.add, gap)
    _wear(params, F.add, gap)
    drive, design = _loads(params, F.add, d)
    _pin(params, F.add, drive)
    _crush(params, F.add, design, lim)
    return list(F)


def _geometry(params: Params, add):
    """Eqs. 6-8: pitch, root and tip diameters; the ISO 606 form and its limits."""
    ch, sp = params.chain, params.sprocket
    z, p, dr = sp.teeth, ch.pitch_mm, ch.sleeve_diameter_mm
    z_initial = iso606.teeth_for_pitch_diameter(p, sp.initial_pitch_diameter_mm)
    d = iso606.every_other_tooth_pitch_diameter(p, z)
    df = d - dr
    de = d + sp.tip_over_pitch_mm
    chord = iso606.groove_chord(d, z)
    z_up = odd_round_up(z_initial)
    z_note = (f"rounded up to the odd z = {z}" if z == z_up
              else f"template z = {z}{'' if z % 2 else ' (even)'}, not the odd round-up {z_up} of this estimate")
    add("teeth_for_initial_pitch_diameter", f"z for d = {sp.initial_pitch_diameter_mm:g} mm (eq. 6 inverted)",
        z_initial, "", z_note, 2)
    add("pitch_diameter_mm", "pitch diameter d = p/sin(360°/z)", d, "mm",
        "every other tooth engages" + ("" if z % 2 else f"; even z: the same {z // 2} teeth take every engagement"),
        2)
    add("root_diameter_mm", "root diameter df = d − dR", df, "mm", digits=2)
    add("tip_diameter_mm", "tip diameter de = d + tip rule", de, "mm",
        f"short tooth: d + {sp.tip_over_pitch_mm:g} mm", 2)
    add("groove_chord_mm", "chord between adjacent grooves d·sin(180°/z)", chord, "mm",
        "a link spans two grooves")

    lim = iso606.seating_limits(dr, z)
    add("iso_seating_radius_min_mm", "ISO 606 seating radius ri min", lim.seating_radius_min_mm, "mm")
    add("iso_seating_radius_max_mm", "ISO 606 seating radius ri max", lim.seating_radius_max_mm, "mm")
    add("seating_radius_mm", "chosen seating radius ri (ρf)", sp.seating_radius_mm, "mm", "within ISO limits")
    add("seated_sleeve_clearance_mm", "seated sleeve clearance ri − R", sp.seating_radius_mm
        - params.chain.sleeve_diameter_mm / 2.0, "mm", "sleeve centred on its seating arc", 4)
    add("iso_flank_radius_min_mm", "ISO 606 flank radius re min", lim.flank_radius_min_mm, "mm", digits=2)
    add("iso_flank_radius_max_mm", "ISO 606 flank radius re max", lim.flank_radius_max_mm, "mm", digits=2)
    add("flank_radius_mm", "chosen flank radius re", sp.flank_radius_mm, "mm", "within ISO limits", 2)
    add("iso_seating_angle_min_deg", "ISO 606 seating angle α min", lim.seating_angle_min_deg, "°", digits=2)
    add("iso_seating_angle_max_deg", "ISO 606 seating angle α max", lim.seating_angle_max_deg, "°", digits=2)
    add("seating_angle_deg", "chosen seating angle α", sp.seating_angle_deg, "°", "within ISO limits", 2)

    tip_lo_g, tip_hi_g = iso606.iso_tip_diameter_range(d, chord, dr, z)
    tip_lo_p, tip_hi_p = iso606.iso_tip_diameter_range(d, p, dr, z)
    add("iso_tip_diameter_min_mm", "ISO 606 tip dia. min (groove chord as pitch)", tip_lo_g, "mm",
        "not applied: intended short tooth", 2)
    add("iso_tip_diameter_max_mm", "ISO 606 tip dia. max (groove chord as pitch)", tip_hi_g, "mm",
        "not applied: intended short tooth", 2)
    add("iso_tip_diameter_min_chain_pitch_mm", "ISO 606 tip dia. min (chain pitch p)", tip_lo_p, "mm",
        "not applied: intended short tooth", 2)
    add("iso_tip_diameter_max_chain_pitch_mm", "ISO 606 tip dia. max (chain pitch p)", tip_hi_p, "mm",
        "not applied: intended short tooth", 2)
    add("tip_below_iso_min_mm", "de below the ISO minimum (groove chord)", tip_lo_g - de, "mm",
        "intended: the tip must stay under the track plate", 2)

    gap = iso606.tooth_gap(d, z, sp.seating_radius_mm, sp.flank_radius_mm, sp.seating_angle_deg, de)
    add("tip_land_width_mm", "tip land width (arc)", gap.tip_land_width_mm, "mm")
    add("sleeve_flank_clearance_at_tip_mm", "seated sleeve to tip corner clearance",
        analysis.sleeve_flank_clearance_at_tip(gap, dr / 2.0), "mm", "sleeve centred on the seating centre")
    bf_max = iso606.iso_tooth_width_max(ch.sleeve_inner_width_mm, p)
    add("iso_tooth_width_max_mm", "ISO 606 tooth width bf1 max (from b1)", bf_max, "mm",
        f"chosen {sp.tooth_width_mm:g} mm")
    return d, gap, lim


def _plate(params: Params, add, gap) -> None:
    """The track plate over the tip: the plate offset for the chosen gap, the gap measured."""
    tp, p = params.track_plate, params.chain.pitch_mm
    pin_line = analysis.link_pin_line_radius(gap)
    e = analysis.plate_offset_for_tip_gap(gap, tp.tip_gap_mm)
    outline = iso606.sprocket_outline(gap, GAP_CHECK_STEP_MM)
    measured = analysis.measured_tip_gap(outline, gap, p, e)
    add("link_pin_line_radius_mm", "seated link pin line from axis, R·cos(360°/z)", pin_line, "mm")
    add("plate_offset_mm", "plate face offset e outside the pin line", e, "mm",
        f"from the chosen gap {tp.tip_gap_mm:g} mm")
    ok, word = _verdict(tp.required_gap_min_mm <= measured <= tp.required_gap_max_mm)
    add("tip_gap_mm", "tip gap to plate, measured on the outline", measured, "mm",
        f"{word}: {_whose(params)} {tp.required_gap_min_mm:g}–{tp.required_gap_max_mm:g} mm")
    add("tip_gap_ok", "tip gap within the required window (1 = pass)", ok, "", word, 0)


def _wear(params: Params, add, gap) -> None:
    """Chain wear: the declared pitch growth and the closed-form limit of the tip mode (the sleeve
    of the worn chain, on R·(1 + e), touching its driving flank at the tip corner)."""
    declared = params.chain.wear_elongation_pct
    limit = 100.0 * wear.tip_limit_closed_form(gap, params.chain.sleeve_diameter_mm / 2.0)
    add("wear_elongation_pct", "declared chain wear (pitch growth)", declared, "%", "chain.wear_elongation_pct")
    add("wear_limit_tip_pct", "wear at which the flank contact reaches the tip corner", limit, "%",
        f"{'pass' if declared <= limit else 'FAIL'}: closed form; `check` brackets it on the exact arcs and "
        "adds the jump and worn-sweep modes", 4)


def _loads(params: Params, add, d: float) -> tuple[float, float]:
    """Eq. 1: weight, drive force, the design load on one tooth; the slope."""
    r, gr = params.robot, params.ground
    weight = r.mass_kg * r.g_m_s2
    drive = analysis.drive_force_N(r.mass_kg, r.g_m_s2, gr.adhesion_coefficient,
                                   gr.rolling_resistance_coefficient, r.tracks)
    normal = weight / r.tracks
    design = max(normal, drive)
    add("weight_N", "robot weight G = m·g", weight, "N", f"g = {r.g_m_s2:g} m/s²", 1)
    drive_note = ("eq. 1 lost: (φ − f)G/n, within 1 % of 234 N at g = 10; no slope term"
                  if is_paper_design(params) else "eq. 1 lost: (φ − f)G/n; no slope term")
    add("max_drive_force_N", "max drive force per track P_Kφ = (φ − f)G/n", drive, "N", drive_note, 1)
    add("normal_load_per_track_N", "normal load per track G/n", normal, "N", "level ground (largest)", 1)
    add("design_load_N", "design load F = max(G/n, P_Kφ), one tooth", design, "N", digits=1)
    need = analysis.required_adhesion(r.slope_deg, gr.rolling_resistance_coefficient)
    climbable = gr.adhesion_coefficient >= need
    ok, word = _verdict(climbable)
    add("required_adhesion_for_slope", f"adhesion needed for {r.slope_deg:g}°: tan α + f", need, "",
        f"{word}: φ = {gr.adhesion_coefficient:g}" + ("" if climbable else " — this slope cannot be climbed"))
    add("max_slope_by_adhesion_deg", "steepest slope adhesion allows, atan(φ − f)",
        analysis.max_slope_deg(gr.adhesion_coefficient, gr.rolling_resistance_coefficient), "°", digits=1)
    add("climb_force_needed_N", f"drive force per track to climb {r.slope_deg:g}°",
        analysis.climb_force_needed_N(r.mass_kg, r.g_m_s2, r.slope_deg, gr.rolling_resistance_coefficient,
                                      r.tracks), "N", "G(sin α + f cos α)/n", 1)
    add("slope_climbable", "slope climbable by adhesion (1 = pass)", ok, "", word, 0)
    advance = analysis.chain_advance_per_turn_mm(params.chain.pitch_mm, params.sprocket.teeth)
    rpm_pi_d = r.speed_m_s * 60_000.0 / (math.pi * d)
    rpm = r.speed_m_s * 60_000.0 / advance
    add("sprocket_speed_rpm", "sprocket speed at v, v/(z·p/2)", rpm, "rpm",
        f"chain advances z/2 links = {advance:.2f} mm per turn (every other tooth engages); "
        f"v/(π·d) would give {rpm_pi_d:.2f} ({100 * (rpm_pi_d / rpm - 1):+.2f} %)", 1)
    add("drive_torque_per_track_Nm", "sprocket torque at P_Kφ", drive * d / 2000.0, "N·m", digits=2)
    add("drive_power_per_track_W", "drive power per track P_Kφ·v", drive * r.speed_m_s, "W", digits=0)
    return drive, design


def _pin(params: Params, add, drive: float) -> None:
    """Pin shear (and bending, for information) at the drive force."""
    ch, st = params.chain, params.strength
    tau = analysis.pin_shear_stress_MPa(drive, ch.pin_segments, ch.pin_diameter_mm)
    ok, word = _verdict(tau <= st.pin_allowable_shear_MPa)
    add("pin_shear_stress_MPa", "pin shear stress 4V/3A (P_Kφ)", tau, "MPa",
        f"{ch.pin_segments} simply supported segments, uniform q", 2)
    add("pin_allowable_shear_MPa", "pin allowable shear [τ]", st.pin_allowable_shear_MPa, "MPa", digits=0)
    add("pin_shear_safety_factor", "pin shear safety factor [τ]/τ", st.pin_allowable_shear_MPa / tau, "", word, 2)
    add("pin_shear_ok", "pin shear (1 = pass)", ok, "", word, 0)
    add("pin_bending_stress_MPa", "pin bending stress (info)",
        analysis.pin_bending_stress_MPa(drive, ch.pin_segments, ch.sleeve_inner_width_mm,
                                        ch.pin_support_span_mm, ch.pin_diameter_mm),
        "MPa", "span b2, load over b1; the paper checks shear only", 1)


def _crush(params: Params, add, design: float, lim) -> None:
    """Eq. 10: Hertz crush stress of the sleeve in its groove."""
    sp, st, mat = params.sprocket, params.strength, params.materials
    dr = params.chain.sleeve_diameter_mm
    sleeve_r = dr / 2.0
    length = sp.tooth_width_mm * st.loaded_tooth_rows
    elastic = (mat.sleeve_E_MPa, mat.sleeve_poisson, mat.sprocket_E_MPa, mat.sprocket_poisson)
    rho_max = lim.seating_radius_max_mm
    concave = analysis.hertz_line_contact(design, length, 1.0 / sleeve_r - 1.0 / rho_max, *elastic)
    chosen = analysis.hertz_line_contact(design, length, 1.0 / sleeve_r - 1.0 / sp.seating_radius_mm, *elastic)
    convex = analysis.hertz_line_contact(design, length, 1.0 / sleeve_r + 1.0 / rho_max, *elastic)
    ok, word = _verdict(concave.peak_pressure_MPa <= st.allowable_crush_stress_MPa)
    add("crush_stress_MPa", "crush stress, sleeve in groove (concave, ρf = ri max)", concave.peak_pressure_MPa,
        "MPa", "1/ρ = 1/R − 1/ρf; paper: largest groove for safety", 1)
    add("crush_stress_chosen_groove_MPa", "crush stress at the chosen ri (info)", chosen.peak_pressure_MPa,
        "MPa", digits=1)
    add("crush_stress_convex_sum_MPa", "crush stress if curvatures summed (alternative)",
        convex.peak_pressure_MPa, "MPa", "1/R + 1/ρf: not the physical contact; upper bound", 1)
    add("contact_half_width_mm", "Hertz contact half-width a (concave)", concave.half_width_mm, "mm",
        f"a/R = {concave.half_width_mm / sleeve_r:.2f}: line-contact Hertz applies")
    add("crush_allowable_MPa", "allowable crush stress", st.allowable_crush_stress_MPa, "MPa", digits=0)
    add("crush_safety_factor", "crush safety factor", st.allowable_crush_stress_MPa / concave.peak_pressure_MPa,
        "", word, 2)
    add("crush_ok", "crush stress (1 = pass)", ok, "", word, 0)


__all__ = ["MESH_TOL_MM", "PAPER", "PAPER_DESIGN", "Params", "calc", "is_paper_design"]
