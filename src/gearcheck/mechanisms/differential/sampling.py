"""Random differential templates for the fuzz and the property tests (stdlib only): every
documented knob redrawn around the shipped template, mostly inside the band where a design can
work, sometimes outside it (see :mod:`gearcheck.mechanisms.sampling`)."""

from __future__ import annotations

import math

from gearcheck.mechanisms.sampling import OUT_OF_BAND, Draw, _int_knob, _knob, _near


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
