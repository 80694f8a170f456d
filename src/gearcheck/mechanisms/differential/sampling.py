"""Random differential templates for the fuzz and the property tests (stdlib only): every
documented knob redrawn around the shipped template, mostly inside the band where a design can
work, sometimes outside it (see :mod:`gearcheck.mechanisms.sampling`). The optional measured
backlash ([calibration]) is kept on a few sets only (:data:`CALIBRATED`), redrawn around what the
paper's first-order model says the drawn design has: a calibrated set solves its thinning on the
exact geometry, and the thinning knobs would otherwise go unexercised."""

from __future__ import annotations

import math

from gearcheck.mechanisms.sampling import OUT_OF_BAND, Draw, _int_knob, _knob, _near

# Share of sets that keep a [calibration] (a measured backlash to solve the thinning from).
CALIBRATED = 0.15
ARCMIN_PER_RAD = 10800.0 / math.pi


def sample_differential(data: dict, draw: Draw) -> None:
    """Redraw a differential template body in place."""
    g = data["gears"]
    g["module_mm"] = _knob(draw, 1.5, 6.0)
    g["big_teeth"] = _int_knob(draw, 14, 60)
    g["small_teeth"] = _int_knob(draw, 8, min(g["big_teeth"], 40))
    g["pressure_angle_deg"] = _knob(draw, 14.5, 30.0, 2)
    m, z1, z2 = g["module_mm"], g["big_teeth"], g["small_teeth"]
    # around Gleason's long-addendum rule, where undercut, pointed tips and contact ratio allow it
    x_gleason = 0.46 * (1.0 - (z2 / z1) ** 2) if z1 > 0 else 0.0
    g["small_profile_shift"] = _knob(draw, x_gleason - 0.18, x_gleason + 0.18, 3)
    cone = 0.5 * m * math.hypot(z1, z2)  # outer cone distance Re (90° shafts)
    g["face_width_mm"] = _knob(draw, 0.1 * cone, 0.345 * cone, 3)
    if draw.chance(OUT_OF_BAND):
        g["shaft_angle_deg"] = _knob(draw, 60.0, 120.0, 1)

    b = data["backlash"]
    b["mesh_thinning_min_mm"] = _knob(draw, 0.0, 0.12)
    b["mesh_thinning_max_mm"] = round(b["mesh_thinning_min_mm"] + _knob(draw, 0.0, 0.05), 4)

    mat = data["materials"]
    for key in ("housing_cte_per_K", "shaft_cte_per_K", "gear_cte_per_K"):
        mat[key] = round(_knob(draw, 0.0, 30.0, 3) * 1e-6, 10)

    # Common apex: b/2 = l11 + l12 + d2/2, a/2 = l2 + d1/2 (occasionally missed).
    d = data["dimensions"]
    d["l11_mm"] = _knob(draw, 0.0, 30.0, 3)
    d["l12_mm"] = _knob(draw, 1.5, 15.0, 3)
    d["l2_mm"] = _knob(draw, 0.5, 12.0, 3)
    d["b_mm"] = _near(draw, 2.0 * (d["l11_mm"] + d["l12_mm"] + m * z2 / 2.0), 0.2)
    d["a_mm"] = _near(draw, 2.0 * (d["l2_mm"] + m * z1 / 2.0), 0.2)

    op = data["operating"]
    op["warm_C"] = _knob(draw, -40.0, 120.0, 1)
    op["cold_C"] = _knob(draw, -150.0, min(op["warm_C"], 25.0), 1)
    op["operating_min_C"] = _knob(draw, -150.0, 20.0, 1)
    op["operating_max_C"] = _knob(draw, op["operating_min_C"], 150.0, 1)
    op["storage_min_C"] = _knob(draw, -150.0, 20.0, 1)
    op["storage_max_C"] = _knob(draw, op["storage_min_C"], 150.0, 1)

    s = data["shim"]
    s["thickness_mm"] = _knob(draw, 0.0, 0.5, 3)
    s["study_mm"] = [round(_knob(draw, 0.0, 0.5, 2), 2) for _ in range(draw.integer(0, 5))]

    if "calibration" in data and not draw.chance(CALIBRATED):
        del data["calibration"]
    elif "calibration" in data:
        _calibration(data, draw)


def _calibration(data: dict, draw: Draw) -> None:
    """A measured warm total around the first-order estimate for the drawn design: the thinning
    on d1/2 plus eq (11)'s shim gain with the pitch cone angle only (both sides)."""
    g, b, c = data["gears"], data["backlash"], data["calibration"]
    m, z1, z2 = g["module_mm"], g["big_teeth"], g["small_teeth"]
    shim = _knob(draw, 0.0, 0.3, 3)
    d1_half = max(m * z1 / 2.0, 1e-3)
    delta1 = math.atan2(z1, z2) if z2 else 0.0
    gain = 2.0 * math.tan(math.radians(20.0)) * shim * math.sin(delta1)
    total = 2.0 * (b["mesh_thinning_min_mm"] + gain) / d1_half * ARCMIN_PER_RAD
    c["measured_shim_mm"] = shim
    c["measured_at_C"] = _knob(draw, 15.0, 30.0, 1)
    c["measured_backlash_total_min_arcmin"] = round(total * _knob(draw, 0.7, 1.3, 3), 3)
    c["measured_backlash_total_max_arcmin"] = round(c["measured_backlash_total_min_arcmin"] + _knob(draw, 0.0, 3.0), 3)
