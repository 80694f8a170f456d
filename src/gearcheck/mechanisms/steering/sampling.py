"""Random steering templates for the property tests and `make fuzz` (stdlib only): every knob of
the rack and pinion redrawn around the shipped template, mostly inside the band where a design can
work, sometimes outside it (:mod:`gearcheck.mechanisms.sampling`)."""

from __future__ import annotations

from gearcheck.mechanisms.sampling import OUT_OF_BAND, Draw, _int_knob, _knob

# Figures the model documents as NaN: none. A figure the model has no value for (no RS1 / hS2 in range
# reaches the target; the rack still moving at towing.max_angle_deg; a towing-curve point beyond it)
# is left out of calc, its reason in the table (calc._without_missing), so calc --json never holds
# null: every figure of an accepted set must be finite.
NAN_FIGURES: frozenset[str] = frozenset()


def sample(data: dict, draw: Draw) -> None:
    """Redraw the steering knobs of a template body in place."""
    pin, rack, trim = data["pinion"], data["rack"], data["trim"]
    m = pin["module_mm"] = _knob(draw, 1.5, 8.0, 3)
    pin["pressure_angle_deg"] = _knob(draw, 14.5, 30.0, 2)
    x = pin["profile_shift"] = _knob(draw, -0.4, 0.6, 3)
    ha = pin["addendum_coefficient"] = _knob(draw, 0.8, 1.2, 3)
    pin["dedendum_coefficient"] = _knob(draw, 1.1, 1.5, 3)
    rack["addendum_coefficient"] = _knob(draw, 0.8, 1.2, 3)
    hf_rack = rack["dedendum_coefficient"] = _knob(draw, 1.1, 1.5, 3)
    k = _int_knob(draw, 2, 9, out=1)
    rack["first_tooth"], rack["last_tooth"] = -k, k
    pin["sector_first_tooth"], pin["sector_last_tooth"] = -k - 1, k
    if draw.chance(OUT_OF_BAND):
        rack["last_tooth"] = k + 1
    z = pin["teeth"] = _int_knob(draw, max(2 * k + 4, 18), 80)
    r = m * z / 2.0
    tip = r + (ha + x) * m
    H = data["layout"]["centre_to_datum_mm"] = round(r + x * m + hf_rack * m + _knob(draw, 2.0, 40.0, 3), 3)

    # Trim heights as fractions of the band from the rolling line h to the rack top.
    h = H - r
    top = h - x * m + rack["addendum_coefficient"] * m
    for name in ("hS2_mm", "hS4_mm", "hS6_mm", "hS8_mm"):
        trim[name] = round(h + (top - h) * _knob(draw, 0.3, 1.0, 4), 4)
    trim["min_contact_ratio"] = _knob(draw, 1.0, 1.5, 3)
    # RS1 between the circle through S2 and the tip circle (the params' lower end also has the
    # form radius; a miss there is a rejection, which is fine).
    lo = H - trim["hS2_mm"]
    pin["topped_radius_mm"] = round(lo + (tip - lo) * _knob(draw, 0.05, 1.0, 4), 4)
    data["targets"]["continuous_drive_deg"] = _knob(draw, 10.0, 90.0, 2)
    data["towing"]["max_angle_deg"] = _knob(draw, 30.0, 120.0, 2)
