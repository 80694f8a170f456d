"""Power mode of the trimmed rack and pinion (the rack drives), numpy/scipy only: the closed-form
pinion angle the rack drives it to, and where a meshed pinion flank touches a straight rack flank.

Frame, angle 0 and tooth numbering: :mod:`gearcheck.geometry.rack_pinion`. φ > 0 and L > 0 are
the direction in which the first rack tooth (k = rack.first_tooth) comes under the pinion.
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry.rack_pinion import RackPinionGeometry

# Most mesh vertices walked from the one nearest the FCL contact to the flank's support vertex.
TANGENCY_WINDOW = 8


def phi_power_conjugate_end(g: RackPinionGeometry, k: int, h_corner: float) -> float:
    """Pinion angle at which the conjugate contact on rack tooth k's power-side (right) flank
    reaches its top corner at ``h_corner`` (S6 for the first tooth, eq (19)): the contact
    point is at t = (h_c − h)/sin α on the power line of action, where the flank
    x = k·p + L + w(h_c) passes; φ = (L − Δa·tan α)/r (:attr:`RackPinionGeometry.flank_offset`)."""
    a = g.pressure_angle_rad
    t = (h_corner - g.rolling_line_height) / math.sin(a)
    travel = t * math.cos(a) - k * g.pitch - float(g.rack_half_width(h_corner))
    return (travel - g.flank_offset) / g.pitch_radius


def power_corner(g: RackPinionGeometry) -> tuple[float, float, float]:
    """S6 of the first rack tooth: x in the rack frame, its depth below the pinion centre
    (H + Δa − hS6), and the travel at which it leaves the pinion's tip circle (the pinion is released)."""
    x0 = g.rack_first_tooth * g.pitch + float(g.rack_half_width(g.hS6_mm))
    dy = g.centre_height - g.hS6_mm
    return x0, dy, math.sqrt(g.tip_radius ** 2 - dy ** 2) - x0


def power_model_angle(g: RackPinionGeometry, travel: float) -> float:
    """Pinion angle driven by the rack (φ > 0, L > 0): conjugate (L − Δa·tan α)/r (the pinion held
    against the driving flank) up to the S6 engagement (eq 19); beyond it the corner
    S6 = (k·p + L + w(hS6), hS6) rides on the left involute flank of pinion tooth j = k
    (k = rack.first_tooth): φ = γ(S6) + β(ρ(S6)) − (j + ½)·τ, until S6 leaves the tip circle and
    the pinion stops."""
    k = g.rack_first_tooth
    if travel <= phi_power_conjugate_end(g, k, g.hS6_mm) * g.pitch_radius + g.flank_offset:
        return (travel - g.flank_offset) / g.pitch_radius
    x0, dy, release = power_corner(g)
    x = x0 + min(travel, release)
    rho = math.hypot(x, dy)
    return math.atan2(x, dy) + float(g.involute_half_angle(rho)) - (k + 0.5) * g.angular_pitch


def power_model_travel(g: RackPinionGeometry, angle: float) -> float:
    """Inverse of :func:`power_model_angle`: the rack travel that has driven the pinion to
    ``angle`` (NaN at or past the release, where any further travel gives the same angle)."""
    end = phi_power_conjugate_end(g, g.rack_first_tooth, g.hS6_mm)
    if angle <= end:
        return angle * g.pitch_radius + g.flank_offset
    release = power_corner(g)[2]
    if angle >= power_model_angle(g, release):
        return math.nan
    from scipy.optimize import brentq  # lazy: sweep workers import this module and never call it

    return float(brentq(lambda t: power_model_angle(g, t) - angle, end * g.pitch_radius + g.flank_offset,
                        release, xtol=1e-10))


def tangency_offset(profile_world: np.ndarray, near: np.ndarray, normal: np.ndarray, corner: np.ndarray,
                    up: np.ndarray, window: int = TANGENCY_WINDOW) -> float:
    """Signed distance along a straight rack flank (direction ``up``, towards its ``corner``) from
    the corner to the point where the pinion's flank is tangent to it, from the pinion's mesh
    outline (world xy, ordered) near the contact point ``near``.

    A polygonal flank (vertices on the exact flank, chords inside it) puts the raw nearest point
    on a vertex, which jumps by a chord along the flank. The support vertex (least
    ``normal``·V, ``normal`` the flank's outward normal) is where the flank direction lies
    between the directions of the two chords on either side. On the smooth flank those chord
    directions are the tangents at (about) the chords' midpoints, and the tangent turns nearly
    uniformly between them, so the tangency point is found by linear interpolation of the
    tangent's normal component along M1 → V → M2. NaN when no vertex near ``near`` is a support
    vertex of the flank direction."""
    n = len(profile_world)
    height = profile_world @ normal
    i = int(np.argmin(np.linalg.norm(profile_world - near[:2], axis=1)))
    for _ in range(window):  # walk down to the local support vertex (never past the tooth)
        if 0 < i < n - 1 and height[i - 1] < height[i]:
            i -= 1
        elif 0 < i < n - 1 and height[i + 1] < height[i]:
            i += 1
        else:
            break
    if not 0 < i < n - 1:
        return math.nan
    v0, v1, v2 = profile_world[i - 1], profile_world[i], profile_world[i + 1]
    e1, e2 = v1 - v0, v2 - v1
    l1, l2 = float(np.linalg.norm(e1)), float(np.linalg.norm(e2))
    s1, s2 = float(normal @ e1) / l1, float(normal @ e2) / l2
    if not (s1 <= 0.0 <= s2) or s2 - s1 <= 0.0:
        return math.nan
    along = -s1 / (s2 - s1) * 0.5 * (l1 + l2)
    point = v0 + e1 * (0.5 + along / l1) if along <= 0.5 * l1 else v1 + e2 * ((along - 0.5 * l1) / l2)
    return float(up @ (point - corner))
