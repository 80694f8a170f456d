"""Analytic volume of a bevel gear (numpy only): the check the built solids are measured against.

Pappus under the root cone plus the teeth, V_teeth = z ∫ w(θ)·(Re³ − Ri³)/(3 cos³(θ − δ))·sin θ dθ
(w = tooth azimuth width), exact where the blank's faces lie under the roots (docs/bevel.md).
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry.bevel import BevelGearSpec, flank_azimuth


def _revolved_volume(poly: np.ndarray) -> float:
    """Volume of revolution about z of a closed CCW polygon in (ρ, z): 2π ∫∫ ρ dA."""
    x, y = poly[:, 0], poly[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    return float(2 * math.pi * np.sum((x + x1) * (x * y1 - x1 * y)) / 6.0)


def _clip_polygon(poly: np.ndarray, keep) -> np.ndarray:
    """Sutherland–Hodgman clip by the half-plane keep(p) = n·p ≥ 0 (n given as a function)."""
    out = []
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        fa, fb = keep(a), keep(b)
        if fa >= 0:
            out.append(a)
        if (fa >= 0) != (fb >= 0):
            out.append(a + (b - a) * fa / (fa - fb))
    return np.array(out)


def analytic_volume_mm3(spec: BevelGearSpec, nodes: int = 400) -> float:
    """Volume (mm³) of the finished gear from the geometry alone (no CAD): the blank under
    the root cone (Pappus on the clipped meridian polygon) plus the teeth,

        V_teeth = z ∫_{θf}^{θa} w(θ) · (Re³ − Ri³) / (3 cos³(θ − δ)) · sin θ dθ

    with w(θ) = 2·flank_azimuth(θ, +1) the tooth's azimuth width (back and front cones bound a
    ray at r = Re / cos(θ − δ) and Ri / cos(θ − δ)). Gauss–Legendre, split at δb.
    """
    t = math.tan(spec.root_angle_rad)
    under_root = _clip_polygon(spec.blank_profile(), lambda p: p[1] * t - p[0])
    volume = _revolved_volume(under_root)
    d = spec.pitch_angle_rad
    re, ri = spec.outer_cone_distance_mm, spec.inner_cone_distance_mm
    cuts = sorted({spec.root_angle_rad, spec.face_angle_rad,
                   min(max(spec.base_angle_rad, spec.root_angle_rad), spec.face_angle_rad)})
    x, w = np.polynomial.legendre.leggauss(nodes)
    for lo, hi in zip(cuts[:-1], cuts[1:], strict=True):
        th = 0.5 * (hi - lo) * x + 0.5 * (hi + lo)
        width = 2 * flank_azimuth(spec, th, +1)
        f = width * (re**3 - ri**3) / (3 * np.cos(th - d) ** 3) * np.sin(th)
        volume += spec.teeth * 0.5 * (hi - lo) * float(w @ f)
    return volume
