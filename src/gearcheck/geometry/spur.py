"""Involute spur gears as polygons, and rigid transforms: building blocks for a mechanism of your
own (numpy only; docs/extending.md). The spur-pair example mechanism is written with them.

A gear's outline is a polygon whose vertices lie exactly on its involute flanks (uniform in roll
angle), on its tip and root circles: the solid made from it (``gearcheck.cad.profile.
extruded_outline``) is exact at its vertices, and its flat faces mesh without chord error. The
chords sag inside the convex involute by at most :func:`flank_sag_mm`, which a sweep adds to its
agreement allowance.
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry.involute import inv

FLANK_POINTS = 32  # involute points per flank (uniform in roll angle)
ARC_POINTS = 6  # points per tip land and per root land
ROOT_CLEARANCE = 0.25  # dedendum = (1 + this)·m


def spur_outline(z: int, m: float, alpha: float, thinning: float = 0.0, *, flank_points: int = FLANK_POINTS,
                 arc_points: int = ARC_POINTS, root_clearance: float = ROOT_CLEARANCE) -> np.ndarray:
    """Counter-clockwise (n, 2) polygon of a standard spur gear (module ``m`` mm, ``z`` teeth,
    pressure angle ``alpha`` rad, addendum m, dedendum (1 + root_clearance)·m), each tooth thinned
    by ``thinning`` mm on its pitch circle; in its own frame, tooth 0 centred on +x. ValueError for
    pointed teeth."""
    r, rb = m * z / 2.0, m * z / 2.0 * math.cos(alpha)
    ra, rf = r + m, r - (1.0 + root_clearance) * m
    psi = math.pi / (2 * z) - thinning / (2.0 * r)  # half tooth thickness at the pitch circle (angle)
    start = max(rb, rf)
    u = np.linspace(math.sqrt(max(start**2 / rb**2 - 1.0, 0.0)), math.sqrt(ra**2 / rb**2 - 1.0), flank_points)
    rho = rb * np.sqrt(1.0 + u**2)
    pressure = np.arccos(np.clip(rb / rho, -1.0, 1.0))
    theta = psi + float(inv(alpha)) - (np.tan(pressure) - pressure)
    if theta[-1] <= 0.0:
        raise ValueError(f"pointed teeth: z = {z}, m = {m}, thinning {thinning} mm")
    pts: list[tuple[float, float]] = []
    for k in range(z):
        c = 2 * math.pi * k / z
        flank = [(rf, c - theta[0])] if rf < rb else []
        flank += list(zip(rho, c - theta, strict=True))
        tip = [(ra, a) for a in np.linspace(c - theta[-1], c + theta[-1], arc_points)[1:-1]]
        back = [(p, 2 * c - a) for p, a in reversed(flank)]
        nxt = c + 2 * math.pi / z
        root = [(rf, a) for a in np.linspace(c + theta[0], nxt - theta[0], arc_points)[1:-1]]
        pts += flank + tip + back + root
    return np.array([[p * math.cos(a), p * math.sin(a)] for p, a in pts])


def flank_sag_mm(z: int, m: float, alpha: float, flank_points: int = FLANK_POINTS) -> float:
    """Largest sag of :func:`spur_outline`'s flank chords inside the involute: rb·u·du²/8 at the tip."""
    rb, ra = m * z / 2.0 * math.cos(alpha), m * z / 2.0 + m
    ua = math.sqrt(ra**2 / rb**2 - 1.0)
    return rb * ua * (ua / (flank_points - 1)) ** 2 / 8.0


def rot_z(angle: float) -> np.ndarray:
    """4×4 rotation by ``angle`` rad about +z through the origin."""
    out = np.eye(4)
    c, s = math.cos(angle), math.sin(angle)
    out[:2, :2] = [[c, -s], [s, c]]
    return out


def translation(offset) -> np.ndarray:
    """4×4 translation by ``offset`` (mm)."""
    out = np.eye(4)
    out[:3, 3] = np.asarray(offset, float)
    return out
