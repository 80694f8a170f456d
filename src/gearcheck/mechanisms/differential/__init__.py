"""Bevel-gear differential of the Zhurong Mars rover: cold backlash and shims.

``calc(params)`` runs the paper's model, eqs (1)–(11) (the lost (1), (10), (11) reconstructed,
see :mod:`.analysis` and docs/differential.md), and returns figures beside the paper's numbers.
Paper values are attached only to the paper's own unit (:func:`.paper.is_paper_design`: the gears,
thinning, materials, dimensions and calibration of the shipped template) and only at the paper's
own conditions (a 90 K drop, its 0.10 mm shim), so another design or an override never shows a
paper number beside a figure it does not describe.

The paper's model is first order and linear in the temperature; beside it ``calc`` gives the
exact-flank model (no mesh, :mod:`.temperature`) at the template's named temperatures and the
tooth thinning the gears are built with (solved from a measured backlash when the template is
calibrated, :mod:`.calibration`). The linear model's pass/fail figure is labelled as the linear
model's; the verdict over the temperature ranges is the exact model's (``exact_range_verdict``).
"""

from __future__ import annotations

import math

from gearcheck.figures import Figure
from gearcheck.mechanisms.differential import analysis
from gearcheck.mechanisms.differential.analysis import analyse_params
from gearcheck.mechanisms.differential.paper import is_paper_design
from gearcheck.mechanisms.differential.params import Params, shim_key
from gearcheck.mechanisms.differential.temperature import STATE_TEXT, RangeCheck, range_check

# Meshing tolerance requested when --tol is not given. The pipeline refines it where the smallest
# clearance decided (Differential.smallest_clearance, exact model) needs a pair bound ≤ 1/10 of it
# and a practical mesh can give that; the template's (0.354′ overlap at −130 °C, 4.25 µm) cannot,
# so its play verdicts rest on the exact model.
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

__all__ = ["MESH_TOL_MM", "PAPER", "Params", "analyse_params", "calc", "is_paper_design", "paper_conditions"]


def _mm(shim_mm: float) -> str:
    """Shim thickness as in the JSON key: 0.1 → '0.10', 0.125 → '0.125'."""
    return shim_key(shim_mm).replace("p", ".")


def _paper(key: str, applies: bool) -> float | None:
    return PAPER[key] if applies else None


def paper_conditions(params: Params) -> tuple[bool, bool]:
    """Whether the paper's drop figures (a 90 K drop) and its warm figures (its shim) stand beside
    this design's: only on the paper's own unit (:func:`is_paper_design`), at those conditions."""
    if not is_paper_design(params):
        return False, False
    drop = params.operating.warm_C - params.operating.cold_C
    return (math.isclose(drop, PAPER_TEMPERATURE_DROP_K, abs_tol=1e-9),
            math.isclose(params.shim.thickness_mm, PAPER_SHIM_MM, abs_tol=1e-9))


def calc(params: Params) -> list[Figure]:
    r = analyse_params(params)
    op = params.operating
    geom, mesh, ap, cold, design = r.geometry, r.mesh, r.approach, r.cold, r.design
    um = analysis.UM_PER_MM
    at_paper_dT, at_paper_shim = paper_conditions(params)
    paper_unit = is_paper_design(params)
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
    exact = _exact_range(params)
    linear = "paper's linear model"
    exact_says = _exact_words(params, exact)
    figs += [
        # Designed backlash: tooth thinning (eq 10) + shim (eq 11), then cooled.
        Figure("unshimmed_warm_backlash_total_min_arcmin", "unshimmed warm total, least (thinning)",
               r.unshimmed_warm_total_min_arcmin, "arcmin", digits=2,
               note="reconstructed thinning, docs" if paper_unit else "the design's [backlash] thinning"),
        Figure("unshimmed_warm_backlash_total_max_arcmin", "unshimmed warm total, largest",
               r.unshimmed_warm_total_max_arcmin, "arcmin", digits=2),
        Figure("warm_backlash_total_min_arcmin", f"warm total at {op.warm_C:g} °C, least", warm_min, "arcmin", digits=2,
               paper=_paper("warm_backlash_total_min_arcmin", at_paper_shim)),
        Figure("warm_backlash_total_max_arcmin", f"warm total at {op.warm_C:g} °C, largest", warm_max, "arcmin",
               digits=2, paper=_paper("warm_backlash_total_max_arcmin", at_paper_shim)),
        Figure("cold_backlash_total_min_arcmin", f"cold total at {op.cold_C:g} °C, least",
               design.cold_total_min_arcmin, "arcmin", digits=2,
               paper=_paper("cold_backlash_total_min_arcmin", at_paper_shim and at_paper_dT),
               note=(f"paper: a bound, ≥ {PAPER['cold_backlash_total_min_arcmin']:g}′" if at_paper_shim and at_paper_dT
                     else "")),
        Figure("cold_backlash_total_max_arcmin", f"cold total at {op.cold_C:g} °C, largest",
               design.cold_total_max_arcmin, "arcmin", digits=2),
        Figure("play_min_arcmin_at_warm", f"least play per side, warm at {op.warm_C:g} °C",
               warm_min / 2.0, "arcmin", digits=2),
        Figure("play_min_arcmin_at_cold", f"least play per side, cold at {op.cold_C:g} °C",
               design.cold_total_min_arcmin / 2.0, "arcmin", digits=2),
        Figure("cold_backlash_positive", f"{linear}: cold total > 0 at {op.cold_C:g} °C (1 yes, 0 no)",
               1.0 if cold_ok else 0.0, "pass", digits=0,
               note=f"{linear}: {'free' if cold_ok else 'binds cold'}; exact geometry: {exact_says}"),
        Figure("backlash_total_min_at_operating_min_arcmin",
               f"{linear}: total at operating min {op.operating_min_C:g} °C, least",
               r.total_backlash_at(op.operating_min_C, op.warm_C, warm_min), "arcmin", digits=2,
               note=_exact_total(exact, "operating_min")),
        Figure("backlash_total_max_at_operating_max_arcmin",
               f"{linear}: total at operating max {op.operating_max_C:g} °C, largest",
               r.total_backlash_at(op.operating_max_C, op.warm_C,
                                   warm_max), "arcmin", digits=2, note="loosest body pitch"),
        Figure("backlash_total_min_at_storage_min_arcmin",
               f"{linear}: total at storage min {op.storage_min_C:g} °C, least",
               r.total_backlash_at(op.storage_min_C, op.warm_C, warm_min), "arcmin", digits=2,
               note=_exact_total(exact, "storage_min")),
        Figure("backlash_total_max_at_storage_max_arcmin",
               f"{linear}: total at storage max {op.storage_max_C:g} °C, largest",
               r.total_backlash_at(op.storage_max_C, op.warm_C, warm_max), "arcmin", digits=2),
    ]
    return figs + _thinning_figures(params) + _exact_figures(params, exact)


# -- the exact model beside the paper's ----------------------------------------------------------

def _exact_range(params: Params) -> RangeCheck | None:
    """The exact model at the named temperatures, template shim (None: beyond its reach)."""
    try:
        return range_check(params, params.shim.thickness_mm, grid=False)
    except (RuntimeError, ValueError):  # no contact within the exact model's reach (a huge play)
        return None


def _exact_words(params: Params, exact: RangeCheck | None) -> str:
    """The exact geometry's finding over the ranges, in words."""
    op = params.operating
    if exact is None:
        return "exact model out of its reach (no contact within 69′)"
    if exact.binds_operating:
        least, at = exact.operating
        return f"binds in the operating range ({least:.2f}′ per side at {at:g} °C)"
    if exact.binds_storage:
        onset = exact.cold_onset_C if exact.cold_onset_C is not None else exact.hot_onset_C
        where = f" below {onset:.1f} °C" if onset is not None and onset < op.warm_C else \
            f" above {onset:.1f} °C" if onset is not None else ""
        return f"binds in storage{where} ({exact.storage[0]:.2f}′ per side at {exact.storage[1]:g} °C)"
    return "free over the operating and storage ranges"


def _exact_total(exact: RangeCheck | None, name: str) -> str:
    if exact is None:
        return ""
    total = 2.0 * exact.at(name)
    return f"exact: {total:.2f}′{' (binds)' if total <= 0 else ''}"


def _thinning_figures(params: Params) -> list[Figure]:
    """The thinning the gears are built with: the design's [backlash] (an input), or, calibrated, the
    one solved from the measured backlash beside the [backlash] set through the paper's model."""
    th = params.thinning()
    um = analysis.UM_PER_MM
    source = "solved on the exact geometry from the measured backlash" if th.calibrated else "the design's [backlash]"
    figs = [
        Figure("design_thinning_min_um", "tooth thinning per mesh, least: the gears built", th.min_mm * um, "µm",
               digits=2, note=source),
        Figure("design_thinning_max_um", "tooth thinning per mesh, largest: the gears built", th.max_mm * um, "µm",
               digits=2),
    ]
    if th.calibrated:
        figs[:0] = [
            Figure("paper_model_thinning_min_um",
                   "tooth thinning per mesh, least: [backlash] through the paper's model", th.template_min_mm * um,
                   "µm", digits=1, note="eqs (10), (11); replaced by the calibration"),
            Figure("paper_model_thinning_max_um", "tooth thinning per mesh, largest: [backlash]",
                   th.template_max_mm * um, "µm", digits=1),
        ]
        c = params.calibration
        where = f"shim {_mm(float(c.measured_shim_mm or 0.0))} mm, {c.measured_at_C:g} °C"
        figs += [
            Figure("exact_warm_backlash_total_min_at_measured_arcmin", f"exact warm total, least, {where}",
                   th.exact_total_min_arcmin, "arcmin", digits=2,
                   note=f"solved thinning; measured {c.measured_backlash_total_min_arcmin:g}′ (cycle minimum)"),
            Figure("exact_warm_backlash_total_max_at_measured_arcmin", f"exact warm total, largest, {where}",
                   th.exact_total_max_arcmin, "arcmin", digits=2,
                   note=f"measured {c.measured_backlash_total_max_arcmin:g}′"),
            Figure("exact_warm_backlash_total_min_at_paper_thinning_arcmin",
                   f"exact warm total, least, {where}, paper-model thinning", th.template_exact_total_min_arcmin,
                   "arcmin", digits=2, note="what the paper-model thinning builds: less than measured"),
        ]
    return figs


def _exact_figures(params: Params, exact: RangeCheck | None) -> list[Figure]:
    figs = [Figure("exact_model_solved", "exact-flank model solved at the named temperatures (1 yes, 0 no)",
                   0.0 if exact is None else 1.0, "", digits=0,
                   note="" if exact is not None else "no contact within the exact model's reach")]
    if exact is None:
        return figs
    shim = params.shim.thickness_mm
    for name in ("warm", "cold", "operating_min", "operating_max", "storage_min", "storage_max"):
        figs.append(Figure(f"exact_play_min_arcmin_at_{name}",
                           f"exact least play per side, {STATE_TEXT[name]} {exact.keys[name]:g} °C",
                           exact.at(name), "arcmin", digits=3, note=f"shim {_mm(shim)} mm, exact flanks"))
    (op_least, op_at), (st_least, st_at) = exact.operating, exact.storage
    deep = exact.at("storage_min")
    figs += [
        Figure("exact_operating_least_play_arcmin", "exact least play per side over the operating range", op_least,
               "arcmin", digits=3, note=f"at {op_at:g} °C"),
        Figure("exact_storage_least_play_arcmin", "exact least play per side over the storage range", st_least,
               "arcmin", digits=3, note=f"at {st_at:g} °C"),
        Figure("exact_storage_min_overlap_um", "exact overlap at the storage minimum, on d1/2", exact.depth_um(deep),
               "µm", digits=2, note="0: free" if deep > 0 else f"{-deep:.3f}′ per side"),
    ]
    onsets = [t for t in (exact.cold_onset_C, exact.hot_onset_C) if t is not None]
    for key, t in zip(("exact_binding_onset_C", "exact_binding_onset_hot_C"), onsets, strict=False):
        figs.append(Figure(key, "exact: contact starts at", t, "°C", digits=2, note="solved on the exact model"))
    level = exact.level
    figs.append(Figure("exact_range_verdict", "exact geometry over the ranges (1 pass, 0.5 warn, 0 fail)",
                       {"pass": 1.0, "warn": 0.5, "fail": 0.0}[level], "pass", digits=1,
                       note=f"{level.upper()}: {_exact_words(params, exact)}"))
    return figs
