"""ISO 606 (GB/T 1243) roller-chain sprocket tooth form, numpy only.

The bomb-disposal robot's track sprocket engages every other tooth: it has ``z`` teeth and ``z``
grooves, groove ``k`` centred on polar angle ``k·360°/z``, and a chain link (pitch ``p``) spans
two groove pitches, so its pins sit in grooves two apart. Hence (paper eq. 6)

    d = p / sin(360°/z)          (standard sprocket: p / sin(180°/z))

and the chord between adjacent grooves is ``d·sin(180°/z)`` (15.031 mm at z = 49, p = 30).

Each groove has the ISO 606 tooth-gap form with roller diameter ``d1`` (here the track sleeve
``dR``): a seating arc of radius ``ri`` centred on the pitch circle spanning the seating angle
``α`` symmetrically about the groove's radial line, then on each side a convex flank arc of radius
``re`` tangent to the seating arc at its end, up to the tip circle. Coordinates are millimetres
in the sprocket plane with its axis at the origin; groove 0 is centred on the +x axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# ISO 606 tooth width factor bf1 = k·b1: 0.93 for p ≤ 12.7 mm, 0.95 above.
ISO_TOOTH_WIDTH_PITCH_LIMIT_MM = 12.7

# Default largest distance between successive profile points (chordal step), mm.
PROFILE_STEP_MM = 0.05


def every_other_tooth_pitch_diameter(pitch_mm: float, teeth: int) -> float:
    """Pitch diameter d = p / sin(360°/z) when the chain engages every other tooth (paper eq. 6)."""
    return pitch_mm / math.sin(2.0 * math.pi / teeth)


def teeth_for_pitch_diameter(pitch_mm: float, pitch_diameter_mm: float) -> float:
    """Inverse of eq. 6: the (real) tooth count z = 360° / asin(p/d) for a wanted d (needs d > p)."""
    if not pitch_diameter_mm > pitch_mm > 0:
        raise ValueError("pitch diameter must exceed the chain pitch")
    return 2.0 * math.pi / math.asin(pitch_mm / pitch_diameter_mm)


def groove_chord(pitch_diameter_mm: float, teeth: int) -> float:
    """Chord between the seating centres of adjacent grooves, d·sin(180°/z)."""
    return pitch_diameter_mm * math.sin(math.pi / teeth)


@dataclass(frozen=True)
class SeatingLimits:
    """ISO 606 limits of the tooth-gap form for roller diameter d1 and z teeth.

    The minimum tooth gap has (ri_min, re_max, α_max); the maximum has (ri_max, re_min, α_min);
    an actual form may take any values in between.
    """

    seating_radius_min_mm: float  # ri_min = 0.505·d1
    seating_radius_max_mm: float  # ri_max = 0.505·d1 + 0.069·d1^(1/3)
    flank_radius_min_mm: float  # re_min = 0.12·d1·(z + 2)
    flank_radius_max_mm: float  # re_max = 0.008·d1·(z² + 180)
    seating_angle_min_deg: float  # α_min = 120° − 90°/z
    seating_angle_max_deg: float  # α_max = 140° − 90°/z


def seating_limits(roller_diameter_mm: float, teeth: int) -> SeatingLimits:
    d1, z = roller_diameter_mm, teeth
    return SeatingLimits(
        seating_radius_min_mm=0.505 * d1,
        seating_radius_max_mm=0.505 * d1 + 0.069 * d1 ** (1.0 / 3.0),
        flank_radius_min_mm=0.12 * d1 * (z + 2),
        flank_radius_max_mm=0.008 * d1 * (z * z + 180),
        seating_angle_min_deg=120.0 - 90.0 / z,
        seating_angle_max_deg=140.0 - 90.0 / z,
    )


def iso_tip_diameter_range(
    pitch_diameter_mm: float, chord_pitch_mm: float, roller_diameter_mm: float, teeth: int
) -> tuple[float, float]:
    """ISO 606 tip diameter limits (da_min, da_max) = (d + p(1 − 1.6/z) − d1, d + 1.25p − d1).

    ``chord_pitch_mm`` is the pitch the standard's formula is fed: for this sprocket either the
    groove chord or the chain pitch; neither applies to the paper's deliberately short tooth.
    """
    d, p, d1, z = pitch_diameter_mm, chord_pitch_mm, roller_diameter_mm, teeth
    return d + p * (1.0 - 1.6 / z) - d1, d + 1.25 * p - d1


def iso_tooth_width_max(inner_width_mm: float, pitch_mm: float) -> float:
    """ISO 606 largest tooth width bf1: 0.93·b1 for p ≤ 12.7 mm, 0.95·b1 above."""
    factor = 0.93 if pitch_mm <= ISO_TOOTH_WIDTH_PITCH_LIMIT_MM else 0.95
    return factor * inner_width_mm


class ToothFormError(ValueError):
    """The chosen values give no tooth between adjacent grooves (or no tip land)."""


@dataclass(frozen=True)
class ToothGap:
    """One ISO 606 groove (groove 0, centred on +x) and the half teeth beside it.

    The +y side is solved; the −y side is its mirror image. ``flank_start_angle_rad`` is the
    direction of ``junction`` seen from ``flank_centre``; the flank runs counter-clockwise about
    ``flank_centre`` from there to ``tip_corner``.
    """

    teeth: int
    pitch_radius_mm: float
    seating_radius_mm: float
    flank_radius_mm: float
    seating_angle_rad: float
    tip_radius_mm: float
    seating_centre: np.ndarray  # (2,) on the pitch circle, +x axis
    junction: np.ndarray  # (2,) end of the seating arc on the +y side
    flank_centre: np.ndarray  # (2,)
    flank_start_angle_rad: float
    flank_sweep_rad: float  # flank arc angle from junction to tip corner
    tip_corner: np.ndarray  # (2,) where the +y flank meets the tip circle

    @property
    def half_pitch_angle_rad(self) -> float:
        """Angle from a groove's centre line to the next tooth's centre line, 180°/z."""
        return math.pi / self.teeth

    @property
    def tip_corner_angle_rad(self) -> float:
        """Polar angle of the tip corner from the groove centre line."""
        return math.atan2(self.tip_corner[1], self.tip_corner[0])

    @property
    def tip_land_half_angle_rad(self) -> float:
        return self.half_pitch_angle_rad - self.tip_corner_angle_rad

    @property
    def tip_land_width_mm(self) -> float:
        """Arc length of a tooth's tip land."""
        return 2.0 * self.tip_radius_mm * self.tip_land_half_angle_rad


def _first_sweep(start_angle: float, candidates: list[float]) -> float | None:
    """Smallest counter-clockwise sweep (0, π) from ``start_angle`` to any candidate angle."""
    best = None
    for c in candidates:
        sweep = (c - start_angle) % (2.0 * math.pi)
        if 0.0 < sweep < math.pi and (best is None or sweep < best):
            best = sweep
    return best


def flank_meet_radius(gap_centre: np.ndarray, flank_radius: float, start_angle: float, teeth: int) -> float | None:
    """Radius at which a groove's +y flank (continued) crosses the next tooth's centre line.

    The flanks of adjacent grooves are mirror images about that line, so this is where they
    meet: a tip circle above it leaves no tip land. None if the flank never gets there.
    """
    u = np.array([math.cos(math.pi / teeth), math.sin(math.pi / teeth)])
    b = float(u @ gap_centre)
    c = float(gap_centre @ gap_centre) - flank_radius**2
    disc = b * b - c
    if disc < 0:
        return None
    best = None
    for t in (b - math.sqrt(disc), b + math.sqrt(disc)):
        if t <= 0:
            continue
        w = t * u - gap_centre
        sweep = _first_sweep(start_angle, [math.atan2(w[1], w[0])])
        if sweep is not None and (best is None or sweep < best[0]):
            best = (sweep, t)
    return None if best is None else best[1]


def _flank(pitch_radius: float, ri: float, re: float, half_alpha: float):
    """Seating centre, junction, flank centre and the junction's direction from the flank centre."""
    centre = np.array([pitch_radius, 0.0])
    # u points from the seating centre to the seating arc's end, into the tooth.
    u = np.array([-math.cos(half_alpha), math.sin(half_alpha)])
    junction = centre + ri * u
    # Flank tangent to the seating arc at the junction, convex tooth: its centre lies beyond the
    # junction on the line from the seating centre.
    flank_centre = junction + re * u
    return centre, junction, flank_centre, math.atan2(-u[1], -u[0])


def tip_land_limit_diameter(
    pitch_diameter_mm: float, teeth: int, seating_radius_mm: float, flank_radius_mm: float, seating_angle_deg: float
) -> float:
    """Tip diameter at which the flanks of adjacent grooves meet (no tip land left); inf if never."""
    _, _, fc, start = _flank(pitch_diameter_mm / 2.0, seating_radius_mm, flank_radius_mm,
                             math.radians(seating_angle_deg) / 2.0)
    meet = flank_meet_radius(fc, flank_radius_mm, start, teeth)
    return math.inf if meet is None else 2.0 * meet


def tooth_gap(
    pitch_diameter_mm: float,
    teeth: int,
    seating_radius_mm: float,
    flank_radius_mm: float,
    seating_angle_deg: float,
    tip_diameter_mm: float,
) -> ToothGap:
    """Solve one groove's form. Raises :class:`ToothFormError` if it leaves no tooth or tip land."""
    rp = pitch_diameter_mm / 2.0
    ri, re = seating_radius_mm, flank_radius_mm
    half_alpha = math.radians(seating_angle_deg) / 2.0
    rt = tip_diameter_mm / 2.0
    z = teeth
    if 2.0 * ri >= groove_chord(pitch_diameter_mm, z):
        raise ToothFormError("seating circles of adjacent grooves overlap: no tooth left")
    centre, junction, flank_centre, start = _flank(rp, ri, re, half_alpha)
    if math.atan2(junction[1], junction[0]) >= math.pi / z:
        raise ToothFormError("seating arcs of adjacent grooves meet: no tooth left")
    if rt <= float(np.hypot(*junction)):
        raise ToothFormError("tip circle lies below the end of the seating arc")
    # Tip corner: |flank_centre + re·w| = rt.
    oc = float(np.hypot(*flank_centre))
    cos_gap = (rt * rt - oc * oc - re * re) / (2.0 * re * oc)
    if abs(cos_gap) > 1.0:
        raise ToothFormError("flank never reaches the tip circle")
    base = math.atan2(flank_centre[1], flank_centre[0])
    sweep = _first_sweep(start, [base + math.acos(cos_gap), base - math.acos(cos_gap)])
    if sweep is None:
        raise ToothFormError("flank never reaches the tip circle")
    corner = flank_centre + re * np.array([math.cos(start + sweep), math.sin(start + sweep)])
    meet = flank_meet_radius(flank_centre, re, start, z)
    if math.atan2(corner[1], corner[0]) >= math.pi / z or (meet is not None and meet < rt):
        raise ToothFormError("flanks of adjacent grooves meet below the tip circle: no tip land")
    return ToothGap(
        teeth=z,
        pitch_radius_mm=rp,
        seating_radius_mm=ri,
        flank_radius_mm=re,
        seating_angle_rad=2.0 * half_alpha,
        tip_radius_mm=rt,
        seating_centre=centre,
        junction=junction,
        flank_centre=flank_centre,
        flank_start_angle_rad=start,
        flank_sweep_rad=sweep,
        tip_corner=corner,
    )


def _arc(centre: np.ndarray, radius: float, a0: float, a1: float, step: float) -> np.ndarray:
    n = max(2, int(math.ceil(abs(a1 - a0) * radius / step)) + 1)
    a = np.linspace(a0, a1, n)
    return np.column_stack([centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)])


def tooth_gap_profile(gap: ToothGap, step_mm: float = PROFILE_STEP_MM) -> np.ndarray:
    """Points (N, 2) of one pitch of the outline, counter-clockwise (increasing polar angle).

    Runs from the centre of the tooth at −180°/z over its tip land, down the −y flank, round
    the seating arc, up the +y flank and over the next tip land to the tooth centre at +180°/z.
    Arc ends (tip corners, flank–seating junctions) are exact vertices; no point is repeated.
    """
    half = gap.half_pitch_angle_rad
    corner_angle = gap.tip_corner_angle_rad
    origin = np.zeros(2)
    # +y side: flank from junction to corner, then the tip land to the tooth centre.
    flank = _arc(gap.flank_centre, gap.flank_radius_mm, gap.flank_start_angle_rad,
                 gap.flank_start_angle_rad + gap.flank_sweep_rad, step_mm)
    flank[0] = gap.junction
    flank[-1] = gap.tip_corner
    land = _arc(origin, gap.tip_radius_mm, corner_angle, half, step_mm)
    upper = np.vstack([flank, land[1:]])
    # Seating arc from −α/2 to +α/2 about the inward direction (angle π seen from the centre).
    ha = gap.seating_angle_rad / 2.0
    seat = _arc(gap.seating_centre, gap.seating_radius_mm, math.pi + ha, math.pi - ha, step_mm)
    seat[0] = gap.junction * [1.0, -1.0]
    seat[-1] = gap.junction
    lower = (upper * [1.0, -1.0])[::-1]
    return np.vstack([lower, seat[1:-1], upper])


def sprocket_outline(gap: ToothGap, step_mm: float = PROFILE_STEP_MM) -> np.ndarray:
    """Closed outline (M, 2) of one tooth row: the groove profile repeated z times.

    Counter-clockwise, first point not repeated at the end; groove k is centred on k·360°/z.
    """
    one = tooth_gap_profile(gap, step_mm)[:-1]  # last point = next pitch's first point
    pieces = []
    for k in range(gap.teeth):
        a = 2.0 * math.pi * k / gap.teeth
        rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        pieces.append(one @ rot.T)
    return np.vstack(pieces)
