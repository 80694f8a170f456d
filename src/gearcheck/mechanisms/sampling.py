"""Random parameter sets around the shipped templates (stdlib only), for property tests and
`make fuzz`.

A sample starts from a real template's data and redraws every documented knob of its mechanism
(module, tooth counts, face width, pressure angle, profile shift, pitch, sleeve diameter,
temperatures, shim, trim heights, ...). Most values are drawn inside the band where a design can
work, so that a good share of the sets is accepted; a small fraction lands outside the fields'
documented ranges or breaks a cross-field rule, so that every rejection path runs too. Inputs the
models tie to others (the common-apex lengths a, b; the trims between the rolling line and the
rack top) are drawn relative to what they depend on, with an occasional miss.

The draws go through a :class:`Draw`, so the same definition serves hypothesis (tests: shrinking,
a seeded database-free run) and :class:`random.Random` (``bench/fuzz.py``).
"""

from __future__ import annotations

import copy

import math
import random
from typing import Callable, Protocol

from gearcheck.geometry import iso606

# Share of knobs drawn outside their working band, and exactly at one of its ends (each knob
# decides alone).
OUT_OF_BAND = 0.04
EDGE = 0.03

# Figures a model documents as NaN when it has no value (steering/__init__.py notes: no RS1 /
# hS2 in range reaches the target; the rack still moving at towing.max_angle_deg; a towing-curve
# point beyond towing.max_angle_deg). Every other figure of an accepted set must be finite, and
# none may be infinite: what the property tests and `make fuzz` check.
NAN_FIGURES: dict[str, frozenset[str]] = {
    "differential": frozenset(),
    "track": frozenset(),
    "steering": frozenset({
        "RS1_solved_mm", "hS2_solved_mm", "disengage_angle_deg", "disengage_angle_paper_bookkeeping_deg",
        "rack_travel_at_disengage_mm", "towing_grazing_span_deg", "reengage_angle_deg",
        "towing_travel_mm_at_068deg", "towing_travel_mm_at_072deg", "towing_travel_mm_at_075deg",
        "towing_travel_mm_at_adams_angle",
    }),
}


class Draw(Protocol):
    def real(self, lo: float, hi: float) -> float: ...

    def integer(self, lo: int, hi: int) -> int: ...

    def chance(self, p: float) -> bool: ...


class RandomDraw:
    """:class:`Draw` from a seeded :class:`random.Random`."""

    def __init__(self, seed: int):
        self.rng = random.Random(seed)

    def real(self, lo: float, hi: float) -> float:
        return self.rng.uniform(lo, hi)

    def integer(self, lo: int, hi: int) -> int:
        return self.rng.randint(lo, hi)

    def chance(self, p: float) -> bool:
        return self.rng.random() < p


def _knob(draw: Draw, lo: float, hi: float, digits: int = 4) -> float:
    """Inside [lo, hi] mostly; exactly an end EDGE of the time (bounds are where rules break);
    else up to 30 % of the span beyond one end."""
    if draw.chance(EDGE):
        return round(lo if draw.chance(0.5) else hi, digits)
    if draw.chance(OUT_OF_BAND):
        span = 0.3 * (hi - lo) if hi > lo else 1.0
        value = draw.real(hi, hi + span) if draw.chance(0.5) else draw.real(lo - span, lo)
    else:
        value = draw.real(lo, hi)
    return round(value, digits)


def _int_knob(draw: Draw, lo: int, hi: int, out: int = 3) -> int:
    if draw.chance(OUT_OF_BAND):
        return draw.integer(hi + 1, hi + out) if draw.chance(0.5) else draw.integer(lo - out, lo - 1)
    return draw.integer(lo, hi)


def _near(draw: Draw, value: float, miss: float, digits: int = 4) -> float:
    """``value`` up to rounding (and, OUT_OF_BAND of the time, off by up to ±``miss``)."""
    if draw.chance(OUT_OF_BAND):
        value += draw.real(-miss, miss)
    return round(value, digits)


# ------------------------------------------------------------------------------ differential
def _differential(data: dict, draw: Draw) -> None:
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


# ------------------------------------------------------------------------------------- track
def _track(data: dict, draw: Draw) -> None:
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


# ---------------------------------------------------------------------------------- steering
def _steering(data: dict, draw: Draw) -> None:
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
    data["targets"]["continuous_angle_deg"] = _knob(draw, 10.0, 90.0, 2)
    data["towing"]["max_angle_deg"] = _knob(draw, 30.0, 120.0, 2)


SAMPLERS: dict[str, Callable[[dict, Draw], None]] = {
    "differential": _differential,
    "track": _track,
    "steering": _steering,
}


def sample(base: dict, draw: Draw) -> dict:
    """A new template body (TOML data, ``mechanism`` key kept) redrawn from ``base``."""
    data = copy.deepcopy(base)
    SAMPLERS[data["mechanism"]](data, draw)
    return data
