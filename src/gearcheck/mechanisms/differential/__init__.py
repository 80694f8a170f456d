"""Bevel-gear differential of the Zhurong Mars rover: cold backlash and shims.

``calc(params)`` runs the paper's model, eqs (1)–(11) (the lost (1), (10), (11) reconstructed,
see :mod:`.analysis` and docs/differential.md), and returns figures beside the paper's numbers.
Paper values are attached only at the paper's own conditions (25 → −65 °C, 0.10 mm shim), so an
override never shows a paper number beside a figure it does not describe.
"""

from __future__ import annotations

import math

from gearcheck.figures import Figure
from gearcheck.mechanisms.differential import analysis
from gearcheck.mechanisms.differential.analysis import analyse_params
from gearcheck.mechanisms.differential.params import Params, shim_key

# Meshing tolerance when --tol is not given: the mesh-error bound must stay within 1/10 of the
# least play checked (template: 2.98′ per side cold = 35.8 µm on d1/2, so ≤ 3.6 µm).
MESH_TOL_MM = 0.003

# The paper's printed values (report data only, never used in a computation).
PAPER = {
    "cold_drop_per_side_arcmin": 3.4,  # §2: 25 → −65 °C, one big/small mesh
    "cold_drop_total_arcmin": 6.8,  # §2: both sides, output shaft 1 to output shaft 2
    "min_warm_backlash_total_arcmin": 6.8,  # §2: room-temperature backlash must be ≥ 6.8′
    "warm_backlash_total_min_arcmin": 16.8,  # §4 conclusion: 0.10 mm shim → 16.8′–18.8′
    "warm_backlash_total_max_arcmin": 18.8,
    "cold_backlash_total_min_arcmin": 10.0,  # §3.1: "still not less than 10′" (a bound)
}
PAPER_TEMPERATURE_DROP_K = 90.0  # 25 °C → −65 °C
PAPER_SHIM_MM = 0.10

__all__ = ["MESH_TOL_MM", "PAPER", "Params", "analyse_params", "calc"]


def _mm(shim_mm: float) -> str:
    """Shim thickness as in the JSON key: 0.1 → '0.10', 0.125 → '0.125'."""
    return shim_key(shim_mm).replace("p", ".")


def _paper(key: str, applies: bool) -> float | None:
    return PAPER[key] if applies else None


def calc(params: Params) -> list[Figure]:
    r = analyse_params(params)
    op = params.operating
    geom, mesh, ap, cold, design = r.geometry, r.mesh, r.approach, r.cold, r.design
    um = analysis.UM_PER_MM
    at_paper_dT = math.isclose(ap.temperature_drop_K, PAPER_TEMPERATURE_DROP_K, abs_tol=1e-9)
    at_paper_shim = math.isclose(design.shim_mm, PAPER_SHIM_MM, abs_tol=1e-9)
    printed_eq9 = "eq (9) as printed (2tanα also on the t-term)"

    figs = [
        # Cone geometry (Tredgold virtual gears on the back cone for the tooth checks).
        Figure("big_cone_angle_deg", "big gear pitch cone angle δ1", math.degrees(geom.big_cone_angle_rad), "deg",
               digits=2),
        Figure("small_cone_angle_deg", "small gear pitch cone angle δ2", math.degrees(geom.small_cone_angle_rad),
               "deg", digits=2),
        Figure("outer_cone_distance_mm", "outer cone distance Re", geom.outer_cone_distance_mm, "mm", digits=2),
        Figure("big_pitch_diameter_mm", "big gear outer pitch diameter d1", geom.big_pitch_diameter_mm, "mm", digits=2),
        Figure("small_pitch_diameter_mm", "small gear outer pitch diameter d2", geom.small_pitch_diameter_mm, "mm",
               digits=2),
        Figure("big_virtual_teeth", "big gear virtual teeth z1/cos δ1", geom.big_virtual_teeth, "", digits=2),
        Figure("small_virtual_teeth", "small gear virtual teeth z2/cos δ2", geom.small_virtual_teeth, "", digits=2),
        Figure("flank_taper_angle_deg", "flank angle θ, 2tan(θ/2) = πm/(2Re)",
               math.degrees(geom.flank_taper_angle_rad), "deg", digits=2),
        Figure("small_undercut_min_profile_shift", "small gear least profile shift (undercut)",
               mesh.small_undercut_min_shift, "", digits=3,
               note="x ≥ 1 − zv·sin²α/2"),
        Figure("gleason_profile_shift", "Gleason long-addendum shift for this ratio", mesh.gleason_small_shift, "",
               digits=3, note="template x is an input; this is the rule"),
        Figure("small_tip_thickness_mm", "small gear tip thickness (back cone)", mesh.small_tip_thickness_mm, "mm",
               digits=3, note=f"pointed below {analysis.MIN_TIP_THICKNESS_MODULES * geom.module_mm:.3f} mm"),
        Figure("virtual_contact_ratio", "contact ratio of the virtual spur pair", mesh.contact_ratio, "", digits=3),
        # Thermal approach, eqs (2)–(7).
        Figure("temperature_drop_K", f"temperature drop {op.warm_C:g} → {op.cold_C:g} °C", ap.temperature_drop_K, "K",
               digits=1),
        Figure("big_axial_shrink_um", "ΔL1 big pitch circle toward centre (2)", ap.big_axial_shrink_mm * um, "µm",
               digits=1),
        Figure("big_diameter_shrink_um", "Δd1 big pitch diameter shrink (3)", ap.big_diameter_shrink_mm * um, "µm",
               digits=1),
        Figure("small_axial_shrink_um", "ΔL2 small pitch circle toward centre (4)", ap.small_axial_shrink_mm * um,
               "µm", digits=1),
        Figure("small_diameter_shrink_um", "Δd2 small pitch diameter shrink (5)", ap.small_diameter_shrink_mm * um,
               "µm", digits=1),
        Figure("big_gear_approach_um", "ΔS1 big gear toward the mesh (6)", ap.big_approach_mm * um, "µm", digits=1),
        Figure("small_gear_approach_um", "ΔS2 small gear toward the mesh (7)", ap.small_approach_mm * um, "µm",
               digits=1),
        # Eqs (1), (8)–(10).
        Figure("big_normal_shift_um", "r1 = ΔS1·sin δ1 (1)", cold.big_normal_mm * um, "µm", digits=1),
        Figure("big_slide_um", "t1 = ΔS1·cos δ1 (1)", cold.big_along_mm * um, "µm", digits=1),
        Figure("small_normal_shift_um", "r2 = ΔS2·sin δ2 (1)", cold.small_normal_mm * um, "µm", digits=1),
        Figure("small_slide_um", "t2 = ΔS2·cos δ2 (1)", cold.small_along_mm * um, "µm", digits=1),
        Figure("normal_backlash_drop_um", "Δjn normal backlash lost (8)", cold.normal_mm * um, "µm", digits=1),
        Figure("circumferential_backlash_drop_um", "Δjc circumferential backlash lost (9)",
               cold.circumferential_mm * um, "µm", digits=1,
               note=printed_eq9),
        Figure("clean_circumferential_backlash_drop_um", "Δjc, dimensionally clean form",
               cold.clean_circumferential_mm * um, "µm", digits=1,
               note="2tanα(r1+r2) + 2tan(θ/2)(t1−t2)"),
        Figure("cold_drop_per_side_arcmin", "cold backlash drop per side (10)", cold.per_side_arcmin, "arcmin",
               digits=2,
               paper=_paper("cold_drop_per_side_arcmin", at_paper_dT), note="paper's form: eq (9) as printed"),
        Figure("cold_drop_total_arcmin", "cold backlash drop, both sides", r.cold_drop_total_arcmin, "arcmin", digits=2,
               paper=_paper("cold_drop_total_arcmin", at_paper_dT)),
        Figure("clean_cold_drop_per_side_arcmin", "cold drop per side, clean eq (9)", cold.clean_per_side_arcmin,
               "arcmin", digits=2,
               paper=_paper("cold_drop_per_side_arcmin", at_paper_dT),
               note="consistent form; exact flanks lose more (docs)"),
        Figure("clean_cold_drop_total_arcmin", "cold drop, both sides, clean eq (9)", 2.0 * cold.clean_per_side_arcmin,
               "arcmin", digits=2),
        Figure("cold_drop_total_per_K_arcmin", "total backlash lost per kelvin of cooling",
               2.0 * r.drop_per_side_per_K_arcmin, "arcmin/K", digits=4),
        Figure("min_warm_backlash_total_arcmin", "least warm total backlash (≥ cold drop)",
               r.min_warm_backlash_total_arcmin, "arcmin", digits=2,
               paper=_paper("min_warm_backlash_total_arcmin", at_paper_dT), note=f"rule for {op.cold_C:g} °C"),
        # Shim, eq (11).
        Figure("shim_gain_per_mm_per_side_arcmin", "shim gain per mm, per side (11)",
               analysis.shim_gain(geom, math.radians(params.gears.pressure_angle_deg),
                                  1.0).per_side_arcmin, "arcmin/mm", digits=2),
        Figure("shim_gain_per_side_arcmin", f"shim {_mm(design.shim_mm)} mm gain per side (11)",
               design.gain_per_side_arcmin, "arcmin", digits=2,
               note="paper's form, eq (9) as printed"),
        Figure("shim_gain_total_arcmin", f"shim {_mm(design.shim_mm)} mm gain, both sides",
               2.0 * design.gain_per_side_arcmin, "arcmin", digits=2),
        Figure("clean_shim_gain_per_side_arcmin", f"shim {_mm(design.shim_mm)} mm gain per side, clean (9)",
               design.clean_gain_per_side_arcmin, "arcmin", digits=2),
    ]
    for s in r.study:
        k = shim_key(s.shim_mm)
        figs += [
            Figure(f"shim_gain_per_side_arcmin_at_{k}mm", f"study shim {_mm(s.shim_mm)} mm: gain per side",
                   s.gain_per_side_arcmin, "arcmin", digits=2),
            Figure(f"shim_gain_total_arcmin_at_{k}mm", f"study shim {_mm(s.shim_mm)} mm: gain, both sides",
                   2.0 * s.gain_per_side_arcmin, "arcmin", digits=2),
            Figure(f"warm_backlash_total_min_arcmin_at_{k}mm", f"study shim {_mm(s.shim_mm)} mm: warm total, least",
                   s.warm_total_min_arcmin, "arcmin", digits=2),
            Figure(f"cold_backlash_total_min_arcmin_at_{k}mm", f"study shim {_mm(s.shim_mm)} mm: cold total, least",
                   s.cold_total_min_arcmin, "arcmin", digits=2,
                   note="binds cold" if s.cold_total_min_arcmin <= 0.0 else ""),
        ]
    cold_ok = design.cold_total_min_arcmin > 0.0
    warm_min, warm_max = design.warm_total_min_arcmin, design.warm_total_max_arcmin
    figs += [
        # Designed backlash: tooth thinning (eq 10) + shim (eq 11), then cooled.
        Figure("unshimmed_warm_backlash_total_min_arcmin", "unshimmed warm total, least (thinning)",
               r.unshimmed_warm_total_min_arcmin, "arcmin", digits=2,
               note="reconstructed thinning, docs"),
        Figure("unshimmed_warm_backlash_total_max_arcmin", "unshimmed warm total, largest",
               r.unshimmed_warm_total_max_arcmin, "arcmin", digits=2),
        Figure("warm_backlash_total_min_arcmin", f"warm total at {op.warm_C:g} °C, least", warm_min, "arcmin", digits=2,
               paper=_paper("warm_backlash_total_min_arcmin", at_paper_shim)),
        Figure("warm_backlash_total_max_arcmin", f"warm total at {op.warm_C:g} °C, largest", warm_max, "arcmin",
               digits=2, paper=_paper("warm_backlash_total_max_arcmin", at_paper_shim)),
        Figure("cold_backlash_total_min_arcmin", f"cold total at {op.cold_C:g} °C, least",
               design.cold_total_min_arcmin, "arcmin", digits=2,
               paper=_paper("cold_backlash_total_min_arcmin",
                            at_paper_shim and at_paper_dT), note="paper: a bound, ≥ 10′"),
        Figure("cold_backlash_total_max_arcmin", f"cold total at {op.cold_C:g} °C, largest",
               design.cold_total_max_arcmin, "arcmin", digits=2),
        Figure("cold_backlash_per_side_min_arcmin", f"cold per side at {op.cold_C:g} °C, least",
               design.cold_total_min_arcmin / 2.0, "arcmin", digits=2),
        Figure("cold_backlash_positive", "cold backlash stays > 0 (1 pass, 0 fail)", 1.0 if cold_ok else 0.0, "pass",
               digits=0, note="PASS" if cold_ok else "FAIL: binds cold, thin the teeth or shim more"),
        Figure("backlash_total_min_at_operating_min_arcmin", f"total at operating min {op.operating_min_C:g} °C, least",
               r.total_backlash_at(op.operating_min_C, op.warm_C, warm_min), "arcmin", digits=2),
        Figure("backlash_total_max_at_operating_max_arcmin",
               f"total at operating max {op.operating_max_C:g} °C, largest",
               r.total_backlash_at(op.operating_max_C, op.warm_C,
                                   warm_max), "arcmin", digits=2, note="loosest body pitch"),
        Figure("backlash_total_min_at_storage_min_arcmin", f"total at storage min {op.storage_min_C:g} °C, least",
               r.total_backlash_at(op.storage_min_C, op.warm_C, warm_min), "arcmin", digits=2),
        Figure("backlash_total_max_at_storage_max_arcmin", f"total at storage max {op.storage_max_C:g} °C, largest",
               r.total_backlash_at(op.storage_max_C, op.warm_C, warm_max), "arcmin", digits=2),
    ]
    return figs
