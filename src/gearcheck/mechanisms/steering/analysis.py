"""Analytical model of the trimmed nose-wheel steering rack and pinion (seed 003), numpy/scipy.

Two independent layers:

* closed forms on the line of action (contact ratio, eq (3)/(4) travels, the S1/S6 engagement
  angles, tangent constructions, the trimming solver), written for any basic profile;
* an exact-polyline **push model** of towing: for each pinion angle the rack sits at the
  smallest travel (forward swing) or the largest (return swing) at which no pinion tooth
  overlaps a rack tooth, moving only when a tooth pushes it. The disengage and re-engage
  angles, the towing curve and the interference check come from it; the closed forms are
  used to cross-check it (tests).

Frame, tooth indices and angle-0 convention: :mod:`gearcheck.geometry.rack_pinion`. All
angles are radians unless a name says ``_deg``; the towing direction is the one in which the
first rack tooth (k = rack.first_tooth) comes under the pinion (φ > 0, rack moving +x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from gearcheck.geometry.rack_pinion import RackPinionGeometry

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



def is_paper_design(params) -> bool:
    """The template is the paper's mechanism (m 4, z 42, α 25°, H 107): only then do its printed
    figures stand beside the results (beside another design they would read as targets)."""
    p = params.pinion
    return (math.isclose(p.module_mm, 4.0) and p.teeth == 42 and math.isclose(p.pressure_angle_deg, 25.0)
            and math.isclose(params.layout.centre_to_datum_mm, 107.0))


# Named tolerances.
TRAVEL_TOL_MM = 1e-4  # rack standing still / a pair touching, within this (≫ polyline error, measured ≤ 0.04 µm)
ANGLE_STEP_DEG = 0.05  # towing-curve grid; events are refined by bisection
BISECT_TOL_RAD = 1e-7
CHECK_ANGLES_DEG = (68.0, 72.0, 75.0)  # towing-curve sample points reported as figures
# Only the rack's flanks push it. A trimmed top, even a steeply slanted one, is a cut the
# pinion is meant to clear (its tip land grazes S2 at most): a tooth that has to drive the rack
# through a top jams, and the overlap is reported as interference. A rack corner (a flank's end)
# can push through the pinion's flank, but only while the contact normal lies within 60° of the
# travel (|n_x| ≥ 0.5, flanks: cos α ≥ 0.82 for α ≤ 35°): flatter, the normal force would exceed
# twice the push. That bounds how fast a tooth drives the rack, |dL/dφ| = |v·n| / |n_x| ≤
# r_tip / 0.5; a push needing more within one step is a jam as well. The mesh sweep applies both
# rules to its faces (flank triangles only) and its reach.
PUSH_NORMAL_MIN = 0.5
PUSH_RATE_PER_TIP_RADIUS = 1.0 / PUSH_NORMAL_MIN


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
    x_on_circle = math.sqrt(radius * radius - (g.centre_to_datum_mm - h_corner) ** 2)
    return x_on_circle - k * g.pitch + float(g.rack_half_width(h_corner))


def _polar_angle(g: RackPinionGeometry, point) -> float:
    return math.atan2(point[0], g.centre_to_datum_mm - point[1])


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


def phi_power_conjugate_end(g: RackPinionGeometry, k: int, h_corner: float) -> float:
    """Pinion angle at which the conjugate contact on rack tooth k's power-side (right) flank
    reaches its top corner at ``h_corner`` (S6 for the first tooth, eq (19)): the contact
    point is at t = (h_c − h)/sin α on the power line of action, where the flank
    x = k·p + L + w(h_c) passes; φ = L/r."""
    a = g.pressure_angle_rad
    t = (h_corner - g.rolling_line_height) / math.sin(a)
    travel = t * math.cos(a) - k * g.pitch - float(g.rack_half_width(h_corner))
    return travel / g.pitch_radius


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
    L = r·φ up to the S1 engagement; then G1's right tip corner S1 = (x1, y1) drags the first
    rack tooth's left flank, L = x1 − k·p + w(y1); from the disengage angle the rack stands."""
    phi = np.asarray(phi, dtype=float)
    j, k = g.sector_first_tooth, g.rack_first_tooth
    phi_s1 = phi_towing_conjugate_end(g, j)
    phi_dis, travel_dis = disengage_closed_form(g)
    corner = g.pinion_tip_corner(j, phi)
    dragged = corner[..., 0] - k * g.pitch + g.rack_half_width(corner[..., 1])
    return np.where(phi <= phi_s1, g.pitch_radius * phi, np.where(phi < phi_dis, dragged, travel_dis))


def tangent_top_height(g: RackPinionGeometry, corner, k: int, travel: float, flank_through_centre: bool = False) -> float:
    """Height at which the tangent, at ``corner``, to the circle about the pinion centre through
    ``corner`` meets the power-side (right) flank of rack tooth k at ``travel`` — the highest
    straight trimmed top from that corner the tip circle passes over (paper, eqs (8)-(16)).
    ``flank_through_centre`` draws the flank through the tooth centre on the pitch line,
    as the paper's lines (9)/(16) do (half a tooth off)."""
    qx, qy = float(corner[0]), float(corner[1])
    slope = qx / (g.centre_to_datum_mm - qy)
    tan_a = math.tan(g.pressure_angle_rad)
    h = g.rolling_line_height
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
    H = g.centre_to_datum_mm
    hS4 = trim_height_for_contact_ratio(g, min_contact_ratio)
    travel = travel_corner_on_circle(g, first + 1, hS4, g.tip_radius)

    j = g.sector_first_tooth

    def s1_miss(radius: float) -> float:
        return phi_towing_conjugate_end(g, j, radius) - target_angle

    lo, hi = g.form_radius + 1e-9, g.tip_radius
    rs1 = float(brentq(s1_miss, lo, hi, xtol=1e-12)) if s1_miss(lo) < 0 < s1_miss(hi) else math.nan

    hS2 = math.nan
    if math.isfinite(rs1):
        def travel_miss(h_corner: float) -> float:
            return travel_corner_on_circle(g, first, h_corner, rs1) - travel

        h_lo = max(g.rolling_line_height, H - rs1) + 1e-9
        h_hi = g.rack_top_height
        if h_lo < h_hi and travel_miss(h_lo) < 0 < travel_miss(h_hi):
            hS2 = float(brentq(travel_miss, h_lo, h_hi, xtol=1e-12))

    machined_travel = travel_corner_on_circle(g, first + 1, g.hS4_mm, g.tip_radius)
    x_s1 = machined_travel + first * g.pitch - float(g.rack_half_width(g.hS2_mm))
    rs1_eq4 = math.hypot(x_s1, H - g.hS2_mm)
    return TrimDesign(hS4, travel, rs1, hS2, rs1_eq4)


# ============================================================================================
# Push model (exact polylines)
# ============================================================================================

def _rack_chains(g: RackPinionGeometry, k: int):
    """Left and right boundary of rack tooth k at L = 0 as increasing-y polylines (y, x): the
    top (S2–S6 or S4–S8) joins the chain on its lower side. Also its two flanks alone (the
    faces that push the rack), the root height and the top height."""
    bl, br, tr, tl = g.rack_tooth_polygon(k, 0.0)
    y0, h_l, h_r = bl[1], tl[1], tr[1]
    left_pts, right_pts = [bl, tl] + ([tr] if h_r > h_l else []), [br, tr] + ([tl] if h_l > h_r else [])

    def chain(pts):
        return np.array([q[1] for q in pts]), np.array([q[0] for q in pts])

    return chain(left_pts), chain(right_pts), chain([bl, tl]), chain([br, tr]), y0, max(h_l, h_r)


def _active(g: RackPinionGeometry, j: int, y_top: float, phis: np.ndarray) -> np.ndarray:
    """Pinion angles at which tooth j can reach down to ``y_top`` (cheap bound)."""
    theta = np.abs(np.asarray(g.pinion_tooth_angle(j, phis)))
    beta_max = float(g.involute_half_angle(g.form_radius))
    lowest = g.centre_to_datum_mm - g.pinion_tip_radius(j) * np.cos(np.clip(theta - beta_max, 0.0, math.pi))
    return lowest <= y_top + 1e-6


def _tooth_pairs_by_pinion(g: RackPinionGeometry) -> dict[int, list[int]]:
    """Rack teeth each pinion tooth can meet: pinion tooth j lives between rack teeth j and
    j + 1; one more on each side catches a tooth that passes over a trimmed top."""
    out = {}
    for j in range(g.sector_first_tooth, g.sector_last_tooth + 1):
        ks = [k for k in (j - 1, j, j + 1, j + 2) if g.rack_first_tooth <= k <= g.rack_last_tooth]
        if ks:
            out[j] = ks
    return out


def tooth_pairs(g: RackPinionGeometry) -> list[tuple[int, int]]:
    """All (j, k) pairs the push model checks, in a fixed order."""
    return [(j, k) for j, ks in _tooth_pairs_by_pinion(g).items() for k in ks]


def _offsets(px, py, flat, inv_dy, slope_x, chain, want_lo: bool = True, want_hi: bool = True):
    """min and max over the chain's heights of [pinion boundary x(y) − chain x(y)], per angle
    (rows of the pinion polygon's vertices px, py): over the pinion vertices within the chain's
    heights and the pinion edges crossing the chain's vertex heights (±inf where none; None for
    an end not wanted)."""
    ys, xs = chain
    inside = (py >= ys[0]) & (py <= ys[-1])
    d = px - np.interp(py, ys, xs)
    hi = np.where(inside, d, -np.inf).max(axis=1) if want_hi else None
    lo = np.where(inside, d, np.inf).min(axis=1) if want_lo else None
    for uy, ux in zip(ys, xs):
        t = (uy - py) * inv_dy
        crossing = ~flat & (t >= 0.0) & (t <= 1.0)
        x = px + (uy - py) * slope_x
        if want_hi:
            hi = np.maximum(hi, np.where(crossing, x, -np.inf).max(axis=1) - ux)
        if want_lo:
            lo = np.minimum(lo, np.where(crossing, x, np.inf).min(axis=1) - ux)
    return lo, hi


def overlap_intervals(g: RackPinionGeometry, phis, flanks: bool = False):
    """For every pair (j, k) of :func:`tooth_pairs` and every pinion angle φ: the interval
    (lo, hi) of rack travels L at which rack tooth k overlaps pinion tooth j (NaN where their
    heights never overlap). Both teeth are convex, so hi = max over y of [pinion right edge(y)
    − rack left edge(y)] and lo = min over y of [pinion left edge(y) − rack right edge(y)],
    and the extremes lie at vertex heights of either polygon. L = hi: the pinion tooth touches
    the left side of the rack tooth (towing drive side); L = lo: its right side.

    With ``flanks`` the intervals are those of each flank segment alone (the faces that push
    the rack): returns pairs, (lo, hi) of the left flanks and (lo, hi) of the right flanks; a
    tooth in (lo, hi) of a left flank cuts it, and the rack clears it at L = hi (pushed +x)."""
    phis = np.atleast_1d(np.asarray(phis, dtype=float))
    pairs: list[tuple[int, int]] = []
    rows: list[list[np.ndarray]] = []
    for j, ks in _tooth_pairs_by_pinion(g).items():
        chains = [_rack_chains(g, k) for k in ks]
        mask = _active(g, j, max(c[5] for c in chains), phis)
        idx = np.flatnonzero(mask)
        if idx.size:
            rho, gam = g.pinion_contact_polygon_polar(j)
            ang = gam[None, :] + g.pinion_tooth_angle(j, phis[idx])[:, None]
            px = rho * np.sin(ang)
            py = g.centre_to_datum_mm - rho * np.cos(ang)
            bx = np.concatenate([px[:, 1:], px[:, :1]], axis=1)
            by = np.concatenate([py[:, 1:], py[:, :1]], axis=1)
            dy = by - py
            flat = dy == 0.0
            inv_dy = 1.0 / np.where(flat, 1.0, dy)
            slope_x = (bx - px) * inv_dy
            y_min, y_max = py.min(axis=1), py.max(axis=1)
        for k, (left, right, left_flank, right_flank, y0, top) in zip(ks, chains):
            pairs.append((j, k))
            out = [np.full(phis.shape, np.nan) for _ in range(4 if flanks else 2)]
            rows.append(out)
            if not idx.size:
                continue
            overlap = (y_min <= top) & (y_max >= y0)
            if not overlap.any():
                continue
            if flanks:
                found = [_offsets(px, py, flat, inv_dy, slope_x, c) for c in (left_flank, right_flank)]
            else:
                found = [(_offsets(px, py, flat, inv_dy, slope_x, right, want_hi=False)[0],
                          _offsets(px, py, flat, inv_dy, slope_x, left, want_lo=False)[1])]
            for n, (lo_m, hi_m) in enumerate(found):
                ok = overlap & np.isfinite(hi_m) & np.isfinite(lo_m)
                out[2 * n][idx[ok]] = lo_m[ok]
                out[2 * n + 1][idx[ok]] = hi_m[ok]
    shape = (len(pairs), phis.size)
    arrays = [np.array([r[n] for r in rows]).reshape(shape) for n in range(4 if flanks else 2)]
    if flanks:
        return pairs, (arrays[0], arrays[1]), (arrays[2], arrays[3])
    return pairs, arrays[0], arrays[1]


def push_intervals(g: RackPinionGeometry, phis, direction: int) -> tuple[list[tuple[int, int]], np.ndarray, np.ndarray]:
    """(pairs, lo, hi) of the flanks that push the rack towards ``direction``: left flanks (+x),
    right flanks (−x)."""
    pairs, left, right = overlap_intervals(g, phis, flanks=True)
    return (pairs, *left) if direction > 0 else (pairs, *right)


def pair_push_interval(g: RackPinionGeometry, j: int, k: int, phis, direction: int) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of :func:`push_intervals` for one pair."""
    pairs, lo, hi = push_intervals(g, phis, direction)
    n = pairs.index((j, k))
    return lo[n], hi[n]


@dataclass(frozen=True)
class Sweep:
    """Rack travel along a swing of the pinion (rack pushed only by teeth)."""

    phi_rad: np.ndarray
    travel_mm: np.ndarray
    pairs: list[tuple[int, int]]
    lo: np.ndarray  # (n_pairs, n_phi) intervals of the pushing flanks, see push_intervals
    hi: np.ndarray
    direction: int  # +1: φ increasing, rack pushed +x; −1: φ decreasing, rack pushed −x
    max_overlap_mm: float  # deepest overlap left after the pushes (interference if > tolerance)
    max_rate: float  # largest |ΔL/Δφ| between grid points, mm/rad
    overlap_mm: np.ndarray  # overlap depth at each angle (0: clear or touching)

    @property
    def phi_deg(self) -> np.ndarray:
        return np.degrees(self.phi_rad)

    @property
    def jammed(self) -> np.ndarray:
        """Angles at which a tooth overlaps the rack it could not push (deeper than TRAVEL_TOL_MM)."""
        return self.overlap_mm > TRAVEL_TOL_MM


def push_reach(g: RackPinionGeometry, step_rad: float) -> float:
    """The farthest a tooth can drive the rack while the pinion turns by ``step_rad``."""
    return PUSH_RATE_PER_TIP_RADIUS * g.tip_radius * abs(step_rad)


def _step(lo: np.ndarray, hi: np.ndarray, travel: float, direction: int, reach: float = math.inf) -> float:
    """Travel after a turn: the nearest travel towards ``direction`` at which no pushing flank
    cuts a pinion tooth (``lo``, ``hi`` from :func:`push_intervals`), unless that takes more
    than ``reach`` (a jam: the rack stays)."""
    target = travel
    while True:
        cut = (lo < target) & (target < hi)
        if not cut.any():
            break
        target = float(hi[cut].max()) if direction > 0 else float(lo[cut].min())
    return target if abs(target - travel) <= reach else travel


def _overlap_depth(lo: np.ndarray, hi: np.ndarray, travel: float) -> float:
    inside = (lo < travel) & (travel < hi)
    if not inside.any():
        return 0.0
    return float(np.minimum(travel - lo[inside], hi[inside] - travel).max())


def sweep(g: RackPinionGeometry, phis, travel_start: float, direction: int, intervals=None) -> Sweep:
    """Swing the pinion through ``phis`` (monotone, in the sense of ``direction``) starting
    with the rack at ``travel_start``; at each angle the rack moves only as far as a pinion
    tooth pushes it through a flank, at most :func:`push_reach` per step (see
    :data:`PUSH_NORMAL_MIN`); any overlap left (with the whole tooth) is interference.
    ``intervals`` may pass (pairs, push lo, push hi, overlap lo, overlap hi) precomputed at ``phis``."""
    phis = np.asarray(phis, dtype=float)
    if intervals is None:
        pairs, lo, hi = push_intervals(g, phis, direction)
        _, full_lo, full_hi = overlap_intervals(g, phis)
    else:
        pairs, lo, hi, full_lo, full_hi = intervals
    travel = np.empty(phis.size)
    depth = np.zeros(phis.size)
    current = float(travel_start)
    for i in range(phis.size):
        step = phis[i] - phis[i - 1] if i else 0.0
        current = _step(lo[:, i], hi[:, i], current, direction, push_reach(g, step))
        travel[i] = current
        depth[i] = _overlap_depth(full_lo[:, i], full_hi[:, i], current)
    rate = float(np.max(np.abs(np.diff(travel) / np.diff(phis)))) if phis.size > 1 else 0.0
    return Sweep(phis, travel, pairs, lo, hi, direction, float(depth.max()) if depth.size else 0.0, rate, depth)


def _travel_after(g: RackPinionGeometry, phi: float, travel_before: float, direction: int, phi_before: float) -> float:
    """Rack travel at one angle, given where it was at ``phi_before`` (for bisection)."""
    _, lo, hi = push_intervals(g, [phi], direction)
    return _step(lo[:, 0], hi[:, 0], travel_before, direction, push_reach(g, phi - phi_before))


def _bisect(predicate, a: float, b: float) -> float:
    """Boundary between a (predicate False) and b (predicate True)."""
    while abs(b - a) > BISECT_TOL_RAD:
        mid = 0.5 * (a + b)
        if predicate(mid):
            b = mid
        else:
            a = mid
    return 0.5 * (a + b)


@dataclass(frozen=True)
class Towing:
    forward: Sweep  # 0 → max angle
    back: Sweep  # max angle → 0, starting where the forward swing left the rack
    disengage_rad: float  # rack stops for good (forward); NaN if still moving at the end
    travel_at_disengage_mm: float
    grazing_end_rad: float  # the last pusher stops touching the standing rack (forward)
    reengage_rad: float  # a tooth picks the rack up again (return)


def towing_grid(max_angle_deg: float, step_deg: float = ANGLE_STEP_DEG, extra_deg=CHECK_ANGLES_DEG) -> np.ndarray:
    """Pinion angles (rad) from 0 to the towing swing, every ``step_deg``, plus ``extra_deg``."""
    n = max(int(math.ceil(max_angle_deg / step_deg)), 1)
    grid = np.linspace(0.0, max_angle_deg, n + 1)
    extra = [a for a in extra_deg if 0.0 <= a <= max_angle_deg]
    return np.radians(np.unique(np.concatenate([grid, extra])))


def analyse_towing(g: RackPinionGeometry, max_angle_deg: float, step_deg: float = ANGLE_STEP_DEG,
                   extra_deg=CHECK_ANGLES_DEG) -> Towing:
    """Forward and return towing swings of the push model, with the disengage angle (from it
    on the rack never moves again), how long the last pushing tooth still touches the standing
    rack (zero-clearance grazing), and the re-engage angle (the return swing picks the rack
    up), each refined by bisection between grid angles."""
    phis = towing_grid(max_angle_deg, step_deg, extra_deg)
    # every interval once on the grid: left flanks push the forward swing, right flanks the return
    pairs, (left_lo, left_hi), (right_lo, right_hi) = overlap_intervals(g, phis, flanks=True)
    _, full_lo, full_hi = overlap_intervals(g, phis)
    fwd = sweep(g, phis, 0.0, +1, (pairs, left_lo, left_hi, full_lo, full_hi))  # angle 0: tight mesh, rack tooth 0 centred
    end = float(fwd.travel_mm[-1])
    moving_late = end - np.interp(phis[-1] - math.radians(1.0), phis, fwd.travel_mm) > TRAVEL_TOL_MM
    dis = graze = math.nan
    if not moving_late:
        i = int(np.argmax(fwd.travel_mm >= end - TRAVEL_TOL_MM))
        if i > 0:
            before = float(fwd.travel_mm[i - 1])
            dis = _bisect(lambda p: _travel_after(g, p, before, +1, phis[i - 1]) >= end - TRAVEL_TOL_MM, phis[i - 1], phis[i])
        else:
            dis = float(phis[0])
        # the pair that pushed last, and where it stops touching
        n = int(np.nanargmin(np.abs(np.where(np.isfinite(fwd.hi[:, i]), fwd.hi[:, i] - end, np.inf))))
        j, k = fwd.pairs[n]

        def apart(p: float) -> bool:
            hi = pair_push_interval(g, j, k, [p], +1)[1][0]
            return not (np.isfinite(hi) and hi >= end - TRAVEL_TOL_MM)

        touching = np.isfinite(fwd.hi[n]) & (fwd.hi[n] >= end - TRAVEL_TOL_MM)
        later = np.flatnonzero(~touching[i + 1:])
        if later.size:
            m = i + 1 + int(later[0])
            graze = _bisect(apart, phis[m - 1], phis[m])

    back_phis = phis[::-1]
    back = sweep(g, back_phis, end, -1, (pairs, right_lo[:, ::-1], right_hi[:, ::-1], full_lo[:, ::-1], full_hi[:, ::-1]))
    re = math.nan
    moved = back.travel_mm < end - TRAVEL_TOL_MM
    if moved.any():
        i = int(np.argmax(moved))
        re = _bisect(lambda p: _travel_after(g, p, end, -1, back_phis[i - 1]) < end - TRAVEL_TOL_MM, back_phis[i - 1], back_phis[i])
    return Towing(fwd, back, dis, end if math.isfinite(dis) else math.nan, graze, re)


def towing_curve(params, step_deg: float = ANGLE_STEP_DEG) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Arrays for the report: pinion angle (deg, 0 → towing.max_angle_deg), rack travel on the
    forward swing (mm) and on the return swing (mm, same angles)."""
    g = geometry_from_params(params)
    t = analyse_towing(g, params.towing.max_angle_deg, step_deg)
    return t.forward.phi_deg, t.forward.travel_mm, t.back.travel_mm[::-1]


def travel_on_curve(t: Towing, phi: float) -> float:
    """Forward-swing travel at φ (interpolated between grid points; exact at grid points)."""
    return float(np.interp(phi, t.forward.phi_rad, t.forward.travel_mm))
