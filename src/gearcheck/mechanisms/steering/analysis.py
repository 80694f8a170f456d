"""Analytical model of the trimmed nose-wheel steering rack and pinion, numpy/scipy.

Two independent layers:

* closed forms on the line of action (contact ratio, eq (3)/(4) travels, the S1/S6 engagement
  angles, tangent constructions, the trimming solver), written for any basic profile;
* an exact-polyline **push model** of towing: for each pinion angle the rack sits at the
  smallest travel (forward swing) or the largest (return swing) at which no pinion tooth
  overlaps a rack tooth, moving only when a tooth pushes it. The disengage and re-engage
  angles, the towing curve and the interference check come from it; the closed forms are
  used to cross-check it (tests). It lives in :mod:`.push` and is re-exported here.

Frame, tooth indices and angle-0 convention: :mod:`gearcheck.geometry.rack_pinion`. All
angles are radians unless a name says ``_deg``; the towing direction is the one in which the
first rack tooth (k = rack.first_tooth) comes under the pinion (φ > 0, rack moving +x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_power import phi_power_conjugate_end
from gearcheck.mechanisms.steering.push import (  # noqa: F401  (re-exported: the model's one namespace)
    ANGLE_STEP_DEG,
    BISECT_TOL_RAD,
    CHECK_ANGLES_DEG,
    PUSH_NORMAL_MIN,
    PUSH_RATE_PER_TIP_RADIUS,
    TRAVEL_TOL_MM,
    Sweep,
    Towing,
    all_intervals,
    analyse_towing,
    overlap_intervals,
    pair_push_interval,
    push_intervals,
    push_reach,
    sweep,
    tooth_pairs,
    towing_grid,
    travel_on_curve,
)

# The paper's printed numbers (for display beside the model; never used as results).
PAPER = {
    "hS4_mm": 25.13,
    "hS2_mm": 25.13,
    "travel_S3S4_mm": 109.81,
    "S1_x_mm": 20.07,
    "RS1_from_S1_mm": 84.294,  # √(20.07² + (107 − 25.13)²): the printed S1 point
    "hS8_mm": 25.51,
    "hS6_mm": 25.57,
    "OS_mm": 82.24,
    "alpha_S6_deg": 21.42,
    "phi_S1_deg": 62.67,
    "phi_S6_deg": 62.11,
    "disengage_deg": 75.32,
    "travel_disengage_mm": 110.20,
    "adams_disengage_deg": 75.89,
    "adams_travel_mm": 110.05,
    "test_continuous_deg": 64.0,
    "test_disengage_deg": 78.0,
    "test_travel_mm": 109.5,
}



# The paper's design as the template holds it: every input of the drawing and of the design chain
# (towing.max_angle_deg only sets how far the check swings, so it may differ).
PAPER_DESIGN = {
    "pinion": {"module_mm": 4.0, "teeth": 42, "profile_shift": 0.0, "pressure_angle_deg": 25.0,
               "addendum_coefficient": 1.0, "dedendum_coefficient": 1.25, "sector_first_tooth": -8,
               "sector_last_tooth": 7, "topped_radius_mm": 84.294},
    "rack": {"first_tooth": -7, "last_tooth": 7, "addendum_coefficient": 1.0, "dedendum_coefficient": 1.25},
    "layout": {"centre_to_datum_mm": 107.0},
    "trim": {"min_contact_ratio": 1.2, "hS2_mm": 25.13, "hS4_mm": 25.13, "hS6_mm": 25.51, "hS8_mm": 25.51},
    "targets": {"continuous_drive_deg": 60.0},
}


def is_paper_design(params) -> bool:
    """The template is the paper's mechanism (:data:`PAPER_DESIGN`: module, teeth, α, H, RS1, the
    four trims, the design rules): only then do its printed figures stand beside the results
    (beside another design they would read as targets)."""
    for section, values in PAPER_DESIGN.items():
        got = getattr(params, section)
        for key, value in values.items():
            if not math.isclose(float(getattr(got, key)), float(value), rel_tol=0.0, abs_tol=1e-9):
                return False
    return True


def geometry_from_params(params) -> RackPinionGeometry:
    """The drawing of the template's parts (machined trims)."""
    pin, rack, trim = params.pinion, params.rack, params.trim
    values = dict(
        module_mm=pin.module_mm,
        teeth=pin.teeth,
        pressure_angle_rad=math.radians(pin.pressure_angle_deg),
        profile_shift=pin.profile_shift,
        pinion_addendum_coefficient=pin.addendum_coefficient,
        pinion_dedendum_coefficient=pin.dedendum_coefficient,
        rack_addendum_coefficient=rack.addendum_coefficient,
        rack_dedendum_coefficient=rack.dedendum_coefficient,
        centre_to_datum_mm=params.layout.centre_to_datum_mm,
        rack_first_tooth=rack.first_tooth,
        rack_last_tooth=rack.last_tooth,
        sector_first_tooth=pin.sector_first_tooth,
        sector_last_tooth=pin.sector_last_tooth,
        topped_radius_mm=pin.topped_radius_mm,
        hS2_mm=trim.hS2_mm,
        hS4_mm=trim.hS4_mm,
        hS6_mm=trim.hS6_mm,
        hS8_mm=trim.hS8_mm,
    )
    return RackPinionGeometry(**values)


def with_inputs(g: RackPinionGeometry, **replace) -> RackPinionGeometry:
    """The same drawing with some inputs replaced (solver checks, sensitivities)."""
    values = {k: getattr(g, k) for k in g.__dataclass_fields__ if not k.startswith("_")}
    values.update(replace)
    return RackPinionGeometry(**values)


# ============================================================================================
# Closed forms on the line of action
# ============================================================================================
# Towing drive side: pinion right flanks push rack left flanks along the line through the
# pitch point P = (0, h) with direction (cos α, −sin α); a point at signed distance t from P is
# (t·cos α, h − t·sin α). Contact starts where the rack's left top corner meets it (t < 0) and
# ends at the pinion tip circle (t > 0). Power drive side: rack right flanks push pinion left
# flanks along (cos α, sin α); contact ends where the rack's right top corner meets it.

def recess_length(g: RackPinionGeometry, radius: float) -> float:
    """t from P to where the towing line of action meets the circle of ``radius``:
    √(ρ² − rb²) − r·sin α (eq (1)-(2) recess term)."""
    return math.sqrt(radius * radius - g.base_radius ** 2) - g.pitch_radius * math.sin(g.pressure_angle_rad)


def contact_ratio(g: RackPinionGeometry, h_top: float, tip_radius: float | None = None) -> float:
    """ε of a pair whose rack tooth is trimmed to ``h_top`` on its drive-side corner (S4):
    ε = [(h_top − h)/sin α + √(Ra² − rb²) − r·sin α] / (π·m·cos α)   (eqs (1)-(2))."""
    a = g.pressure_angle_rad
    approach = (h_top - g.rolling_line_height) / math.sin(a)
    return (approach + recess_length(g, tip_radius or g.tip_radius)) / g.base_pitch


def trim_height_for_contact_ratio(g: RackPinionGeometry, eps: float) -> float:
    """hS4 with contact_ratio(hS4) = ε: the inverse of :func:`contact_ratio`."""
    a = g.pressure_angle_rad
    return g.rolling_line_height + math.sin(a) * (eps * g.base_pitch - recess_length(g, g.tip_radius))


def travel_corner_on_circle(g: RackPinionGeometry, k: int, h_corner: float, radius: float) -> float:
    """Rack travel L at which the drive-side (left) top corner of rack tooth k, at height
    ``h_corner``, lies on the circle of ``radius`` about the pinion centre, right of it.
    For k = first + 1, Ra, hS4 this is eq (3); for k = first, RS1, hS2 eqs (4)/(22):
    L = −k·p + s/2 − (h_c − h)·tan α + R·sin θ,  R·cos θ = H − h_c."""
    x_on_circle = math.sqrt(radius * radius - (g.centre_height - h_corner) ** 2)
    return x_on_circle - k * g.pitch + float(g.rack_half_width(h_corner))


def _polar_angle(g: RackPinionGeometry, point) -> float:
    return math.atan2(point[0], g.centre_height - point[1])


def phi_towing_conjugate_end(g: RackPinionGeometry, j: int, radius: float | None = None) -> float:
    """Pinion angle at which the conjugate contact of pinion tooth j's drive (right) flank
    reaches its tip corner at ``radius`` (S1 for G1 at RS1: the 'S1 engagement', eq (17)).
    The contact point is on the towing line of action at t = recess_length(radius); the
    tooth's flank point there has polar angle (j + ½)τ + φ + β(ρ)."""
    radius = radius or g.pinion_tip_radius(j)
    a = g.pressure_angle_rad
    t = recess_length(g, radius)
    point = (t * math.cos(a), g.rolling_line_height - t * math.sin(a))
    return _polar_angle(g, point) - float(g.involute_half_angle(radius)) - (j + 0.5) * g.angular_pitch


def pressure_angle_at_power_corner(g: RackPinionGeometry, h_corner: float) -> float:
    """α at the pinion radius where the power-side contact meets the corner at ``h_corner``
    (paper's αS6 = ∠S6OB1, eq (18))."""
    a = g.pressure_angle_rad
    t = (h_corner - g.rolling_line_height) / math.sin(a)
    radius = math.hypot(g.base_radius, g.pitch_radius * math.sin(a) - t)
    return math.acos(g.base_radius / radius)


def _towing_conjugate_start(g: RackPinionGeometry, k: int) -> float:
    """Pinion angle at which towing contact on rack tooth k's left flank starts: the line of
    action reaches its left top corner, t = −(h_L − h)/sin α; L = −k·p + w + t/cos α."""
    a = g.pressure_angle_rad
    t = -(g.rack_corner_heights(k)[0] - g.rolling_line_height) / math.sin(a)
    return (-k * g.pitch + g.rack_half_thickness_at_rolling_line + t / math.cos(a)) / g.pitch_radius


def _power_conjugate_start(g: RackPinionGeometry, j: int) -> float:
    """Pinion angle at which power contact between pinion tooth j's left flank and rack tooth
    k = j's right flank starts: the power line of action at the pinion tip circle,
    t = −recess; L = t/cos α − k·p − w."""
    a = g.pressure_angle_rad
    t = -recess_length(g, g.pinion_tip_radius(j))
    return (t / math.cos(a) - j * g.pitch - g.rack_half_thickness_at_rolling_line) / g.pitch_radius


def continuous_towing_angle(g: RackPinionGeometry) -> float:
    """Last pinion angle of unbroken conjugate drive with the pinion driving (φ > 0): pinion
    tooth j drives rack tooth j + 1 from the rack corner (start) to its own tip corner (end);
    each pair must start before the previous one ends. For the paper's design this is the
    S1 engagement of G1 (eq (17)) unless a handover fails first."""
    j_last = g.sector_first_tooth
    for j in range(0, j_last, -1):  # pair (j, j + 1) hands over to (j − 1, j)
        end = phi_towing_conjugate_end(g, j)
        if _towing_conjugate_start(g, j) > end:
            return end
    return phi_towing_conjugate_end(g, j_last)


def continuous_power_angle(g: RackPinionGeometry) -> float:
    """Last pinion angle of unbroken conjugate drive with the rack driving (φ > 0): rack tooth k
    drives pinion tooth j = k from the pinion tip (start) to the rack's right top corner (end,
    S6 for the first rack tooth, eq (19))."""
    first = g.rack_first_tooth
    for k in range(0, first, -1):
        if _power_conjugate_start(g, k - 1) > phi_power_conjugate_end(g, k, g.rack_corner_heights(k)[1]):
            return phi_power_conjugate_end(g, k, g.rack_corner_heights(k)[1])
    return phi_power_conjugate_end(g, first, g.rack_corner_heights(first)[1])


def reference_contact_radius(g: RackPinionGeometry) -> float:
    """OS (fig. 7): radius of the towing contact point at angle 0 (rack tooth centred): the
    line of action at t = −cos α·(rack half thickness at the rolling line)."""
    a = g.pressure_angle_rad
    t = -math.cos(a) * g.rack_half_thickness_at_rolling_line
    return math.hypot(g.base_radius, g.pitch_radius * math.sin(a) + t)


def disengage_closed_form(g: RackPinionGeometry) -> tuple[float, float]:
    """(φ, L) when G1's tip corner S1, dragging the first rack tooth's left flank, reaches S2
    (S2 on the RS1 circle): eq (22) for L; φ puts S1 at S2's polar angle."""
    k, j = g.rack_first_tooth, g.sector_first_tooth
    travel = travel_corner_on_circle(g, k, g.hS2_mm, g.topped_radius_mm)
    s2 = g.trim_corners(travel)["S2"]
    phi = _polar_angle(g, s2) - float(g.involute_half_angle(g.topped_radius_mm)) - (j + 0.5) * g.angular_pitch
    return phi, travel


def towing_travel_closed_form(g: RackPinionGeometry, phi) -> np.ndarray:
    """Towing curve written out for the paper's mechanism story, to cross-check the push model:
    L = r·φ − Δa·tan α up to the S1 engagement; then G1's right tip corner S1 = (x1, y1) drags the
    first rack tooth's left flank, L = x1 − k·p + w(y1); from the disengage angle the rack stands."""
    phi = np.asarray(phi, dtype=float)
    j, k = g.sector_first_tooth, g.rack_first_tooth
    phi_s1 = phi_towing_conjugate_end(g, j)
    phi_dis, travel_dis = disengage_closed_form(g)
    corner = g.pinion_tip_corner(j, phi)
    dragged = corner[..., 0] - k * g.pitch + g.rack_half_width(corner[..., 1])
    return np.where(phi <= phi_s1, g.pitch_radius * phi - g.flank_offset, np.where(phi < phi_dis, dragged, travel_dis))


def tangent_top_height(g: RackPinionGeometry, corner, k: int, travel: float,
                       flank_through_centre: bool = False) -> float:
    """Height at which the tangent, at ``corner``, to the circle about the pinion centre through
    ``corner`` meets the power-side (right) flank of rack tooth k at ``travel`` — the highest
    straight trimmed top from that corner the tip circle passes over (paper, eqs (8)-(16)).
    ``flank_through_centre`` draws the flank through the tooth centre on the pitch line,
    as the paper's lines (9)/(16) do (half a tooth off)."""
    qx, qy = float(corner[0]), float(corner[1])
    slope = qx / (g.centre_height - qy)
    tan_a = math.tan(g.pressure_angle_rad)
    h = g.made_rolling_line_height  # the flank as made
    half = 0.0 if flank_through_centre else g.rack_half_thickness_at_rolling_line
    # flank: x = c + half − (y − h)·tan α;  tangent: y = qy + slope·(x − qx)
    c = k * g.pitch + travel
    return (qy + slope * (c + half + h * tan_a - qx)) / (1.0 + slope * tan_a)


@dataclass(frozen=True)
class TrimDesign:
    """The paper's trimming design chain (solved values, not the machined ones)."""

    hS4_mm: float  # from ε = trim.min_contact_ratio (eqs (1)-(2))
    travel_S3S4_mm: float  # eq (3) at the solved hS4
    RS1_mm: float  # S1 engagement at the target angle (eqs (5)-(6), (17))
    hS2_mm: float  # equal travel at S1/S2 (eq (4))
    RS1_equal_travel_at_machined_hS2_mm: float  # eq (4) with the machined hS2 and L(S3/S4)


def solve_trims(g: RackPinionGeometry, min_contact_ratio: float, target_angle: float) -> TrimDesign:
    """hS4 from the contact ratio; L(S3/S4) from eq (3); RS1 so that the S1 engagement angle
    equals the target (its smallest, lightest value); hS2 so that S1 reaches S2 at the same
    rack travel (eq (4), shortest travel). NaN where no value in the physical range works."""
    first = g.rack_first_tooth
    H = g.centre_height
    hS4 = trim_height_for_contact_ratio(g, min_contact_ratio)
    travel = travel_corner_on_circle(g, first + 1, hS4, g.tip_radius)

    j = g.sector_first_tooth

    def s1_miss(radius: float) -> float:
        return phi_towing_conjugate_end(g, j, radius) - target_angle

    lo, hi = g.form_radius + 1e-9, g.tip_radius
    rs1 = float(_brentq()(s1_miss, lo, hi, xtol=1e-12)) if s1_miss(lo) < 0 < s1_miss(hi) else math.nan

    hS2 = math.nan
    if math.isfinite(rs1):
        def travel_miss(h_corner: float) -> float:
            return travel_corner_on_circle(g, first, h_corner, rs1) - travel

        h_lo = max(g.made_rolling_line_height, H - rs1) + 1e-9
        h_hi = g.rack_top_height
        if h_lo < h_hi and travel_miss(h_lo) < 0 < travel_miss(h_hi):
            hS2 = float(_brentq()(travel_miss, h_lo, h_hi, xtol=1e-12))

    machined_travel = travel_corner_on_circle(g, first + 1, g.hS4_mm, g.tip_radius)
    x_s1 = machined_travel + first * g.pitch - float(g.rack_half_width(g.hS2_mm))
    rs1_eq4 = math.hypot(x_s1, H - g.hS2_mm)
    return TrimDesign(hS4, travel, rs1, hS2, rs1_eq4)


def towing_curve(params, step_deg: float = ANGLE_STEP_DEG) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Arrays for the report: pinion angle (deg, 0 → towing.max_angle_deg), rack travel on the
    forward swing (mm) and on the return swing (mm, same angles)."""
    g = geometry_from_params(params)
    t = analyse_towing(g, params.towing.max_angle_deg, step_deg)
    return t.forward.phi_deg, t.forward.travel_mm, t.back.travel_mm[::-1]


def _brentq():
    """scipy's root finder, imported when first needed (sweep workers import this module and never
    call it)."""
    from scipy.optimize import brentq

    return brentq
