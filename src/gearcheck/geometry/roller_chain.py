"""A roller chain on an ISO 606 sprocket whose every tooth engages, numpy only: the chain's
wrap as the sprocket turns, the exact 2-D distances the mesh sweep is checked against, the
polygon effect and the chain-wear limit.

Wrap (sprocket frame turning counter-clockwise by θ; world frame: +y up). The chain arrives as a
horizontal tight span over the top, from +x, wraps 180° round the left, and leaves as a horizontal
span under the bottom, towards +x. Roller i sits, while seated, on the pitch circle R = d/2 at polar
angle β_i = 2π(u − i)/z with u = u0 + θ·z/(2π), in the groove of the sprocket turned by β_0. The
entry anchor (the most upstream seated roller) engages at β = 90° − 180°/z and carries the top span
until it reaches 90° + 180°/z, when the next roller, p behind it on the horizontal span, lands
exactly in its groove; the span's rollers lie p apart on the horizontal through the anchor. The
exit anchor (the most downstream seated roller) is the mirror image at the bottom. So the link
behind an anchor swings into its groove about the anchor's centre (radius p), and the span rises
and falls with the anchor: the polygon effect, chain speed v = ω·R·sin β_anchor, between ω·R·cos(180°/z)
and ω·R (ripple 1 − cos(180°/z)), chordal rise R·(1 − cos(180°/z)).

Links: link j joins rollers j and j + 1 (frame: roller j at the origin, roller j + 1 at (p, 0), z
along the sprocket axis); even j are inner links (inner plates and two rollers), odd j outer links
(outer plates and pins).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import iso606

# Anchors are found with this slack on u (a roller exactly at a handover is on either side: the
# positions are the same, so the choice does not matter).
ANCHOR_EPS = 1e-9


def rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


@dataclass(frozen=True)
class RollerWrap:
    """The chain segment on the sprocket (180° wrap, horizontal spans of ``span`` rollers beyond
    each anchor over the default sweep, :meth:`centred`)."""

    teeth: int
    pitch_mm: float
    rollers: int
    u0: float  # u at θ = 0
    span: int

    @classmethod
    def centred(cls, teeth: int, pitch_mm: float, span: int = 3) -> RollerWrap:
        """At θ = 0 the exit anchor is roller ``span`` at its handover; over θ ∈ [0, 2 cycles] every
        roller stays within the segment (an even number of rollers: whole inner links)."""
        u0 = span + 0.75 * teeth + 0.5
        n = 2 * span + teeth // 2 + 4
        return cls(teeth, pitch_mm, n + (n % 2), u0, span)

    @property
    def pitch_radius_mm(self) -> float:
        return self.pitch_mm / (2.0 * math.sin(math.pi / self.teeth))

    @property
    def cycle_rad(self) -> float:
        """One engagement cycle: a tooth pitch 2π/z of sprocket rotation."""
        return 2.0 * math.pi / self.teeth

    @property
    def links(self) -> int:
        return self.rollers - 1

    def u(self, theta: float) -> float:
        return self.u0 + theta * self.teeth / (2.0 * math.pi)

    def sprocket_angle(self, theta: float) -> float:
        """The sprocket's rotation (its groove 0 on the pitch circle at polar angle 2π·u0/z + θ)."""
        return 2.0 * math.pi * self.u0 / self.teeth + theta

    def sprocket_matrix(self, theta: float) -> np.ndarray:
        return rot_z(self.sprocket_angle(theta))

    def anchors(self, theta: float) -> tuple[int, int]:
        """(exit anchor, entry anchor): the first and last seated roller."""
        u, z = self.u(theta), self.teeth
        a_out = math.ceil(u - 0.75 * z - 0.5 - ANCHOR_EPS)
        a_in = math.floor(u - 0.25 * z + 0.5 + ANCHOR_EPS)
        if not (0 <= a_out <= a_in < self.rollers):
            raise ValueError(f"θ = {theta:.6f} rad lies outside the segment's sweep")
        return a_out, a_in

    def beta(self, theta: float) -> np.ndarray:
        return 2.0 * math.pi * (self.u(theta) - np.arange(self.rollers)) / self.teeth

    def centres(self, theta: float) -> np.ndarray:
        """(rollers, 2) roller centres in the world plane."""
        a_out, a_in = self.anchors(theta)
        b = self.beta(theta)
        r = self.pitch_radius_mm
        c = np.column_stack([r * np.cos(b), r * np.sin(b)])
        i = np.arange(self.rollers)
        up = i > a_in
        c[up] = c[a_in] + np.outer(i[up] - a_in, [self.pitch_mm, 0.0])
        down = i < a_out
        c[down] = c[a_out] + np.outer(a_out - i[down], [self.pitch_mm, 0.0])
        return c

    def seated(self, theta: float) -> np.ndarray:
        a_out, a_in = self.anchors(theta)
        i = np.arange(self.rollers)
        return (i >= a_out) & (i <= a_in)

    def link_matrices(self, theta: float) -> list[np.ndarray]:
        """Pose of link j (frame → world): origin on roller j, +x towards roller j + 1."""
        c = self.centres(theta)
        out = []
        for j in range(self.links):
            v = (c[j + 1] - c[j]) / np.hypot(*(c[j + 1] - c[j]))
            m = np.eye(4)
            m[:2, :2] = [[v[0], -v[1]], [v[1], v[0]]]
            m[:2, 3] = c[j]
            out.append(m)
        return out

    def in_sprocket_frame(self, theta: float) -> np.ndarray:
        """Roller centres in the sprocket's own frame (groove k on polar angle 2πk/z)."""
        a = -self.sprocket_angle(theta)
        c = self.centres(theta)
        ca, sa = math.cos(a), math.sin(a)
        return c @ np.array([[ca, -sa], [sa, ca]]).T

    def top_speed_ratio(self, theta: float) -> float:
        """Exact top-span speed over ω·R: sin β of the entry anchor."""
        _, a_in = self.anchors(theta)
        return float(math.sin(self.beta(theta)[a_in]))


def speed_ripple(teeth: int) -> float:
    """Closed form of the chain speed ripple (v_max − v_min)/v_max = 1 − cos(180°/z)."""
    return 1.0 - math.cos(math.pi / teeth)


def chordal_rise(pitch_mm: float, teeth: int) -> float:
    """Closed form of the chordal rise R·(1 − cos(180°/z)), R = p / (2·sin(180°/z))."""
    return pitch_mm / (2.0 * math.sin(math.pi / teeth)) * speed_ripple(teeth)


# --------------------------------------------------------------------------------------------
# Exact distances to the tooth outline (the exact arcs, no polyline)

SEAT, FLANK, LAND = 0, 1, 2


def _arc_distance(points: np.ndarray, centre: np.ndarray, radius: float, a0: float, span: float,
                  end0: np.ndarray, end1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance from points (N, 2) to the arc about ``centre`` counter-clockwise from angle ``a0``
    through ``span`` (ends ``end0``, ``end1``), and whether the nearest point is the end ``end1``."""
    v = points - centre
    rho = np.hypot(v[:, 0], v[:, 1])
    on_arc = np.mod(np.arctan2(v[:, 1], v[:, 0]) - a0, 2.0 * math.pi) <= span
    d0 = np.hypot(*(points - end0).T)
    d1 = np.hypot(*(points - end1).T)
    return np.where(on_arc, np.abs(rho - radius), np.minimum(d0, d1)), ~on_arc & (d1 <= d0)


def wedge(gap: iso606.ToothGap, points: np.ndarray) -> np.ndarray:
    """Points (N, 2) of the sprocket frame folded into groove 0's half wedge (polar angle 0 … 180°/z)
    by the outline's symmetry (turns by 360°/z and the mirror in each groove's centre line)."""
    step = 2.0 * math.pi / gap.teeth
    phi = np.arctan2(points[:, 1], points[:, 0])
    k = np.round(phi / step)
    a = phi - k * step
    rho = np.hypot(points[:, 0], points[:, 1])
    a = np.abs(a)
    return np.column_stack([rho * np.cos(a), rho * np.sin(a)])


def outline_distance(gap: iso606.ToothGap, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance from points (N, 2, sprocket frame, outside the teeth) to the exact tooth outline,
    and the piece nearest (SEAT, FLANK or LAND; a flank distance whose nearest point is the tip
    corner counts as LAND)."""
    q = wedge(gap, np.asarray(points, float).reshape(-1, 2))
    j, c = gap.junction, gap.tip_corner
    ha = gap.seating_angle_rad / 2.0
    bottom = gap.seating_centre + np.array([-gap.seating_radius_mm, 0.0])
    seat, _ = _arc_distance(q, gap.seating_centre, gap.seating_radius_mm, math.pi - ha, ha, j, bottom)
    flank, at_corner = _arc_distance(q, gap.flank_centre, gap.flank_radius_mm, gap.flank_start_angle_rad,
                                     gap.flank_sweep_rad, j, c)
    half = gap.half_pitch_angle_rad
    land, _ = _arc_distance(q, np.zeros(2), gap.tip_radius_mm, gap.tip_corner_angle_rad,
                            gap.tip_land_half_angle_rad, c, gap.tip_radius_mm * np.array([math.cos(half),
                                                                                          math.sin(half)]))
    d = np.stack([seat, flank, land])
    piece = np.argmin(d, axis=0)
    piece = np.where((piece == FLANK) & at_corner, LAND, piece)
    return d.min(axis=0), piece


def roller_clearances(gap: iso606.ToothGap, wrap: RollerWrap, theta: float, roller_radius_mm: float) -> np.ndarray:
    """Exact roller–tooth clearance of every roller at θ (mm; negative: overlap depth from the
    surface, for a roller centre outside the teeth)."""
    d, _ = outline_distance(gap, wrap.in_sprocket_frame(theta))
    return d - roller_radius_mm


# --------------------------------------------------------------------------------------------
# Chain wear: the elongation at which a roller first rides up to the tip

WEAR_BRACKET_MAX = 0.30  # the limit is searched in e ∈ [0, 30 %]
WEAR_TOL = 1e-7  # bisection width on e
CONTACT_SCAN = 400  # roller-centre angles scanned for the first contact before bisection
CONTACT_BISECTIONS = 60


@dataclass(frozen=True)
class Contact:
    """The first contact of a roller whose centre moves along the circle of radius ``radius``
    from the groove's centre line towards its flank (None fields: it never touches)."""

    found: bool
    angle_rad: float  # polar angle of the roller centre at contact (groove frame)
    piece: int  # SEAT, FLANK or LAND (LAND: the tip corner or the tip land: the roller rides up)

    @property
    def on_tip(self) -> bool:
        return not self.found or self.piece == LAND


def first_contact(gap: iso606.ToothGap, roller_radius_mm: float, radius_mm: float) -> Contact:
    """The tooth pushes a worn chain's roller (its centre on the circle R·(1 + e)) round the axis
    until it touches the driving flank: where does it first touch? (exact arcs; scan, then bisect)."""
    half = gap.half_pitch_angle_rad
    angles = np.linspace(0.0, half, CONTACT_SCAN + 1)
    pts = radius_mm * np.column_stack([np.cos(angles), np.sin(angles)])
    d, _ = outline_distance(gap, pts)
    touching = np.flatnonzero(d <= roller_radius_mm)
    if not len(touching):
        return Contact(False, math.nan, LAND)
    hi = float(angles[touching[0]])
    lo = float(angles[touching[0] - 1]) if touching[0] > 0 else 0.0
    if touching[0] == 0:
        lo = hi = 0.0
    for _ in range(CONTACT_BISECTIONS if hi > lo else 0):
        mid = 0.5 * (lo + hi)
        dm, _ = outline_distance(gap, radius_mm * np.array([[math.cos(mid), math.sin(mid)]]))
        if dm[0] <= roller_radius_mm:
            hi = mid
        else:
            lo = mid
    _, piece = outline_distance(gap, radius_mm * np.array([[math.cos(hi), math.sin(hi)]]))
    return Contact(True, hi, int(piece[0]))


def wear_limit_closed_form(gap: iso606.ToothGap, roller_radius_mm: float) -> float:
    """The limit in closed form: the roller touches the flank exactly at the tip corner C, so its
    centre is C + r·n (n the flank's outward normal at C) and R·(1 + e) = |C + r·n|. (The roller
    centres' path round the groove, offset r from the outline, moves monotonically away from the
    axis, so the first contact passes from the flank to the corner at this radius.)"""
    c, f = gap.tip_corner, gap.flank_centre
    n = (c - f) / float(np.hypot(*(c - f)))
    return float(np.hypot(*(c + roller_radius_mm * n))) / gap.pitch_radius_mm - 1.0


@dataclass(frozen=True)
class WearLimit:
    limit: float  # elongation (fraction) at which the first contact reaches the tip
    closed_form: float  # R(1 + e) = |C + r·n| (C tip corner, n the flank's normal there)
    contact_radius_new_mm: float  # where a new chain's roller first touches (e = 0)


def wear_limit(gap: iso606.ToothGap, roller_radius_mm: float) -> WearLimit:
    """The elongation e at which a roller of the worn chain (pitch p(1 + e), so its centre on
    R(1 + e)) first touches the tooth at the tip corner or beyond: bisection on the exact contact;
    the closed form beside it."""
    r, rp = roller_radius_mm, gap.pitch_radius_mm

    def rides_up(e: float) -> bool:
        return first_contact(gap, r, rp * (1.0 + e)).on_tip

    lo, hi = 0.0, WEAR_BRACKET_MAX
    if rides_up(lo):
        limit = 0.0
    elif not rides_up(hi):
        limit = math.inf
    else:
        while hi - lo > WEAR_TOL:
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if rides_up(mid) else (mid, hi)
        limit = 0.5 * (lo + hi)
    closed = wear_limit_closed_form(gap, r)
    new = first_contact(gap, r, rp)
    radius_new = math.nan
    if new.found:
        centre = rp * np.array([math.cos(new.angle_rad), math.sin(new.angle_rad)])
        radius_new = float(np.hypot(*centre))
    return WearLimit(limit, closed, radius_new)


def replacement_limit_pct(teeth: int, fixed_centres: bool) -> tuple[float, str]:
    """The usual replacement elongation (%): 3 %, 200/z % where that is less (large sprockets),
    1.5 % on fixed centres (no tensioner takes up the slack); and which rule set it."""
    rules = [(3.0, "3 % (general limit)"), (200.0 / teeth, f"200/z = {200.0 / teeth:.2f} % (large sprocket)")]
    if fixed_centres:
        rules.append((1.5, "1.5 % (fixed centres)"))
    return min(rules)


# --------------------------------------------------------------------------------------------
# The link solids as data (what :mod:`gearcheck.cad.roller_chain` builds)

@dataclass(frozen=True)
class LinkSpec:
    """One link of an ``strands``-strand chain in its own frame (roller/pin axes at (0, 0) and
    (p, 0), parallel to z; strands centred on z = 0, ``transverse_pitch_mm`` apart). Inner link:
    two rollers per strand (d1, length b1) between its inner plates; outer link: pins (d2) through
    every strand and the outer plates outside the inner ones. Plates are stadiums: depth h2, ends
    round about the axes, thickness t each."""

    kind: str  # "inner" or "outer"
    pitch_mm: float
    roller_radius_mm: float
    pin_radius_mm: float
    inner_width_mm: float
    plate_depth_mm: float
    plate_thickness_mm: float
    strands: int
    transverse_pitch_mm: float

    def strand_z(self) -> list[float]:
        n, pt = self.strands, self.transverse_pitch_mm
        return [(s - (n - 1) / 2.0) * pt for s in range(n)]

    def plate_z_ranges(self) -> list[tuple[float, float]]:
        """(z0, z1) of every plate of this link."""
        b, t = self.inner_width_mm / 2.0, self.plate_thickness_mm
        off = 0.0 if self.kind == "inner" else t
        out = []
        for zs in self.strand_z():
            out += [(zs - b - off - t, zs - b - off), (zs + b + off, zs + b + off + t)]
        return out

    @property
    def width_mm(self) -> float:
        """Overall width (the outer link's pin length): n·pt."""
        return self.strands * self.transverse_pitch_mm
