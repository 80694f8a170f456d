"""Analytical model of the track-drive sprocket of a bomb-disposal robot, numpy only.

Reconstruction of the paper's lost equations, readings and choices: docs/track.md. In short:

- eq. 6  d = p / sin(360°/z) (every other tooth engages); eq. 7 df = d − dR; eq. 8 de = d + 0.4
  (the paper's short tooth, kept as a rule so another z or p gives a consistent tip).
- eq. 1  P_Kφ = (φ − f)·G/n: the only physically readable form within 1 % of the paper's 234 N;
  it has no slope term (level-ground adhesion limit).
- pin: each pin segment a simply supported beam under a uniform load q from the track tension.
- eq. 10 Hertz line contact between the sleeve (R = dR/2) and the groove (ρf), concave:
  1/ρ = 1/R − 1/ρf, with F = max(G/n, P_Kφ) on one tooth.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import iso606


def drive_force_N(mass_kg: float, g_m_s2: float, adhesion: float, rolling: float, tracks: int) -> float:
    """P_Kφ = (φ − f)·G/n (paper eq. 1, lost; reconstructed): adhesion limit less rolling loss."""
    return (adhesion - rolling) * mass_kg * g_m_s2 / tracks


def climb_force_needed_N(mass_kg: float, g_m_s2: float, slope_deg: float, rolling: float, tracks: int) -> float:
    """Drive force per track to climb slope α at constant speed: G(sin α + f·cos α)/n."""
    a = math.radians(slope_deg)
    return mass_kg * g_m_s2 * (math.sin(a) + rolling * math.cos(a)) / tracks


def required_adhesion(slope_deg: float, rolling: float) -> float:
    """Adhesion φ needed to climb slope α: φ·G·cos α ≥ G(sin α + f·cos α) ⇒ φ ≥ tan α + f."""
    return math.tan(math.radians(slope_deg)) + rolling


def max_slope_deg(adhesion: float, rolling: float) -> float:
    """Steepest slope adhesion allows: tan α = φ − f."""
    return math.degrees(math.atan(adhesion - rolling))


def pin_shear_stress_MPa(tension_N: float, segments: int, pin_diameter_mm: float) -> float:
    """Largest transverse shear stress in a pin segment, 4V/(3A).

    Each of ``segments`` simply supported segments takes tension/segments as a uniform load q
    centred between its supports, so each support reaction (the largest shear force) is
    V = tension / (2·segments).
    """
    v = tension_N / (2.0 * segments)
    area = math.pi * pin_diameter_mm**2 / 4.0
    return 4.0 * v / (3.0 * area)


def pin_bending_stress_MPa(
    tension_N: float, segments: int, loaded_length_mm: float, span_mm: float, pin_diameter_mm: float
) -> float:
    """Bending stress at mid-span of a simply supported segment (span b2) under a uniform load over
    the centred length b1: M = W(2·b2 − b1)/8, σ = 32M/(πd³). Not checked by the paper."""
    w = tension_N / segments
    moment = w * (2.0 * span_mm - loaded_length_mm) / 8.0
    return 32.0 * moment / (math.pi * pin_diameter_mm**3)


@dataclass(frozen=True)
class HertzLine:
    peak_pressure_MPa: float  # σ_H, p0
    half_width_mm: float  # a, contact half-width


def hertz_line_contact(
    force_N: float, length_mm: float, curvature_per_mm: float, e1_MPa: float, nu1: float, e2_MPa: float, nu2: float
) -> HertzLine:
    """Two parallel cylinders in line contact (paper eq. 10):

    σ_H = sqrt( F·Σκ / (π·b·[(1−μ1²)/E1 + (1−μ2²)/E2]) ),  a = sqrt( 4F·[…] / (π·b·Σκ) ),

    Σκ = 1/ρ1 + 1/ρ2 for convex bodies, 1/ρ1 − 1/ρ2 for a cylinder in a concave groove.
    """
    if curvature_per_mm <= 0:
        raise ValueError("relative curvature must be positive (sleeve larger than the groove?)")
    compliance = (1.0 - nu1**2) / e1_MPa + (1.0 - nu2**2) / e2_MPa
    p0 = math.sqrt(force_N * curvature_per_mm / (math.pi * length_mm * compliance))
    a = math.sqrt(4.0 * force_N * compliance / (math.pi * length_mm * curvature_per_mm))
    return HertzLine(p0, a)


def chain_advance_per_turn_mm(pitch_mm: float, teeth: int) -> float:
    """Chain travel per sprocket revolution, z·p/2: every other tooth engages, so a link spans
    two of the z grooves and z/2 links pass per turn (exactly, for an even z; an odd z averages
    over two turns, the pins taking the other set of grooves on the second). Not π·d:
    the pins move on the pin circle d but the chain between them is a chord, shorter than the arc
    by the factor sin(2π/z)/(2π/z) (0.27 % at z = 49)."""
    return teeth * pitch_mm / 2.0


def link_pin_line_radius(gap: iso606.ToothGap) -> float:
    """Distance from the sprocket axis to a seated link's pin line at mid-span, R·cos(360°/z)."""
    return gap.pitch_radius_mm * math.cos(2.0 * gap.half_pitch_angle_rad)


def plate_offset_for_tip_gap(gap: iso606.ToothGap, tip_gap_mm: float) -> float:
    """Offset e of the plate face outside the pin line that leaves ``tip_gap_mm`` to the tip land.

    A seated link spans grooves −1 and +1 with groove 0 at mid-span; the teeth under it sit ±180°/z
    off mid-span. Over a tip land (polar angle θc to 360°/z − θc from mid-span) the height above the
    face normal, (de/2)·cos θ, is largest at the corner nearest mid-span, θc.
    """
    top = gap.tip_radius_mm * math.cos(gap.tip_corner_angle_rad)
    return tip_gap_mm + top - link_pin_line_radius(gap)


def measured_tip_gap(outline: np.ndarray, gap: iso606.ToothGap, pitch_mm: float, plate_offset_mm: float) -> float:
    """Smallest distance from the plate face of the link seated on grooves −1, +1 to the sprocket
    outline (every point of the polyline), negative by the depth if the outline crosses the face.

    Independent of :func:`plate_offset_for_tip_gap`: it measures the sampled outline against the
    face segment (length p along the chord) instead of using the tip corner's closed form.
    """
    face_x = link_pin_line_radius(gap) + plate_offset_mm
    half = pitch_mm / 2.0
    x, y = outline[:, 0], outline[:, 1]
    inside = np.abs(y) <= half
    over = x[inside] - face_x
    if over.size and over.max() > 0:
        return -float(over.max())
    dy = np.maximum(np.abs(y) - half, 0.0)
    dist = np.hypot(face_x - x, dy)
    return float(dist.min())


def sleeve_flank_clearance_at_tip(gap: iso606.ToothGap, sleeve_radius_mm: float) -> float:
    """Clearance from a sleeve centred on the seating centre to the tooth's tip corner."""
    return float(np.hypot(*(gap.tip_corner - gap.seating_centre))) - sleeve_radius_mm
