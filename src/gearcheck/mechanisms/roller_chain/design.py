"""``gearcheck new roller_chain --chain 12B --teeth 21 [--strands 2]``: a complete template from
the chain's ISO 606 designation and the tooth count, every other value from the standard."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from gearcheck.drafting import Draft, positive_number, teeth_numbers
from gearcheck.geometry import iso606, iso606_chains
from gearcheck.mechanisms.roller_chain.params import MAX_STRANDS, MAX_TEETH, MIN_TEETH
from gearcheck.params import ParamError

DEFAULT_FORM = 0.5
# The tip circle is kept this share of a pitch (at least) below the diameter where adjacent flanks meet.
TIP_LAND_MARGIN_PITCHES = 0.05


def _round_down(x: float, step: float) -> float:
    return math.floor(x / step + 1e-9) * step


def derive_tip_diameter(pitch_mm: float, roller_diameter_mm: float, teeth: int, form: float) -> tuple[float, str]:
    """Middle of ISO 606's tip range, lowered where needed to leave a tip land (at most the
    diameter where adjacent flanks meet less 0.05·p), rounded down to 0.01 mm."""
    lo, hi = iso606_chains.tip_diameter_range(pitch_mm, roller_diameter_mm, teeth)
    bottom, meet = iso606_chains.tip_diameter_bounds(pitch_mm, roller_diameter_mm, teeth, form)
    mid = 0.5 * (lo + hi)
    cap = meet - TIP_LAND_MARGIN_PITCHES * pitch_mm
    if mid <= cap:
        return _round_down(mid, 0.01), (f"middle of ISO 606's da = {lo:.3f} (d + p(1 − 1.6/z) − d1) to {hi:.3f} "
                                        "(d + 1.25p − d1) mm")
    value = max(lo, cap) if cap > lo else 0.5 * (max(bottom, lo - pitch_mm) + meet)
    return _round_down(value, 0.01), (f"ISO 606's da {lo:.3f} to {hi:.3f} mm, kept 0.05·p below {meet:.3f} mm where "
                                      "this form's flanks meet (a tip land)")


def new_design(inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
    text = str(inputs["chain"]).strip()
    try:
        size = iso606_chains.chain(text)
    except KeyError:
        allowed = "allowed an ISO 606 chain: " + ", ".join(iso606_chains.DESIGNATIONS)
        raise ParamError("--chain", text, allowed) from None
    (z,) = teeth_numbers(inputs["teeth"], 1, "sprocket teeth")
    if not MIN_TEETH <= z <= MAX_TEETH:
        raise ParamError("--teeth", inputs["teeth"], f"allowed {MIN_TEETH} to {MAX_TEETH}")
    n = 1
    if inputs.get("strands") is not None:
        n = int(positive_number("strands", inputs["strands"], 1, MAX_STRANDS))
        if n != float(inputs["strands"]):
            raise ParamError("--strands", inputs["strands"], f"allowed a whole number from 1 to {MAX_STRANDS}")
    form = overrides.get("sprocket.form", DEFAULT_FORM)
    if isinstance(form, bool) or not isinstance(form, (int, float)) or not 0.0 <= float(form) <= 1.0:
        raise ParamError("sprocket.form", form, "allowed a number from 0 to 1")
    form = float(form)
    p, d1, b1 = size.pitch_mm, size.roller_diameter_mm, size.inner_width_mm
    tooth = iso606_chains.tooth_form(d1, z, form)
    lim = iso606.seating_limits(d1, z)
    d = iso606_chains.pitch_diameter(p, z)
    da, da_note = derive_tip_diameter(p, d1, z, form)
    bf_max = iso606_chains.tooth_width_max(b1, p, n)
    factor = bf_max / b1
    dg = iso606_chains.shroud_diameter_max(p, size.plate_depth_mm, z)
    bore = max(0.0, _round_down(0.5 * dg, 1.0))
    strands_word = {1: "simplex", 2: "duplex", 3: "triplex"}[n]
    draft = Draft("roller_chain", f"roller_chain_{size.designation}_z{z}" + (f"_x{n}" if n > 1 else ""), [
        f"ISO 606 {size.designation}-{n} ({strands_word}) roller chain on a {z}-tooth sprocket, every value from the "
        "standard (gearcheck new).",
        f"Chain (ISO 606 table): p = {p:g}, d1 = {d1:g}, b1 = {b1:g}, d2 = {size.pin_diameter_mm:g}, "
        f"h2 = {size.plate_depth_mm:g}, pt = {size.transverse_pitch_mm:g} mm.",
        f"Pitch diameter d = p / sin(180°/z) = {d:.3f} mm; root diameter df = d − d1 = {d - d1:.3f} mm.",
        f"Tooth form {form:g}: ri = {tooth.seating_radius_mm:.4f} mm (0.505·d1 = {lim.seating_radius_min_mm:.4f} to "
        f"0.505·d1 + 0.069·d1^(1/3) = {lim.seating_radius_max_mm:.4f}), re = {tooth.flank_radius_mm:.3f} mm "
        f"(0.008·d1·(z² + 180) = {lim.flank_radius_max_mm:.3f} to 0.12·d1·(z + 2) = {lim.flank_radius_min_mm:.3f}), "
        f"α = {tooth.seating_angle_deg:.3f}° (140° − 90°/z = {lim.seating_angle_max_deg:.3f} to 120° − 90°/z = "
        f"{lim.seating_angle_min_deg:.3f}).",
    ])
    draft.set("chain.designation", size.designation, "ISO 606 chain number (--chain)")
    draft.set("chain.strands", n, "given (--strands)" if inputs.get("strands") is not None else "simplex (default)")
    draft.set("chain.fixed_centres", False, "adjustable centres: wear limit 3 % (1.5 % if true)")
    draft.set("sprocket.teeth", z, "given (--teeth)")
    draft.set("sprocket.form", form, "half way between ISO 606's minimum and maximum tooth gap"
              if "sprocket.form" not in overrides else "set with --set")
    draft.set("sprocket.tip_diameter_mm", da, da_note)
    draft.set("sprocket.tooth_width_mm", _round_down(bf_max, 0.01),
              f"ISO 606 bf1 max = {factor:.2f}·b1 ({strands_word}, p {'≤' if p <= 12.7 else '>'} 12.7 mm)")
    draft.set("sprocket.bore_diameter_mm", bore, f"half the hub diameter dg = p·cot(180°/z) − 1.04·h2 − 0.76 = "
                                                  f"{dg:.2f} mm, rounded down to 1 mm")
    draft.set("drive.speed_rpm", overrides.get("drive.speed_rpm", 100.0), "a working speed: set yours with --set")
    draft.set("drive.power_kW", overrides.get("drive.power_kW", 1.0), "a working power: set yours with --set")
    draft.set("drive.service_factor", overrides.get("drive.service_factor", 1.0), "smooth drive (1 to 3 with shock)")
    draft.set("drive.max_speed_ripple_pct", overrides.get("drive.max_speed_ripple_pct", 2.0),
              "2 % ≈ 16 teeth: the usual least tooth count for smooth running")
    return draft
