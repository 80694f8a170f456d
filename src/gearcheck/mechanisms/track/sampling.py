"""Random track-drive parameter sets around the shipped template, for the property tests and
`make fuzz` (stdlib and the ISO 606 closed forms only; the generic draws are in
:mod:`gearcheck.mechanisms.sampling`)."""

from __future__ import annotations

from gearcheck.geometry import iso606
from gearcheck.mechanisms.sampling import Draw, _int_knob, _knob


def sample_track(data: dict, draw: Draw) -> None:
    """Redraw every knob of a track template body in place: pitch, tooth count (mostly odd,
    sometimes even: valid, with the check's warning), sleeve and the ISO 606 form inside its
    limits, widths and rows, the tip gap and its window, loads, materials and strengths."""
    r = data["robot"]
    r["mass_kg"] = _knob(draw, 5.0, 2000.0, 1)
    r["speed_m_s"] = _knob(draw, 0.1, 5.0, 2)
    r["slope_deg"] = _knob(draw, 0.0, 60.0, 1)
    r["tracks"] = _int_knob(draw, 1, 8)
    r["g_m_s2"] = _knob(draw, 1.6, 25.0, 2)
    gr = data["ground"]
    gr["rolling_resistance_coefficient"] = _knob(draw, 0.0, 0.3, 3)
    gr["adhesion_coefficient"] = _knob(draw, 0.2, 1.2, 3)

    c, s = data["chain"], data["sprocket"]
    p = c["pitch_mm"] = _knob(draw, 10.0, 60.0, 2)
    z = _int_knob(draw, 13, 81, out=6)
    s["teeth"] = z if draw.chance(0.1) or z % 2 else z + 1
    z = s["teeth"]
    ok_z = 5 <= z <= 1000
    d = iso606.every_other_tooth_pitch_diameter(p, z) if ok_z else 100.0
    chord = iso606.groove_chord(d, z) if ok_z else 10.0
    dr = c["sleeve_diameter_mm"] = _knob(draw, 0.2 * chord, 0.9 * chord, 3)
    c["pin_diameter_mm"] = round(dr * _knob(draw, 0.2, 0.8, 3), 3)
    b1 = c["sleeve_inner_width_mm"] = _knob(draw, 0.2 * p, 0.6 * p, 2)
    c["pin_support_span_mm"] = round(b1 * _knob(draw, 1.05, 2.5, 3), 2)
    c["pin_segments"] = _int_knob(draw, 1, 4)

    if dr > 0 and ok_z:
        lim = iso606.seating_limits(dr, z)
        s["seating_radius_mm"] = _knob(draw, lim.seating_radius_min_mm, lim.seating_radius_max_mm)
        s["flank_radius_mm"] = _knob(draw, lim.flank_radius_min_mm, lim.flank_radius_max_mm, 2)
        s["seating_angle_deg"] = _knob(draw, lim.seating_angle_min_deg, lim.seating_angle_max_deg, 3)
    s["initial_pitch_diameter_mm"] = round(d * _knob(draw, 0.95, 1.05, 4), 2)
    s["tip_over_pitch_mm"] = round(dr * _knob(draw, 0.0, 0.15, 4), 3)
    tw = s["tooth_width_mm"] = round(b1 * _knob(draw, 0.5, 0.95, 3), 2)
    rows = s["tooth_rows"] = _int_knob(draw, 1, 3, out=1)
    gw = s["middle_groove_width_mm"] = _knob(draw, 0.0, 2.0 * p, 2)
    total = rows * tw + (rows - 1) * gw
    c["track_width_mm"] = round(total * _knob(draw, 1.0, 1.6, 3), 2)

    t = data["track_plate"]
    t["tip_gap_mm"] = _knob(draw, 0.05, min(2.0, 0.3 * dr), 3)
    t["required_gap_min_mm"] = _knob(draw, 0.0, 1.0, 2)
    t["required_gap_max_mm"] = round(t["required_gap_min_mm"] + _knob(draw, 0.0, 1.0, 2), 2)

    m = data["materials"]
    for key in ("sprocket", "sleeve"):
        m[f"{key}_E_MPa"] = _knob(draw, 40_000.0, 220_000.0, 0)
        m[f"{key}_poisson"] = _knob(draw, 0.2, 0.4, 3)
    st = data["strength"]
    st["pin_allowable_shear_MPa"] = _knob(draw, 50.0, 600.0, 1)
    st["allowable_crush_stress_MPa"] = _knob(draw, 100.0, 1500.0, 1)
    st["loaded_tooth_rows"] = _int_knob(draw, 1, max(1, rows), out=1)
